//! Where a closed, ordered profile's sharp edges are, from its points alone, and the faces between them.
//!
//! A direction along the profile is taken between points a span apart, not between neighbours: a scan crowds
//! its points at an edge (microns apart on a cosine-spaced section, one touched point repeated while a CMM's
//! ball rolls round a sharp edge), where 2 um of noise turns a neighbour-to-neighbour direction by tens of degrees.

use nalgebra::Vector2;

/// The span over which a direction is measured, as a fraction of the perimeter (0.4 mm on a 100 mm chord's
/// section). A round nose of radius r turns it by span / r: 14 deg on a NACA 2412 of 100 mm (r = 1.6 mm), 57 deg
/// on a NACA 0006 of 100 mm (r = 0.4 mm), against 165 deg and more at their sharp trailing edges.
const DIRECTION_SPAN: f64 = 0.002;
/// A point is a sharp edge where the direction turns by more than this over a span either side, rad (90 deg).
const CORNER_TURN_RAD: f64 = std::f64::consts::FRAC_PI_2;
/// Where a profile has one sharp edge, its faces meet smoothly half-way round; each face takes in this fraction of
/// the perimeter past that joint, so that both fit the same points there and meet within their fit.
const JOINT_OVERLAP: f64 = 0.05;

/// One face of a profile: the indices of its points, in order (wrapping round the end of the profile's points).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FacePoints {
    pub(crate) indices: Vec<usize>,
    /// Whether the face starts and ends at a sharp edge (else at a smooth joint with the neighbouring face).
    pub(crate) sharp_start: bool,
    pub(crate) sharp_end: bool,
}

/// The signed area's sign of a closed polygon: +1 counter-clockwise, -1 clockwise.
pub(crate) fn orientation(points: &[Vector2<f64>]) -> f64 {
    let n = points.len();
    let twice_area: f64 = (0..n).map(|i| points[i].perp(&points[(i + 1) % n])).sum();
    if twice_area >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

fn perimeter(points: &[Vector2<f64>]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| (points[(i + 1) % n] - points[i]).norm())
        .sum()
}

/// The index `k` steps from `i` round a closed profile of `n` points (k may be negative).
fn wrap(i: usize, k: isize, n: usize) -> usize {
    (i as isize + k).rem_euclid(n as isize) as usize
}

/// The first point at least `span` from point i, searching one way round (`way` +1 or -1); `None` if the whole
/// profile lies within the span.
fn point_a_span_away(points: &[Vector2<f64>], i: usize, way: isize, span: f64) -> Option<usize> {
    let n = points.len();
    (1..n as isize)
        .map(|k| wrap(i, way * k, n))
        .find(|&j| (points[j] - points[i]).norm() >= span)
}

/// The sharp edges of a closed profile whose points run along it: the indices where the direction turns by more
/// than [`CORNER_TURN_RAD`] over a span either side, one per edge (the sharpest of the points within a span).
pub(crate) fn find_corners(points: &[Vector2<f64>]) -> Vec<usize> {
    let n = points.len();
    if n < 6 {
        return Vec::new();
    }
    let span = DIRECTION_SPAN * perimeter(points);
    let turns: Vec<f64> = (0..n)
        .map(|i| {
            let (Some(before), Some(after)) = (
                point_a_span_away(points, i, -1, span),
                point_a_span_away(points, i, 1, span),
            ) else {
                return 0.0;
            };
            let (incoming, outgoing) = (points[i] - points[before], points[after] - points[i]);
            incoming
                .perp(&outgoing)
                .atan2(incoming.dot(&outgoing))
                .abs()
        })
        .collect();
    let mut candidates: Vec<usize> = (0..n).filter(|&i| turns[i] > CORNER_TURN_RAD).collect();
    candidates.sort_by(|&a, &b| turns[b].total_cmp(&turns[a]));
    let mut corners: Vec<usize> = Vec::new();
    for i in candidates {
        if corners
            .iter()
            .all(|&c| (points[c] - points[i]).norm() > 2.0 * span)
        {
            corners.push(i);
        }
    }
    corners.sort_unstable();
    corners
}

/// The faces of a closed profile with sharp edges at `corners` (sorted indices): one face from each edge to the
/// next, both edges' points included. With a single edge the profile is split again half-way round (by length),
/// where the faces overlap by [`JOINT_OVERLAP`] of the perimeter.
pub(crate) fn split_at_corners(points: &[Vector2<f64>], corners: &[usize]) -> Vec<FacePoints> {
    let n = points.len();
    let run = |from: usize, to: usize| -> Vec<usize> {
        let len = (to + n - from) % n;
        let len = if len == 0 { n } else { len };
        (0..=len).map(|k| (from + k) % n).collect()
    };
    match corners {
        [] => Vec::new(),
        [corner] => {
            let total = perimeter(points);
            let mut along = 0.0;
            let mut joint = *corner;
            let mut overlap_before = None;
            let mut overlap_after = None;
            for k in 0..n {
                let (i, next) = ((corner + k) % n, (corner + k + 1) % n);
                along += (points[next] - points[i]).norm();
                if overlap_before.is_none() && along >= (0.5 - JOINT_OVERLAP) * total {
                    overlap_before = Some(next);
                }
                if joint == *corner && along >= 0.5 * total {
                    joint = next;
                }
                if along >= (0.5 + JOINT_OVERLAP) * total {
                    overlap_after = Some(next);
                    break;
                }
            }
            let (before, after) = (
                overlap_before.unwrap_or(joint),
                overlap_after.unwrap_or(joint),
            );
            vec![
                FacePoints {
                    indices: run(*corner, after),
                    sharp_start: true,
                    sharp_end: false,
                },
                FacePoints {
                    indices: run(before, *corner),
                    sharp_start: false,
                    sharp_end: true,
                },
            ]
        }
        _ => (0..corners.len())
            .map(|k| FacePoints {
                indices: run(corners[k], corners[(k + 1) % corners.len()]),
                sharp_start: true,
                sharp_end: true,
            })
            .collect(),
    }
}

