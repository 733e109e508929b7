//! Nominal points: the master's measured surface thinned to the curve the CMM follows when it scans the same
//! profile on the other instances (ScanOnCurve). Measured points are kept as they are (no interpolation), so every
//! nominal lies on the master's real surface.

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

/// Consecutive nominals may differ in normal direction by at most this: a leading edge turns through 180 degrees
/// within a millimetre or two, and a CMM following a curve through it needs points there to keep its shape.
const MAX_TURN_DEGREES: f64 = 10.0;

/// A nominal surface point with its outward unit normal, part frame, mm: the master's measured surface thinned to
/// at most `nominal_spacing_mm` apart (and closer where the normal turns by more than 10 degrees, so a leading edge
/// keeps its shape). The daemon sends these to the CMM as the curve to scan on the other blades.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct NominalPoint {
    pub point: [f64; 3],
    pub normal: [f64; 3],
}

/// Thins one scan (points in scan order, each with its outward normal, none of them zero) to nominals: the first
/// and last points are always kept; between them the farthest point is kept that is still within `spacing_mm`
/// of the previous nominal and whose normal is within 10 degrees of that nominal's. Where the scan itself steps
/// farther than that, consecutive measured points both become nominals (nothing is invented between them).
pub(crate) fn thin_to_nominals(
    points: &[Point3<f64>],
    normals: &[Vector3<f64>],
    spacing_mm: f64,
) -> Vec<NominalPoint> {
    let unit: Vec<Vector3<f64>> = normals.iter().map(|n| n.normalize()).collect();
    let min_cosine = MAX_TURN_DEGREES.to_radians().cos();
    let close_enough = |from: usize, to: usize| {
        (points[to] - points[from]).norm() <= spacing_mm && unit[from].dot(&unit[to]) >= min_cosine
    };
    let mut kept: Vec<usize> = Vec::new();
    if !points.is_empty() {
        kept.push(0);
    }
    let mut next = 1;
    while next < points.len() {
        let last = kept[kept.len() - 1];
        if close_enough(last, next) {
            next += 1;
        } else if next - 1 > last {
            // The point before `next` is the farthest one still close enough: it becomes the next nominal and
            // `next` is judged again from it.
            kept.push(next - 1);
        } else {
            kept.push(next);
            next += 1;
        }
    }
    if kept.last().is_some_and(|&last| last + 1 < points.len()) {
        kept.push(points.len() - 1);
    }
    kept.into_iter()
        .map(|i| NominalPoint {
            point: points[i].coords.into(),
            normal: unit[i].into(),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thin ellipse (a sharp leading edge at +y) in the plane x = 50, sampled evenly in its parameter, so points
    /// crowd where it is flat and spread out around the edges.
    fn thin_ellipse(count: usize) -> (Vec<Point3<f64>>, Vec<Vector3<f64>>) {
        let (a, b) = (40.0, 2.0);
        (0..count)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / count as f64;
                (
                    Point3::new(50.0, a * t.cos(), b * t.sin()),
                    // Deliberately not unit: the nominals must normalise.
                    Vector3::new(0.0, t.cos() / a, t.sin() / b) * 3.0,
                )
            })
            .unzip()
    }

    #[test]
    fn nominals_keep_the_ends_stay_within_the_spacing_and_follow_the_edge() {
        let (points, normals) = thin_ellipse(2000);
        let spacing = 3.0;
        let nominals = thin_to_nominals(&points, &normals, spacing);
        assert_eq!(nominals[0].point, <[f64; 3]>::from(points[0].coords));
        assert_eq!(
            nominals[nominals.len() - 1].point,
            <[f64; 3]>::from(points[points.len() - 1].coords)
        );
        let min_cosine = MAX_TURN_DEGREES.to_radians().cos();
        for pair in nominals.windows(2) {
            let (a, b) = (Vector3::from(pair[0].point), Vector3::from(pair[1].point));
            assert!((a - b).norm() <= spacing, "{:?} -> {:?}", pair[0], pair[1]);
            let turn = Vector3::from(pair[0].normal).dot(&Vector3::from(pair[1].normal));
            assert!(turn >= min_cosine, "the normal turns too far: {pair:?}");
        }
        for n in &nominals {
            assert!((Vector3::from(n.normal).norm() - 1.0).abs() < 1e-12);
        }
        // The perimeter is about 162 mm: thinning to 3 mm keeps several tens, not thousands, and the turns of the
        // two edges (radius of curvature 0.1 mm) add nominals beyond what the spacing alone needs.
        let by_spacing_alone = (162.0_f64 / spacing).ceil() as usize;
        assert!(nominals.len() > by_spacing_alone + 20, "{}", nominals.len());
        assert!(nominals.len() < 200, "{}", nominals.len());
    }

    #[test]
    fn a_scan_coarser_than_the_spacing_keeps_every_point() {
        let (points, normals) = thin_ellipse(40);
        let nominals = thin_to_nominals(&points, &normals, 0.5);
        assert_eq!(nominals.len(), points.len());
        assert!(thin_to_nominals(&[], &[], 1.0).is_empty());
    }
}
