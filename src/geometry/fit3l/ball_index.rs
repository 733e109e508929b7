//! Emptiness queries on balls over a fixed point set, for the 3L offsets: is any point other than one strictly
//! within a radius of a centre?
//!
//! Why not the R-tree of `nearest`: beside a dense scan an offset's ball nearly touches the curve at its own point,
//! so an empty ball must still visit the index's leaves along a few hundred points of the curve, and rstar's
//! general selection iterator (a work list of boxed nodes per query) spent three times as long walking its tree as
//! on the points (perf, BENCHMARKS.md). This is a static k-d tree of contiguous leaves walked with a fixed stack:
//! it visits other boxes than the R-tree did, but makes the same comparison on each point it reaches and gives the
//! same answer, at far less per visit. Split by count at the median of the widest side, so that many equal
//! coordinates (a stack's planes) cannot overflow a bucket.

use nalgebra::SVector;

/// Points per leaf.
const LEAF: usize = 16;

struct Node<const N: usize> {
    min: [f64; N],
    max: [f64; N],
    /// The node's points are `points[start..end]`.
    start: usize,
    end: usize,
    /// Its children's indices in `nodes`, none for a leaf.
    children: Option<(usize, usize)>,
}

pub(super) struct BallIndex<const N: usize> {
    nodes: Vec<Node<N>>,
    /// The points in leaf order, and each one's index in the slice the index was built from.
    points: Vec<SVector<f64, N>>,
    original: Vec<usize>,
}

impl<const N: usize> BallIndex<N> {
    pub(super) fn new(points: &[SVector<f64, N>]) -> Self {
        let mut order: Vec<usize> = (0..points.len()).collect();
        let mut nodes = Vec::new();
        if !points.is_empty() {
            build(points, &mut order, 0, &mut nodes);
        }
        Self {
            nodes,
            points: order.iter().map(|&i| points[i]).collect(),
            original: order,
        }
    }

    /// Some point other than the one at index `except` strictly within `radius` of `centre` (the same comparison,
    /// `|q - centre| < radius`, for every point it reaches), by its index in the input; the first found.
    pub(super) fn one_within(
        &self,
        centre: &SVector<f64, N>,
        radius: f64,
        except: usize,
    ) -> Option<usize> {
        if self.nodes.is_empty() {
            return None;
        }
        // A box is skipped only when it is clearly farther than the radius: a point at the radius itself, within
        // rounding, is left to the exact comparison.
        let reach = radius * radius * (1.0 + 1e-9);
        let mut stack = [0usize; 64];
        let mut depth = 1;
        while depth > 0 {
            depth -= 1;
            let node = &self.nodes[stack[depth]];
            let gap: f64 = (0..N)
                .map(|k| {
                    let d = (node.min[k] - centre[k])
                        .max(centre[k] - node.max[k])
                        .max(0.0);
                    d * d
                })
                .sum();
            if gap > reach {
                continue;
            }
            match node.children {
                Some((low, high)) => {
                    stack[depth] = low;
                    stack[depth + 1] = high;
                    depth += 2;
                }
                None => {
                    let hit = (node.start..node.end).find(|&j| {
                        self.original[j] != except && (self.points[j] - centre).norm() < radius
                    });
                    if let Some(j) = hit {
                        return Some(self.original[j]);
                    }
                }
            }
        }
        None
    }
}

