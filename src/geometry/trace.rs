//! Tracing a closed planar zero-set curve: predictor (a step along the tangent) and corrector (Newton's projection
//! back onto the curve), until the curve closes. Used to compare a fitted curve with a reference one everywhere,
//! and to draw models.

use nalgebra::Vector2;

use super::implicit::Implicit;
use super::sampling::project_to_zero_set;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TraceError {
    #[error("the start point could not be projected onto the curve")]
    StartOffCurve,
    #[error(
        "the curve could not be followed (singular point or a step that jumped to another branch)"
    )]
    Lost,
    #[error("the curve did not close within {0} steps")]
    NotClosed(usize),
}

/// Points along the closed curve through (the projection of) `start`, about `step` mm apart, in the direction
/// that keeps the outside (F > 0) on the right: counter-clockwise around the material.
pub fn trace_closed_curve(
    f: &impl Implicit<2>,
    start: &Vector2<f64>,
    step: f64,
    max_steps: usize,
) -> Result<Vec<Vector2<f64>>, TraceError> {
    let first = project_to_zero_set(f, start, 10.0 * step).ok_or(TraceError::StartOffCurve)?;
    let mut points = vec![first];
    let mut current = first;
    for _ in 0..max_steps {
        let (_, g) = f.value_gradient(&current);
        let tangent = Vector2::new(-g.y, g.x).normalize();
        let next =
            project_to_zero_set(f, &(current + tangent * step), step).ok_or(TraceError::Lost)?;
        if (next - current).norm() < 0.25 * step {
            return Err(TraceError::Lost);
        }
        if points.len() > 3 && (next - first).norm() < 0.75 * step {
            return Ok(points);
        }
        points.push(next);
        current = next;
    }
    Err(TraceError::NotClosed(max_steps))
}

/// `count` points evenly spaced by arc length along a closed polyline (the curve's own points stay the corners).
pub fn resample_closed(points: &[Vector2<f64>], count: usize) -> Vec<Vector2<f64>> {
    let n = points.len();
    let lengths: Vec<f64> = (0..n)
        .map(|i| (points[(i + 1) % n] - points[i]).norm())
        .collect();
    let total: f64 = lengths.iter().sum();
    let mut out = Vec::with_capacity(count);
    let mut segment = 0;
    let mut start_of_segment = 0.0;
    for k in 0..count {
        let target = total * k as f64 / count as f64;
        while start_of_segment + lengths[segment] < target && segment + 1 < n {
            start_of_segment += lengths[segment];
            segment += 1;
        }
        let t = ((target - start_of_segment) / lengths[segment]).clamp(0.0, 1.0);
        out.push(points[segment] + (points[(segment + 1) % n] - points[segment]) * t);
    }
    out
}

/// Whether `p` lies inside the closed polygon (crossing number: a ray from `p` along +x crosses its sides an odd
/// number of times).
pub(crate) fn inside_closed(polygon: &[Vector2<f64>], p: &Vector2<f64>) -> bool {
    let n = polygon.len();
    let mut inside = false;
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}