/// The points' index where a face with a smooth end joins the next face: half-way round from the one sharp edge.
/// (Both faces of a one-edge profile overlap there; the joint is the middle of the overlap.)
pub(crate) fn joint_of(faces: &[FacePoints]) -> Option<usize> {
    match faces {
        [first, second] if !first.sharp_end => {
            let shared: Vec<usize> = first
                .indices
                .iter()
                .copied()
                .filter(|i| second.indices.contains(i))
                .filter(|&i| i != first.indices[0])
                .collect();
            shared.get(shared.len() / 2).copied()
        }
        _ => None,
    }
}

/// Outward unit normals of a face's points (in order along a profile oriented `orientation`, see
/// [`orientation`]), each from the chord between the face's points a span either side (one-sided at the face's
/// ends, so that no normal looks across a sharp edge to the other face).
pub(crate) fn face_normals(
    points: &[Vector2<f64>],
    face: &[usize],
    orientation: f64,
    perimeter_mm: f64,
) -> Vec<Vector2<f64>> {
    let span = 0.5 * DIRECTION_SPAN * perimeter_mm;
    let at = |k: usize| points[face[k]];
    (0..face.len())
        .map(|k| {
            let back = (0..k)
                .rev()
                .find(|&j| (at(j) - at(k)).norm() >= span)
                .unwrap_or(0);
            let ahead = (k + 1..face.len())
                .find(|&j| (at(j) - at(k)).norm() >= span)
                .unwrap_or(face.len() - 1);
            let tangent = at(ahead) - at(back);
            let normal = Vector2::new(tangent.y, -tangent.x) * orientation;
            normal.try_normalize(0.0).unwrap_or_else(Vector2::x)
        })
        .collect()
}

pub(crate) fn perimeter_mm(points: &[Vector2<f64>]) -> f64 {
    perimeter(points)
}

#[cfg(test)]
mod tests {
    use super::*;
    use zeroset_sim::naca::Naca4;

    fn section(digits: &str, chord: f64, count: usize) -> Vec<Vector2<f64>> {
        let foil = Naca4::from_digits(digits, chord, true).unwrap();
        foil.points(count).into_iter().map(Vector2::from).collect()
    }

    #[test]
    fn a_sharp_trailing_edge_is_one_corner_and_a_round_nose_none() {
        for (digits, chord) in [("2412", 100.0), ("0006", 100.0), ("6412", 250.0)] {
            let points = section(digits, chord, 400);
            // Point 0 is the trailing edge; the leading edge (point 200) is round.
            assert_eq!(
                find_corners(&points),
                vec![0],
                "NACA {digits} at {chord} mm"
            );
        }
    }

    #[test]
    fn one_edge_gives_two_faces_overlapping_half_way_round() {
        let points = section("2412", 100.0, 400);
        let faces = split_at_corners(&points, &[0]);
        assert_eq!(faces.len(), 2);
        assert_eq!(faces[0].indices[0], 0);
        assert_eq!(*faces[1].indices.last().unwrap(), 0);
        assert!(faces[0].sharp_start && !faces[0].sharp_end);
        assert!(!faces[1].sharp_start && faces[1].sharp_end);
        // The leading edge (index 200 by symmetry of the parameter) is inside the overlap and is the joint.
        assert!(faces[0].indices.contains(&215) && faces[1].indices.contains(&185));
        let joint = joint_of(&faces).unwrap();
        assert!((195..=205).contains(&joint), "{joint}");
    }

    #[test]
    fn two_edges_give_two_faces_from_edge_to_edge() {
        // A lens: two circular arcs of radius 18 mm meeting at sharp ends (-10, 0) and (10, 0).
        let r = (10.0f64 * 10.0 + 15.0 * 15.0).sqrt();
        let half = (10.0 / r).asin();
        let mut points = Vec::new();
        for k in 0..40 {
            // Lower arc (centre (0, 15)) from (-10, 0) to (10, 0), then the upper (centre (0, -15)) back.
            let t = -std::f64::consts::FRAC_PI_2 - half + 2.0 * half * k as f64 / 40.0;
            points.push(Vector2::new(r * t.cos(), 15.0 + r * t.sin()));
        }
        for k in 0..40 {
            let t = std::f64::consts::FRAC_PI_2 - half + 2.0 * half * k as f64 / 40.0;
            points.push(Vector2::new(r * t.cos(), -15.0 + r * t.sin()));
        }
        let corners = find_corners(&points);
        assert_eq!(corners, vec![0, 40]);
        let faces = split_at_corners(&points, &corners);
        assert_eq!(faces.len(), 2);
        assert_eq!(faces[0].indices, (0..=40).collect::<Vec<_>>());
        assert_eq!(
            faces[1].indices,
            (40..80).chain(std::iter::once(0)).collect::<Vec<_>>()
        );
    }
}