/// Builds the node over `order[..]` (offset `start` in the whole order) and its subtree; returns its index.
fn build<const N: usize>(
    points: &[SVector<f64, N>],
    order: &mut [usize],
    start: usize,
    nodes: &mut Vec<Node<N>>,
) -> usize {
    let mut min = [f64::INFINITY; N];
    let mut max = [f64::NEG_INFINITY; N];
    for &i in order.iter() {
        for k in 0..N {
            min[k] = min[k].min(points[i][k]);
            max[k] = max[k].max(points[i][k]);
        }
    }
    let at = nodes.len();
    nodes.push(Node {
        min,
        max,
        start,
        end: start + order.len(),
        children: None,
    });
    if order.len() > LEAF {
        let axis = (0..N)
            .max_by(|&a, &b| (max[a] - min[a]).total_cmp(&(max[b] - min[b])))
            .expect("N > 0");
        let half = order.len() / 2;
        order.select_nth_unstable_by(half, |&a, &b| points[a][axis].total_cmp(&points[b][axis]));
        let (low, high) = order.split_at_mut(half);
        let low = build(points, low, start, nodes);
        let high = build(points, high, start + half, nodes);
        nodes[at].children = Some((low, high));
    }
    at
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};
    use rand::{Rng, SeedableRng};

    /// The answer by looking at every point.
    fn by_every_point<const N: usize>(
        points: &[SVector<f64, N>],
        centre: &SVector<f64, N>,
        radius: f64,
        except: usize,
    ) -> bool {
        (0..points.len()).any(|j| j != except && (points[j] - centre).norm() < radius)
    }

    #[test]
    fn answers_as_a_look_at_every_point_does_on_curves_clusters_and_repeated_coordinates() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(17);
        // A noisy circle, a tight cluster with repeated points, and points on a few planes (a stack's profiles).
        let mut curve: Vec<Vector2<f64>> = (0..3_000)
            .map(|k| {
                let t = k as f64 / 3_000.0 * std::f64::consts::TAU;
                Vector2::new(t.cos(), 0.3 * t.sin()) * (1.0 + rng.gen_range(-1e-4..1e-4))
            })
            .collect();
        curve.extend((0..200).map(|k| Vector2::new(0.5, 0.1 + (k % 7) as f64 * 1e-6)));
        let planes: Vec<Vector3<f64>> = (0..2_000)
            .map(|k| {
                let t = k as f64 / 400.0 * std::f64::consts::TAU;
                Vector3::new((k / 400) as f64, t.cos(), t.sin())
            })
            .collect();
        let mut checked = (0, 0);
        let curve_index = BallIndex::new(&curve);
        for _ in 0..4_000 {
            let except = rng.gen_range(0..curve.len());
            let centre =
                curve[except] + Vector2::new(rng.gen_range(-0.1..0.1), rng.gen_range(-0.1..0.1));
            let radius = rng.gen_range(1e-6..0.2);
            let expected = by_every_point(&curve, &centre, radius, except);
            let found = curve_index.one_within(&centre, radius, except);
            assert_eq!(found.is_some(), expected);
            // The point named is one that counts.
            if let Some(j) = found {
                assert!(j != except && (curve[j] - centre).norm() < radius);
            }
            checked.0 += usize::from(expected);
            // A ball through a point exactly: strictly within excludes it.
            let through = (curve[(except + 1) % curve.len()] - centre).norm();
            assert_eq!(
                curve_index.one_within(&centre, through, except).is_some(),
                by_every_point(&curve, &centre, through, except)
            );
        }
        let index = BallIndex::new(&planes);
        for _ in 0..2_000 {
            let except = rng.gen_range(0..planes.len());
            let centre = planes[except] + Vector3::new(rng.gen_range(-0.5..0.5), 0.01, -0.02);
            let radius = rng.gen_range(1e-3..1.0);
            let expected = by_every_point(&planes, &centre, radius, except);
            assert_eq!(
                index.one_within(&centre, radius, except).is_some(),
                expected
            );
            checked.1 += usize::from(expected);
        }
        // Both answers were met often enough to mean something.
        assert!(checked.0 > 400 && checked.0 < 3_600, "{checked:?}");
        assert!(checked.1 > 200 && checked.1 < 1_800, "{checked:?}");
        assert!(BallIndex::<2>::new(&[])
            .one_within(&Vector2::zeros(), 1.0, 0)
            .is_none());
        // The point left out is the one given, by its index in the input: a tiny ball on a point holds only it,
        // and a copy of it at another index counts.
        let lone = 1_234;
        assert_eq!(curve_index.one_within(&curve[lone], 1e-9, lone), None);
        assert_eq!(
            curve_index.one_within(&curve[lone], 1e-9, lone + 1),
            Some(lone)
        );
        let mut doubled = curve.clone();
        doubled.push(curve[lone]);
        assert_eq!(
            BallIndex::new(&doubled).one_within(&curve[lone], 1e-9, lone),
            Some(doubled.len() - 1)
        );
    }
}
