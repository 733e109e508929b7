//! The 3L level-set offsets: per point and side, the largest offset c (from a given largest, halved up to
//! OFFSET_HALVINGS times) whose offset point is no nearer any other data point than OFFSET_CLEARANCE c, so that an
//! offset never reaches past the medial axis of a thin section.
//!
//! The test is an emptiness query on a ball (is any other point strictly within 0.98 c?), which stops at the
//! first point found and only visits the index near the ball, instead of a nearest-neighbour search: beside a dense
//! scan the offset point's nearest points are all about c away, and a nearest search keeps thousands of them in its
//! queue. One index ([`BallIndex`]) serves every candidate of a fit; points are done in parallel.

use nalgebra::SVector;
use rayon::prelude::*;

use super::ball_index::BallIndex;

/// An offset point must be at least this fraction of its offset away from every other data point.
const OFFSET_CLEARANCE: f64 = 0.98;
const OFFSET_HALVINGS: usize = 12;

/// The 3L offsets of one point, in normalised units; `None` where no safe offset exists on that side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Offsets {
    pub(super) inside: Option<f64>,
    pub(super) outside: Option<f64>,
}

/// The offsets of every point, starting from `largest`. `index` indexes `unit`.
pub(super) fn choose_offsets<const N: usize>(
    index: &BallIndex<N>,
    unit: &[SVector<f64, N>],
    normals: &[SVector<f64, N>],
    largest: f64,
) -> Vec<Offsets> {
    let safe = |i: usize, direction: f64| -> Option<f64> {
        let mut c = largest;
        for _ in 0..OFFSET_HALVINGS {
            let offset_point = unit[i] + normals[i] * (direction * c);
            let clearance = OFFSET_CLEARANCE * c;
            if !index.any_within(&offset_point, clearance, i) {
                return Some(c);
            }
            c /= 2.0;
        }
        None
    };
    (0..unit.len())
        .into_par_iter()
        .map(|i| Offsets {
            inside: safe(i, -1.0),
            outside: safe(i, 1.0),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::nearest::PointIndex;
    use nalgebra::Vector2;

    /// The old path: the nearest data point of the offset point must be the point itself or 0.98 c away.
    fn by_nearest(unit: &[Vector2<f64>], normals: &[Vector2<f64>], largest: f64) -> Vec<Offsets> {
        let index = PointIndex::new(unit);
        let safe = |i: usize, direction: f64| -> Option<f64> {
            let mut c = largest;
            for _ in 0..OFFSET_HALVINGS {
                let offset_point = unit[i] + normals[i] * (direction * c);
                let nearest = index.nearest(&offset_point)?;
                if nearest == i || (offset_point - unit[nearest]).norm() >= OFFSET_CLEARANCE * c {
                    return Some(c);
                }
                c /= 2.0;
            }
            None
        };
        (0..unit.len())
            .map(|i| Offsets {
                inside: safe(i, -1.0),
                outside: safe(i, 1.0),
            })
            .collect()
    }

    #[test]
    fn offsets_match_the_nearest_point_rule_on_a_thin_section() {
        // A thin lens (1 by 0.02 at the middle, sharp at both ends), 2 000 points, with duplicated points: the
        // offsets shrink near the ends and inside, and must be exactly those of the nearest-point rule.
        let n = 2_000;
        let mut unit = Vec::new();
        let mut normals = Vec::new();
        for k in 0..n {
            let t = k as f64 / n as f64 * std::f64::consts::TAU;
            let (x, y) = (t.cos(), 0.02 * t.sin() * (1.0 - t.cos().powi(2)).sqrt());
            unit.push(Vector2::new(x, y));
            normals.push(Vector2::new(0.02 * t.cos(), t.sin()).normalize());
        }
        unit.extend_from_within(0..10);
        normals.extend_from_within(0..10);
        for largest in [0.003, 0.01, 0.03, 0.1] {
            let index = BallIndex::new(&unit);
            let fast = choose_offsets(&index, &unit, &normals, largest);
            assert_eq!(
                fast,
                by_nearest(&unit, &normals, largest),
                "largest {largest}"
            );
            let shrunk = fast.iter().filter(|o| o.inside != Some(largest)).count();
            assert!(shrunk > 0, "some inside offsets shrink at {largest}");
        }
    }
}
