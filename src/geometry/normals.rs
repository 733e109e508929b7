//! Outward unit normals of measured points: from the order of a closed planar profile, or by local principal
//! component analysis with a consistent orientation for unordered points (2-D or 3-D).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::{SMatrix, SVector, Vector2};

use super::nearest::PointIndex;
use super::small;

/// Neighbours used for local PCA: enough to average out 2 um probe noise without smoothing over a trailing edge.
const PCA_NEIGHBOURS: usize = 10;

/// A profile whose last point lies farther from its first than this many times its end steps (from the first
/// point to the second, from the last but one to the last) is an open arc (a scan of part of a section): its end
/// points have no neighbour across the gap.
const OPEN_ARC_GAP_STEPS: f64 = 3.0;

/// Normals of an ordered profile: perpendicular to the central-difference tangent, pointing away from the enclosed
/// area (for an open arc, the area its chord between the ends closes) whichever way the profile runs. The ends of
/// an open arc take the one-sided tangent. Needs at least three points.
pub fn ordered_profile_normals(points: &[Vector2<f64>]) -> Vec<Vector2<f64>> {
    let n = points.len();
    let twice_area: f64 = (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            a.x * b.y - a.y * b.x
        })
        .sum();
    // Counter-clockwise profiles have their outside on the right of the direction of travel.
    let outward_sign = if twice_area >= 0.0 { 1.0 } else { -1.0 };
    let open = is_open_arc(points);
    (0..n)
        .map(|i| {
            let before = if open && i == 0 { 0 } else { (i + n - 1) % n };
            let after = if open && i == n - 1 {
                n - 1
            } else {
                (i + 1) % n
            };
            let tangent = points[after] - points[before];
            let normal = Vector2::new(tangent.y, -tangent.x) * outward_sign;
            normal.try_normalize(0.0).unwrap_or_else(Vector2::x)
        })
        .collect()
}

/// Whether the gap from the last point back to the first is several times the steps beside it (the local
/// spacing: a closed scan dense round its edges and sparse along its faces has a gap like its steps there).
fn is_open_arc(points: &[Vector2<f64>]) -> bool {
    let n = points.len();
    if n < 3 {
        return false;
    }
    let beside = (points[1] - points[0])
        .norm()
        .max((points[n - 1] - points[n - 2]).norm());
    (points[n - 1] - points[0]).norm() > OPEN_ARC_GAP_STEPS * beside
}

/// Normals of unordered points by local PCA (the direction of least spread among the nearest neighbours),
/// oriented consistently by growing a tree from the point farthest from the centroid (whose normal must point away
/// from the centroid) and always taking next the neighbour whose normal is most nearly parallel (Hoppe et al. 1992).
pub fn pca_normals<const N: usize>(points: &[SVector<f64, N>]) -> Vec<SVector<f64, N>> {
    let index = PointIndex::new(points);
    let k = PCA_NEIGHBOURS.min(points.len());
    let neighbours: Vec<Vec<usize>> = points
        .iter()
        .map(|p| index.nearest_iter(p).take(k).collect())
        .collect();
    let mut normals: Vec<SVector<f64, N>> = neighbours
        .iter()
        .map(|nb| least_spread_direction(points, nb))
        .collect();
    orient(points, &neighbours, &mut normals);
    normals
}

fn least_spread_direction<const N: usize>(
    points: &[SVector<f64, N>],
    neighbours: &[usize],
) -> SVector<f64, N> {
    let mean = neighbours
        .iter()
        .map(|&j| points[j])
        .sum::<SVector<f64, N>>()
        / neighbours.len() as f64;
    let covariance = neighbours
        .iter()
        .map(|&j| {
            let d = points[j] - mean;
            d * d.transpose()
        })
        .fold(SMatrix::<f64, N, N>::zeros(), |a, b| a + b);
    small::symmetric_eigen(&covariance)[0].1
}

#[derive(PartialEq)]
struct Candidate {
    alignment: f64,
    from: usize,
    to: usize,
}

impl Eq for Candidate {}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Candidate {
    fn cmp(&self, other: &Self) -> Ordering {
        self.alignment.total_cmp(&other.alignment)
    }
}

