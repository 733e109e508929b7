//! Symmetry numbers and start frames from the points, after seed 001 section 3: the z axis of a supershape is an
//! axis of rotational symmetry, so every section across it has the same number of lobes m1. The points' inertia
//! axes are the candidates for that axis; across each, the points are cut into slabs and each slab's outline is
//! read for its lobes. An axis whose slabs agree on a count is a symmetry axis with m1 that count; m2 is read the
//! same way from the meridian section (the points near a plane through the axis). Where nothing stands out the
//! number is 4, "transparent" in eq. 1 as the paper says.
//!
//! Which inertia axis is the supershape's z cannot always be told from the points (a cube's three are alike; a
//! round section has no lobes to count), so every axis gives a guess and the recovery's cost decides.

use std::f64::consts::PI;

use nalgebra::{Matrix3, Point2, Point3, Rotation3, Unit, Vector3};

use crate::geometry::supershape::lobes::{circle_centre, strongest, Lobes};

/// Slabs across a candidate axis, between the 5% and 95% quantiles of the points along it.
const SLABS: usize = 7;
/// A slab needs this many points to show its outline.
const SLAB_POINTS: usize = 24;
/// Lobes weaker than this fraction of the mean radius are not told from noise or a round outline.
const LOBE_STRENGTH: f64 = 0.004;
/// The meridian section: points within this fraction of the half width of a plane through the axis.
const MERIDIAN_BAND: f64 = 0.15;
/// The symmetry numbers looked for.
const COUNTS: std::ops::RangeInclusive<usize> = 2..=12;
/// The number used where none stands out (seed 001: "we set m and M to 4 to make them transparent").
const TRANSPARENT: u32 = 4;

/// One candidate axis with what the points say about it.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisGuess {
    /// Start frames (columns: the canonical x, y, z axes in the points' frame) with z on the candidate axis: one
    /// with a lobe's maximum on x, one half a lobe further (whether a lobe's maximum is a superformula's corner
    /// or the middle of its side depends on exponents not yet known, and the cost has a local minimum at each).
    pub starts: Vec<Rotation3<f64>>,
    /// The start centre: the middle of the points' extent in the candidate frame.
    pub centre: Point3<f64>,
    /// Half the points' extent along the start frame's axes.
    pub half_extents: [f64; 3],
    pub symmetry: [u32; 2],
    /// Whether m1 and m2 were read from the points (rather than given or taken as 4).
    pub detected: [bool; 2],
    /// The fraction of slabs that agree on m1 (0 where none were read).
    pub agreement: f64,
}

/// One guess per inertia axis of the points, the most convincing first. `given` fixes the symmetry numbers.
pub fn guesses(points: &[Point3<f64>], given: Option<[u32; 2]>) -> Vec<AxisGuess> {
    let count = points.len() as f64;
    let centroid = Point3::from(points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / count);
    let covariance = points.iter().fold(Matrix3::zeros(), |sum, p| {
        let d = p - centroid;
        sum + d * d.transpose()
    }) / count;
    let axes = covariance.symmetric_eigen().eigenvectors;
    let mut guesses: Vec<AxisGuess> = (0..3)
        .map(|k| {
            let w = Unit::new_normalize(axes.column(k).into_owned());
            let u = Unit::new_normalize(axes.column((k + 1) % 3).into_owned());
            guess_about(points, &centroid, w, u, given)
        })
        .collect();
    guesses.sort_by(|a, b| b.agreement.total_cmp(&a.agreement));
    guesses
}

/// The guess with `w` as the supershape's z axis and `u` across it.
fn guess_about(
    points: &[Point3<f64>],
    centroid: &Point3<f64>,
    w: Unit<Vector3<f64>>,
    u: Unit<Vector3<f64>>,
    given: Option<[u32; 2]>,
) -> AxisGuess {
    let v = w.cross(&u);
    let local: Vec<Vector3<f64>> = points
        .iter()
        .map(|p| {
            let d = p - centroid;
            Vector3::new(d.dot(&u), d.dot(&v), d.dot(&w))
        })
        .collect();
    let (low, high) = super::extent(local.iter().copied());
    let middle = (low + high) / 2.0;
    let half = (high - low) / 2.0;
    let slabs = slab_lobes(&local);
    let (m1, agreement, phase) = match majority(&slabs) {
        Some((lobes, agreement)) => (lobes.count as u32, agreement, lobes.phase),
        None => (TRANSPARENT, 0.0, 0.0),
    };
    let m2 = meridian_lobes(&local, &half).map(|l| l.count as u32);
    let symmetry = given.unwrap_or([m1, m2.unwrap_or(TRANSPARENT)]);
    let detected = match given {
        Some(_) => [false; 2],
        None => [agreement > 0.0, m2.is_some()],
    };
    let starts = [phase, phase + PI / f64::from(symmetry[0])]
        .iter()
        .map(|turn| {
            let x = u.into_inner() * turn.cos() + v * turn.sin();
            Rotation3::from_basis_unchecked(&[x, w.cross(&x), w.into_inner()])
        })
        .collect();
    let in_plane = (half.x + half.y) / 2.0;
    AxisGuess {
        starts,
        centre: centroid + u.into_inner() * middle.x + v * middle.y + w.into_inner() * middle.z,
        half_extents: [in_plane, in_plane, half.z],
        symmetry,
        detected,
        agreement,
    }
}