/// The vertices of the closed polyline `points` that keep it within `tolerance` of itself (Douglas-Peucker on
/// each half, split at the vertex farthest from the first): a finely traced curve kept dense only where it bends,
/// its sharp corners kept exactly.
pub(crate) fn simplify_closed(points: &[Vector2<f64>], tolerance: f64) -> Vec<Vector2<f64>> {
    let n = points.len();
    if n < 4 {
        return points.to_vec();
    }
    let far = (1..n)
        .max_by(|&a, &b| {
            (points[a] - points[0])
                .norm_squared()
                .total_cmp(&(points[b] - points[0]).norm_squared())
        })
        .expect("points");
    let mut keep = vec![false; n + 1];
    keep[0] = true;
    keep[far] = true;
    keep[n] = true;
    // The closing vertex is the first one again.
    let at = |i: usize| points[i % n];
    let mut stack = vec![(0, far), (far, n)];
    while let Some((first, last)) = stack.pop() {
        let (a, b) = (at(first), at(last));
        let ab = b - a;
        let length = ab.norm();
        let off = |i: usize| {
            let ap = at(i) - a;
            if length == 0.0 {
                ap.norm()
            } else {
                ab.perp(&ap).abs() / length
            }
        };
        let Some((worst, distance)) = (first + 1..last)
            .map(|i| (i, off(i)))
            .max_by(|x, y| x.1.total_cmp(&y.1))
        else {
            continue;
        };
        if distance > tolerance {
            keep[worst] = true;
            stack.push((first, worst));
            stack.push((worst, last));
        }
    }
    (0..n).filter(|&i| keep[i]).map(|i| points[i]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::poly::Poly;

    #[test]
    fn traces_a_circle_counter_clockwise() {
        // (x^2 + y^2 - 100) / 20: a circle of radius 10 mm, F > 0 outside.
        let circle = Poly::<2>::new(2, vec![-5.0, 0.0, 0.0, 0.05, 0.0, 0.05]);
        let points = trace_closed_curve(&circle, &Vector2::new(10.5, 0.0), 0.1, 10_000).unwrap();
        let expected = (std::f64::consts::TAU * 10.0 / 0.1).round() as usize;
        assert!(
            points.len().abs_diff(expected) <= 2,
            "{} points",
            points.len()
        );
        assert!(points.iter().all(|p| (p.norm() - 10.0).abs() < 1e-9));
        // Counter-clockwise: the second point is above the first on the right-hand side of the circle.
        assert!(points[1].y > points[0].y);
        let even = resample_closed(&points, 100);
        let gaps: Vec<f64> = (0..100)
            .map(|i| (even[(i + 1) % 100] - even[i]).norm())
            .collect();
        let (lo, hi) = gaps
            .iter()
            .fold((f64::MAX, 0.0f64), |(a, b), g| (a.min(*g), b.max(*g)));
        assert!(hi - lo < 1e-3, "gaps from {lo} to {hi}");
    }

    /// The distance from `p` to the closed polyline `outline`.
    fn to_polyline(outline: &[Vector2<f64>], p: &Vector2<f64>) -> f64 {
        let n = outline.len();
        (0..n)
            .map(|i| {
                let (a, b) = (outline[i], outline[(i + 1) % n]);
                let t = ((p - a).dot(&(b - a)) / (b - a).norm_squared()).clamp(0.0, 1.0);
                (a + (b - a) * t - p).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_simplified_outline_keeps_its_corners_and_stays_within_the_tolerance() {
        // A square of side 10 mm at 0.01 mm steps is its four corners; a circle of radius 10 mm at 0.01 mm steps
        // keeps a vertex at least every 0.06 mm (sqrt(8 tol R) = 0.09 mm at best), every point dropped within 0.1 um of what is left.
        let side: Vec<Vector2<f64>> = (0..1000)
            .map(|k| Vector2::new(k as f64 * 0.01, 0.0))
            .collect();
        let mut square = Vec::new();
        for turn in 0..4 {
            let r = nalgebra::Rotation2::new(std::f64::consts::FRAC_PI_2 * turn as f64);
            let corner = r * Vector2::new(0.0, 0.0)
                + [
                    Vector2::zeros(),
                    Vector2::new(10.0, 0.0),
                    Vector2::new(10.0, 10.0),
                    Vector2::new(0.0, 10.0),
                ][turn];
            square.extend(side.iter().map(|p| corner + r * p));
        }
        let corners = simplify_closed(&square, 1e-4);
        assert_eq!(corners.len(), 4, "{corners:?}");
        for c in [
            Vector2::new(0.0, 0.0),
            Vector2::new(10.0, 0.0),
            Vector2::new(10.0, 10.0),
            Vector2::new(0.0, 10.0),
        ] {
            assert!(corners.iter().any(|k| (k - c).norm() < 1e-12), "{c} kept");
        }
        let circle: Vec<Vector2<f64>> = (0..6283)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / 6283.0;
                Vector2::new(10.0 * t.cos(), 10.0 * t.sin())
            })
            .collect();
        let kept = simplify_closed(&circle, 1e-4);
        assert!((600..1200).contains(&kept.len()), "{} kept", kept.len());
        let worst = circle
            .iter()
            .map(|p| to_polyline(&kept, p))
            .fold(0.0, f64::max);
        assert!(worst <= 1e-4, "{worst}");
    }
}
