//! Closed plane curves given by a parameter, and the exact nearest point on them: the common ground of the
//! blade sections and the supershape outline.

use std::f64::consts::TAU;

use nalgebra::{Point2, Vector2};

/// A closed curve in a plane, traced counterclockwise as its parameter `s` runs over [0, 1), so that the
/// outward normal is the tangent turned clockwise.
pub trait ClosedCurve: Send + Sync {
    /// The point at parameter `s` (taken modulo 1).
    fn point(&self, s: f64) -> Point2<f64>;
}

/// Samples per curve for the coarse nearest-point search. The curves crowd their parameter where they
/// bend (cosine spacing at a blade's edges), so this many keeps the refined search on the right arc.
pub(crate) const SAMPLES: usize = 720;

/// Parameter step of the tangent's central difference.
const TANGENT_STEP: f64 = 1e-7;

/// A point of a curve with the curve's outward unit normal there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    pub s: f64,
    pub point: Point2<f64>,
    pub normal: Vector2<f64>,
}

/// The nearest point of a curve to a query, and the query's signed distance (positive outside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    pub on_curve: CurvePoint,
    pub signed_distance: f64,
}

/// A curve with its coarse samples, for repeated nearest-point queries.
pub struct SampledCurve<C> {
    curve: C,
    samples: Vec<Point2<f64>>,
}

impl<C: ClosedCurve> SampledCurve<C> {
    pub fn new(curve: C) -> Self {
        let samples = (0..SAMPLES)
            .map(|i| curve.point(sample_parameter(i)))
            .collect();
        SampledCurve { curve, samples }
    }

    /// The curve with its samples computed by the caller: `samples[i]` must be `curve.point(sample_parameter(i))`
    /// for i below [`SAMPLES`] (a caller that places them from stored parts saves the curve's evaluation).
    pub(crate) fn with_samples(curve: C, samples: Vec<Point2<f64>>) -> Self {
        debug_assert_eq!(samples.len(), SAMPLES);
        SampledCurve { curve, samples }
    }

    /// The curve point at `s` with its outward normal.
    pub fn at(&self, s: f64) -> CurvePoint {
        let s = s.rem_euclid(1.0);
        let ahead = self.curve.point(s + TANGENT_STEP);
        let behind = self.curve.point(s - TANGENT_STEP);
        let tangent = ahead - behind;
        let normal = Vector2::new(tangent.y, -tangent.x).normalize();
        CurvePoint {
            s,
            point: self.curve.point(s),
            normal,
        }
    }

    /// The exact nearest point: the nearest sample, then a golden-section search of the parameter between
    /// its neighbours. The sign comes from a crossing-number test, which stays right at a sharp trailing
    /// edge where the normal's direction jumps.
    pub fn nearest(&self, query: &Point2<f64>) -> Nearest {
        let (best, _) = self
            .samples
            .iter()
            .enumerate()
            .map(|(i, p)| (i, (p - query).norm_squared()))
            .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        let step = 1.0 / SAMPLES as f64;
        let centre = sample_parameter(best);
        let distance_at = |s: f64| (self.curve.point(s) - query).norm_squared();
        let s = golden_minimum(distance_at, centre - step, centre + step);
        let on_curve = self.at(s);
        let distance = (on_curve.point - query).norm();
        let sign = if self.contains(query) { -1.0 } else { 1.0 };
        Nearest {
            on_curve,
            signed_distance: sign * distance,
        }
    }

    /// Whether `query` is inside the curve (crossing number of the sample polygon; the polygon's chords
    /// differ from the curve by far less than any distance the simulator resolves near the boundary, and
    /// near it the sign does not matter since the distance is about zero).
    pub fn contains(&self, query: &Point2<f64>) -> bool {
        let mut inside = false;
        let n = self.samples.len();
        for i in 0..n {
            let a = self.samples[i];
            let b = self.samples[(i + 1) % n];
            if (a.y > query.y) != (b.y > query.y) {
                let x = a.x + (query.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if x > query.x {
                    inside = !inside;
                }
            }
        }
        inside
    }

    /// Points spaced evenly in the parameter, for callers that trace the whole curve.
    pub fn dense(&self, count: usize) -> Vec<CurvePoint> {
        (0..count)
            .map(|i| self.at((i as f64 + 0.5) / count as f64))
            .collect()
    }
}

/// Samples sit half a step off the grid, so that none lands on a curve's corner at s = 0.
pub(crate) fn sample_parameter(i: usize) -> f64 {
    (i as f64 + 0.5) / SAMPLES as f64
}

/// The minimum of a unimodal function on [lo, hi].
fn golden_minimum(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut a = hi - ratio * (hi - lo);
    let mut b = lo + ratio * (hi - lo);
    let (mut fa, mut fb) = (f(a), f(b));
    for _ in 0..60 {
        if fa < fb {
            hi = b;
            b = a;
            fb = fa;
            a = hi - ratio * (hi - lo);
            fa = f(a);
        } else {
            lo = a;
            a = b;
            fa = fb;
            b = lo + ratio * (hi - lo);
            fb = f(b);
        }
    }
    (lo + hi) / 2.0
}

/// A circle, for tests of the machinery above.
#[cfg(test)]
pub(crate) struct Circle(pub f64);

#[cfg(test)]
impl ClosedCurve for Circle {
    fn point(&self, s: f64) -> Point2<f64> {
        let angle = TAU * s;
        Point2::new(self.0 * angle.cos(), self.0 * angle.sin())
    }
}

/// The angle of a normal, for turning about a corner.
pub fn angle_of(v: &Vector2<f64>) -> f64 {
    v.y.atan2(v.x)
}

/// The unit vector at `angle`.
pub fn unit_at(angle: f64) -> Vector2<f64> {
    Vector2::new(angle.cos(), angle.sin())
}

/// The signed smallest turn from angle `a` to angle `b`, in (-pi, pi].
pub fn turn(a: f64, b: f64) -> f64 {
    let d = (b - a).rem_euclid(TAU);
    if d > TAU / 2.0 {
        d - TAU
    } else {
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearest_point_of_a_circle_is_radial_with_signed_distance() {
        let circle = SampledCurve::new(Circle(10.0));
        let outside = circle.nearest(&Point2::new(12.0, 5.0));
        let expected = Point2::new(12.0, 5.0).coords.normalize() * 10.0;
        assert!((outside.on_curve.point.coords - expected).norm() < 1e-6);
        assert!((outside.signed_distance - 3.0).abs() < 1e-9);
        assert!((outside.on_curve.normal - expected / 10.0).norm() < 1e-6);
        let inside = circle.nearest(&Point2::new(-3.0, 0.0));
        assert!((inside.signed_distance + 7.0).abs() < 1e-9);
    }

    #[test]
    fn turns_take_the_short_way() {
        assert!((turn(3.0, -3.0) - (TAU - 6.0)).abs() < 1e-12);
        assert!((turn(-3.0, 3.0) + (TAU - 6.0)).abs() < 1e-12);
        assert!((angle_of(&unit_at(1.0)) - 1.0).abs() < 1e-12);
    }
}