/// The lobes of each slab across the z axis of the local frame that has enough points and stands out.
fn slab_lobes(local: &[Vector3<f64>]) -> Vec<Lobes> {
    let mut heights: Vec<f64> = local.iter().map(|p| p.z).collect();
    heights.sort_by(f64::total_cmp);
    let quantile = |q: f64| heights[((heights.len() - 1) as f64 * q) as usize];
    let (bottom, top) = (quantile(0.05), quantile(0.95));
    let step = (top - bottom) / SLABS as f64;
    (0..SLABS)
        .filter_map(|k| {
            let (from, to) = (bottom + step * k as f64, bottom + step * (k + 1) as f64);
            let section: Vec<Point2<f64>> = local
                .iter()
                .filter(|p| p.z >= from && p.z < to)
                .map(|p| Point2::new(p.x, p.y))
                .collect();
            outline_lobes(&section)
        })
        .collect()
}

/// The lobes of the meridian sections (near the planes y = 0 and x = 0 of the local frame), the stronger one.
fn meridian_lobes(local: &[Vector3<f64>], half: &Vector3<f64>) -> Option<Lobes> {
    let across =
        |band: f64, coordinate: fn(&Vector3<f64>) -> f64, along: fn(&Vector3<f64>) -> f64| {
            let section: Vec<Point2<f64>> = local
                .iter()
                .filter(|p| coordinate(p).abs() < band)
                .map(|p| Point2::new(along(p), p.z))
                .collect();
            outline_lobes(&section)
        };
    let by_y = across(MERIDIAN_BAND * half.y, |p| p.y, |p| p.x);
    let by_x = across(MERIDIAN_BAND * half.x, |p| p.x, |p| p.y);
    [by_y, by_x]
        .into_iter()
        .flatten()
        .max_by(|a, b| a.strength.total_cmp(&b.strength))
}

/// The lobes of one planar outline, read after stretching it to a unit square (so that sizes a1 != a2 do not
/// read as two lobes); the phase is turned back to the unstretched plane. `None` for too few points or lobes
/// that do not stand out.
fn outline_lobes(section: &[Point2<f64>]) -> Option<Lobes> {
    if section.len() < SLAB_POINTS {
        return None;
    }
    let (low, high) = section.iter().fold(
        (
            Point2::new(f64::INFINITY, f64::INFINITY),
            Point2::new(f64::NEG_INFINITY, f64::NEG_INFINITY),
        ),
        |(low, high), p| (low.inf(p), high.sup(p)),
    );
    let half = (high - low) / 2.0;
    if !(half.x > 0.0 && half.y > 0.0) {
        return None;
    }
    let middle = nalgebra::center(&low, &high);
    let unit: Vec<Point2<f64>> = section
        .iter()
        .map(|p| Point2::from((p - middle).component_div(&half)))
        .collect();
    let lobes = strongest(&unit, &circle_centre(&unit), COUNTS)?;
    let (sin, cos) = lobes.phase.sin_cos();
    (lobes.strength > LOBE_STRENGTH).then(|| Lobes {
        phase: (sin * half.y).atan2(cos * half.x),
        ..lobes
    })
}

/// The count most slabs agree on, with a slab that has it nearest the middle (for the phase) and the fraction of
/// slabs that agree.
fn majority(slabs: &[Lobes]) -> Option<(Lobes, f64)> {
    let votes = |count: usize| slabs.iter().filter(|l| l.count == count).count();
    let best = slabs.iter().map(|l| l.count).max_by_key(|&c| votes(c))?;
    let agreeing: Vec<&Lobes> = slabs.iter().filter(|l| l.count == best).collect();
    let chosen = *agreeing[agreeing.len() / 2];
    Some((chosen, votes(best) as f64 / SLABS as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::supershape::formula::Superformula;
    use crate::geometry::supershape::shape::Supershape;

    /// A hexagonal-section supershape lying along a turned axis: the guess on its axis reads m1 = 6 from the
    /// slabs and m2 = 4 from its square meridian (the guesses across it read the rectangles of their slabs; the
    /// recovery's cost sets them aside).
    #[test]
    fn a_hexagonal_prism_shows_its_axis_and_both_symmetry_numbers() {
        let shape = Supershape {
            r1: Superformula::new(6.0, 10.0, 6.0, 6.0, 1.0, 1.0).unwrap(),
            r2: Superformula::new(4.0, 12.0, 12.0, 12.0, 1.0, 1.0).unwrap(),
            scale: [20.0, 20.0, 35.0],
        };
        let turn = Rotation3::from_euler_angles(0.4, 0.7, -0.3);
        let points: Vec<Point3<f64>> = (0..60)
            .flat_map(|i| (0..60).map(move |j| (i, j)))
            .map(|(i, j)| {
                let theta = -PI + 2.0 * PI * (i as f64 + 0.5) / 60.0;
                let phi = -PI / 2.0 + PI * (j as f64 + 0.5) / 60.0;
                Point3::from(turn * shape.point(theta, phi).coords)
            })
            .collect();
        let all = guesses(&points, None);
        assert_eq!(all.len(), 3);
        let on_axis = all
            .iter()
            .find(|g| {
                (g.starts[0] * Vector3::z())
                    .dot(&(turn * Vector3::z()))
                    .abs()
                    > 0.999
            })
            .expect("a guess on the prism's axis");
        assert_eq!(on_axis.symmetry, [6, 4], "{on_axis:?}");
        assert_eq!(on_axis.detected, [true, true]);
        assert!(on_axis.agreement >= 5.0 / 7.0, "{on_axis:?}");
    }
}
