//! The 3L level-set offsets: per point and side, the largest offset c (from a given largest, halved up to
//! OFFSET_HALVINGS times) whose offset point is no nearer any other data point than OFFSET_CLEARANCE c, so that an
//! offset never reaches past the medial axis of a thin section.
//!
//! The test is an emptiness query on a ball (is any other point strictly within 0.98 c?), which stops at the
//! first point found and only visits the index near the ball, instead of a nearest-neighbour search: beside a dense
//! scan the offset point's nearest points are all about c away, and a nearest search keeps thousands of them in its
//! queue. One index ([`BallIndex`]) serves every candidate of a fit; points are done in parallel, each point's
//! ladders for every largest offset together, so that what one rung found serves the others (see [`Side`]).

use nalgebra::SVector;
use rayon::prelude::*;

use super::ball_index::BallIndex;

/// An offset point must be at least this fraction of its offset away from every other data point.
const OFFSET_CLEARANCE: f64 = 0.98;
const OFFSET_HALVINGS: usize = 12;
/// How many of the points that blocked a side's rungs are remembered and tried first.
const REMEMBERED: usize = 4;

/// The 3L offsets of one point, in normalised units; `None` where no safe offset exists on that side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Offsets {
    pub(super) inside: Option<f64>,
    pub(super) outside: Option<f64>,
}

/// The offsets of every point for each of `largests` (one set per largest, in its order). `index` indexes `unit`.
pub(super) fn choose_offsets<const N: usize>(
    index: &BallIndex<N>,
    unit: &[SVector<f64, N>],
    normals: &[SVector<f64, N>],
    largests: &[f64],
) -> Vec<Vec<Offsets>> {
    let per_point: Vec<Vec<Offsets>> = (0..unit.len())
        .into_par_iter()
        .map(|i| {
            let mut inside = Side::new(index, unit, normals, i, -1.0);
            let mut outside = Side::new(index, unit, normals, i, 1.0);
            largests
                .iter()
                .map(|&largest| Offsets {
                    inside: inside.safe(largest),
                    outside: outside.safe(largest),
                })
                .collect()
        })
        .collect();
    (0..largests.len())
        .map(|k| per_point.iter().map(|offsets| offsets[k]).collect())
        .collect()
}

/// One side of one point, and the points that blocked its rungs so far.
///
/// Why remember them: beside a noisy scan the ladders halve many times (a neighbour a little off the curve pokes
/// into every ball from about 50 times its height down to its spacing squared over twice the height), and the
/// point that blocked one rung mostly blocks the next and the other ladders' rungs too. A look at it, or at the
/// point's neighbours along the scan, is one distance, where a query of the index visits some thirty boxes; the
/// index is asked only when none of them is in the ball. The answer is the index's: a rung is blocked exactly when
/// some other point is strictly within its ball, by the same comparison.
struct Side<'a, const N: usize> {
    index: &'a BallIndex<N>,
    unit: &'a [SVector<f64, N>],
    normals: &'a [SVector<f64, N>],
    point: usize,
    direction: f64,
    blockers: [usize; REMEMBERED],
    known: usize,
    next: usize,
}

impl<'a, const N: usize> Side<'a, N> {
    fn new(
        index: &'a BallIndex<N>,
        unit: &'a [SVector<f64, N>],
        normals: &'a [SVector<f64, N>],
        point: usize,
        direction: f64,
    ) -> Self {
        Self {
            index,
            unit,
            normals,
            point,
            direction,
            blockers: [0; REMEMBERED],
            known: 0,
            next: 0,
        }
    }

    /// The ladder from `largest`: its first rung whose ball is empty.
    fn safe(&mut self, largest: f64) -> Option<f64> {
        let mut c = largest;
        for _ in 0..OFFSET_HALVINGS {
            if !self.blocked(c) {
                return Some(c);
            }
            c /= 2.0;
        }
        None
    }