fn orient<const N: usize>(
    points: &[SVector<f64, N>],
    neighbours: &[Vec<usize>],
    normals: &mut [SVector<f64, N>],
) {
    let n = points.len();
    let centroid = points.iter().sum::<SVector<f64, N>>() / n as f64;
    let mut visited = vec![false; n];
    // Each pass orients one connected patch of the neighbour graph from its own extreme point.
    while let Some(start) = (0..n).filter(|&i| !visited[i]).max_by(|&a, &b| {
        (points[a] - centroid)
            .norm()
            .total_cmp(&(points[b] - centroid).norm())
    }) {
        if normals[start].dot(&(points[start] - centroid)) < 0.0 {
            normals[start] = -normals[start];
        }
        visited[start] = true;
        let mut heap = BinaryHeap::new();
        push_neighbours(start, neighbours, normals, &visited, &mut heap);
        while let Some(Candidate { from, to, .. }) = heap.pop() {
            if visited[to] {
                continue;
            }
            if normals[to].dot(&normals[from]) < 0.0 {
                normals[to] = -normals[to];
            }
            visited[to] = true;
            push_neighbours(to, neighbours, normals, &visited, &mut heap);
        }
    }
}

fn push_neighbours<const N: usize>(
    from: usize,
    neighbours: &[Vec<usize>],
    normals: &[SVector<f64, N>],
    visited: &[bool],
    heap: &mut BinaryHeap<Candidate>,
) {
    for &to in &neighbours[from] {
        if !visited[to] {
            heap.push(Candidate {
                alignment: normals[from].dot(&normals[to]).abs(),
                from,
                to,
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn circle(n: usize, clockwise: bool) -> Vec<Vector2<f64>> {
        (0..n)
            .map(|i| {
                let t = i as f64 / n as f64
                    * std::f64::consts::TAU
                    * if clockwise { -1.0 } else { 1.0 };
                Vector2::new(3.0 + 2.0 * t.cos(), -1.0 + 2.0 * t.sin())
            })
            .collect()
    }

    #[test]
    fn ordered_normals_point_outward_either_direction() {
        for clockwise in [false, true] {
            let pts = circle(50, clockwise);
            for (p, n) in pts.iter().zip(ordered_profile_normals(&pts)) {
                let radial = (p - Vector2::new(3.0, -1.0)).normalize();
                assert!(
                    n.dot(&radial) > 0.999,
                    "clockwise={clockwise}: {n} vs {radial}"
                );
            }
        }
    }

    #[test]
    fn an_open_arc_s_ends_take_their_own_tangent_not_the_gap_s() {
        // Two thirds of the circle, either way round: across the gap from the last point to the first, a
        // central difference would turn the end normals by 60 deg.
        for clockwise in [false, true] {
            let arc = &circle(60, clockwise)[..40];
            let normals = ordered_profile_normals(arc);
            for (i, (p, n)) in arc.iter().zip(&normals).enumerate() {
                let radial = (p - Vector2::new(3.0, -1.0)).normalize();
                let tolerance = if i == 0 || i == arc.len() - 1 {
                    // one-sided: the chord's normal lies half a step's turn (3 deg) off the radius
                    0.998
                } else {
                    0.999
                };
                assert!(
                    n.dot(&radial) > tolerance,
                    "clockwise={clockwise}, point {i}: {n} vs {radial}"
                );
            }
        }
    }

    #[test]
    fn pca_normals_of_a_shuffled_sphere_point_outward() {
        // A Fibonacci sphere: evenly spread points, so every neighbourhood is a fair patch of surface.
        let count = 1500;
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let pts: Vec<_> = (0..count)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * i as f64;
                Vector3::new(r * phi.cos(), r * phi.sin(), z) * 5.0
            })
            .collect();
        // A fixed shuffle, so that the order carries no information.
        let n = pts.len();
        let shuffled: Vec<_> = (0..n).map(|i| pts[(i * 7919) % n]).collect();
        let wrong: Vec<_> = shuffled
            .iter()
            .zip(pca_normals(&shuffled))
            .filter(|(p, normal)| normal.dot(&p.normalize()) < 0.99)
            .map(|(p, n)| (p.normalize(), n))
            .collect();
        assert!(
            wrong.is_empty(),
            "{} wrong, first {:?}",
            wrong.len(),
            wrong.first()
        );
    }
}
