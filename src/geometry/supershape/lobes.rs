//! The lobes of a closed planar outline seen from its centre: the harmonic of the radius r(theta) that stands out,
//! its strength and where its maxima lie. Seed 001 section 3 reads a supershape's symmetry number from the extrema
//! of r(theta) of its sections; counting extrema of noisy, unevenly spread points is fragile, so the count here is
//! the strongest harmonic of the radius, which has one maximum per lobe.

use std::f64::consts::{PI, TAU};

use nalgebra::Point2;

/// Angular bins the radii are averaged in first, so that where a scan is dense does not weigh more.
const BINS: usize = 720;

/// The strongest harmonic of an outline's radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lobes {
    /// The harmonic k: the number of lobes.
    pub count: usize,
    /// Its amplitude over the mean radius.
    pub strength: f64,
    /// The polar angle of a maximum of that harmonic, radians.
    pub phase: f64,
}

/// The strongest harmonic of the radius about `centre` among `counts`; `None` without points.
pub fn strongest(
    points: &[Point2<f64>],
    centre: &Point2<f64>,
    counts: std::ops::RangeInclusive<usize>,
) -> Option<Lobes> {
    let mut sums = vec![(0.0, 0usize); BINS];
    for p in points {
        let d = p - centre;
        let bin = (((d.y.atan2(d.x) + PI) / TAU * BINS as f64) as usize).min(BINS - 1);
        sums[bin].0 += d.norm();
        sums[bin].1 += 1;
    }
    let filled: Vec<(f64, f64)> = sums
        .iter()
        .enumerate()
        .filter(|(_, (_, n))| *n > 0)
        .map(|(i, (sum, n))| ((i as f64 + 0.5) / BINS as f64 * TAU - PI, sum / *n as f64))
        .collect();
    if filled.is_empty() {
        return None;
    }
    let mean = filled.iter().map(|(_, r)| r).sum::<f64>() / filled.len() as f64;
    counts
        .map(|k| {
            let (c, s) = filled.iter().fold((0.0, 0.0), |(c, s), (theta, r)| {
                let (sin, cos) = (k as f64 * theta).sin_cos();
                (c + (r - mean) * cos, s + (r - mean) * sin)
            });
            // r - mean = A cos(k theta - alpha) with 2 (c, s) / N = A (cos alpha, sin alpha).
            Lobes {
                count: k,
                strength: 2.0 * c.hypot(s) / filled.len() as f64 / mean,
                phase: s.atan2(c) / k as f64,
            }
        })
        .fold(None, |best: Option<Lobes>, next| match best {
            Some(b) if b.strength >= next.strength => Some(b),
            _ => Some(next),
        })
}

/// The centre of the circle closest to the points (Kasa's algebraic fit: x^2 + y^2 + D x + E y + F = 0 in least
/// squares). For an outline with two or more lobes it is the outline's centre however the scan is spread along
/// it, where the points' centroid would lean towards where they are dense.
pub fn circle_centre(points: &[Point2<f64>]) -> Point2<f64> {
    let points: Vec<_> = points.iter().map(|p| p.coords).collect();
    Point2::from(crate::geometry::circle::algebraic_centre(&points))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// r = 10 + cos(5 (theta - 0.2)): five lobes of strength 0.1 with a maximum at 0.2 rad, whatever the centre.
    #[test]
    fn five_lobes_are_counted_with_their_strength_and_phase() {
        let centre = Point2::new(3.0, -4.0);
        let points: Vec<Point2<f64>> = (0..2000)
            .map(|i| {
                let theta = -PI + TAU * i as f64 / 2000.0;
                let r = 10.0 + (5.0 * (theta - 0.2)).cos();
                centre + nalgebra::Vector2::new(theta.cos(), theta.sin()) * r
            })
            .collect();
        let lobes = strongest(&points, &circle_centre(&points), 2..=12).unwrap();
        assert_eq!(lobes.count, 5);
        assert!((lobes.strength - 0.1).abs() < 0.005, "{lobes:?}");
        assert!((lobes.phase - 0.2).abs() < 0.01, "{lobes:?}");
    }
}