    /// Whether another data point lies strictly within OFFSET_CLEARANCE c of the offset point at c.
    fn blocked(&mut self, c: f64) -> bool {
        let i = self.point;
        let offset_point = self.unit[i] + self.normals[i] * (self.direction * c);
        let clearance = OFFSET_CLEARANCE * c;
        let within = |j: usize| (self.unit[j] - offset_point).norm() < clearance;
        let neighbours = [i.wrapping_sub(1), i + 1];
        if self.blockers[..self.known].iter().any(|&j| within(j))
            || neighbours.iter().any(|&j| j < self.unit.len() && within(j))
        {
            return true;
        }
        match self.index.one_within(&offset_point, clearance, i) {
            Some(j) => {
                self.blockers[self.next] = j;
                self.next = (self.next + 1) % REMEMBERED;
                self.known = (self.known + 1).min(REMEMBERED);
                true
            }
            None => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::nearest::PointIndex;
    use nalgebra::{Vector2, Vector3};
    use rand::seq::SliceRandom;
    use rand::{Rng, SeedableRng};

    /// The old path: the nearest data point of the offset point must be the point itself or 0.98 c away.
    fn by_nearest<const N: usize>(
        unit: &[SVector<f64, N>],
        normals: &[SVector<f64, N>],
        largest: f64,
    ) -> Vec<Offsets> {
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

    /// The offsets of every ladder a 3L fit climbs, computed together, each asserted to be the nearest-point
    /// rule's; with their largest offsets.
    fn every_ladder_by_the_nearest_point_rule<const N: usize>(
        unit: &[SVector<f64, N>],
        normals: &[SVector<f64, N>],
    ) -> Vec<(Vec<Offsets>, f64)> {
        let largests = [0.003, 0.01, 0.03, 0.1];
        let sets = choose_offsets(&BallIndex::new(unit), unit, normals, &largests);
        for (fast, largest) in sets.iter().zip(largests) {
            assert_eq!(
                fast,
                &by_nearest(unit, normals, largest),
                "largest {largest}"
            );
        }
        sets.into_iter().zip(largests).collect()
    }

    #[test]
    fn offsets_match_the_nearest_point_rule_on_a_thin_noisy_section_in_any_order() {
        // A thin lens (1 by 0.02 at the middle, sharp at both ends), 2 000 points with noise along the normal (so
        // that neighbours block the middle rungs and the ladders halve), and duplicated points: the offsets shrink
        // near the ends and inside, and every ladder, all computed together, must be exactly the nearest-point
        // rule's; in scan order and shuffled (where the points beside one in the slice are not its neighbours).
        let n = 2_000;
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let mut unit = Vec::new();
        let mut normals = Vec::new();
        for k in 0..n {
            let t = k as f64 / n as f64 * std::f64::consts::TAU;
            let (x, y) = (t.cos(), 0.02 * t.sin() * (1.0 - t.cos().powi(2)).sqrt());
            let normal = Vector2::new(0.02 * t.cos(), t.sin()).normalize();
            unit.push(Vector2::new(x, y) + normal * rng.gen_range(-5e-4..5e-4));
            normals.push(normal);
        }
        unit.extend_from_within(0..10);
        normals.extend_from_within(0..10);
        let mut shuffled: Vec<usize> = (0..unit.len()).collect();
        shuffled.shuffle(&mut rng);
        for order in [(0..unit.len()).collect(), shuffled] {
            let unit: Vec<Vector2<f64>> = order.iter().map(|&i| unit[i]).collect();
            let normals: Vec<Vector2<f64>> = order.iter().map(|&i| normals[i]).collect();
            let mut halved_twice = 0;
            for (fast, largest) in every_ladder_by_the_nearest_point_rule(&unit, &normals) {
                let shrunk = fast.iter().filter(|o| o.inside != Some(largest)).count();
                assert!(shrunk > 0, "some inside offsets shrink at {largest}");
                halved_twice += fast
                    .iter()
                    .flat_map(|o| [o.inside, o.outside])
                    .filter(|c| c.is_some_and(|c| c < largest / 3.0))
                    .count();
            }
            // Many rungs were blocked by a point an earlier rung found: the path that remembers them was taken.
            assert!(halved_twice > 1_000, "{halved_twice} ladders halved twice");
        }
    }

    #[test]
    fn offsets_match_the_nearest_point_rule_on_a_thin_noisy_shell() {
        // 3-D: a flat spheroid (semi-axes 1, 1 and 0.05; its rim's radius of curvature 0.0025), 3 000 points
        // spread by the golden angle with noise along the normal. Inside, the offsets must stop at the middle
        // plane; every ladder must be the nearest-point rule's.
        let n = 3_000;
        let mut rng = rand::rngs::StdRng::seed_from_u64(5);
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let (mut unit, mut normals) = (Vec::new(), Vec::new());
        for k in 0..n {
            let z = 1.0 - 2.0 * (k as f64 + 0.5) / n as f64;
            let (ring, phi) = ((1.0 - z * z).sqrt(), golden * k as f64);
            let on = Vector3::new(ring * phi.cos(), ring * phi.sin(), 0.05 * z);
            let normal = Vector3::new(on.x, on.y, on.z / 0.0025).normalize();
            unit.push(on + normal * rng.gen_range(-2e-4..2e-4));
            normals.push(normal);
        }
        let mut shrunk = 0;
        for (fast, largest) in every_ladder_by_the_nearest_point_rule(&unit, &normals) {
            shrunk += fast.iter().filter(|o| o.inside != Some(largest)).count();
        }
        assert!(shrunk > n, "{shrunk} inside offsets shrink");
    }
}
