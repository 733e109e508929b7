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
/// An edge's turn over an eighth of the span is at least this fraction of its turn over the whole span.
const CONCENTRATED: f64 = 0.75;
/// A turn over a step longer than this many median steps (and than the span) is a stray point's, not an edge's.
const STRAY_STEPS: f64 = 20.0;
/// Where a profile has one sharp edge, it is split again at smooth joints this far round from the edge, as
/// fractions of the perimeter: on a blade, into the faces beside the trailing edge and the nose between them, so
/// that no joint falls on the nose and no face has to follow both a nose and a long flat face. Measured on NACA
/// sections (BENCHMARKS.md): joints at 0.3 and 0.35 fall on the NACA camber line's change of curvature at 40% of
/// chord, where two fits each smoothing it differ by up to 8 um; 0.25 stays clear of it.
const JOINTS_OF_ONE_EDGE: [f64; 2] = [0.25, 0.75];
/// Faces take in this fraction of the perimeter past each smooth joint, so that both fit the same points there
/// and meet within their fit.
const JOINT_OVERLAP: f64 = 0.05;

/// Where a face ends: at a sharp edge or a smooth joint, at the profile's point of this index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct FaceEnd {
    pub(crate) at: usize,
    pub(crate) sharp: bool,
}

/// One face of a profile: the indices of its points, in order (wrapping round the end of the profile's points),
/// and where it meets the faces before and after it.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FacePoints {
    pub(crate) indices: Vec<usize>,
    pub(crate) start: FaceEnd,
    pub(crate) end: FaceEnd,
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

pub(crate) fn perimeter(points: &[Vector2<f64>]) -> f64 {
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
/// profile lies within the span, or if a step on the way is longer than `longest_step` (a jump to or from a stray
/// point: no direction of the profile there).
fn point_a_span_away(
    points: &[Vector2<f64>],
    i: usize,
    way: isize,
    span: f64,
    longest_step: f64,
) -> Option<usize> {
    let n = points.len();
    let mut previous = i;
    for k in 1..n as isize {
        let j = wrap(i, way * k, n);
        if (points[j] - points[previous]).norm() > longest_step {
            return None;
        }
        if (points[j] - points[i]).norm() >= span {
            return Some(j);
        }
        previous = j;
    }
    None
}

/// How far the profile turns at point i between the points `span` before and after it, rad; 0 where it has no
/// direction (see [`point_a_span_away`]).
fn turn_at(points: &[Vector2<f64>], i: usize, span: f64, longest_step: f64) -> f64 {
    let (Some(before), Some(after)) = (
        point_a_span_away(points, i, -1, span, longest_step),
        point_a_span_away(points, i, 1, span, longest_step),
    ) else {
        return 0.0;
    };
    let (incoming, outgoing) = (points[i] - points[before], points[after] - points[i]);
    incoming
        .perp(&outgoing)
        .atan2(incoming.dot(&outgoing))
        .abs()
}

/// The span over which a profile's direction is measured, and the longest step across which it is: a stray point,
/// and its neighbours, turn the profile by up to 180 deg too, over steps far longer than the scan's (a stray, named
/// to the operator as such, not an edge).
fn direction_scales(points: &[Vector2<f64>]) -> (f64, f64) {
    let n = points.len();
    let span = DIRECTION_SPAN * perimeter(points);
    let mut steps: Vec<f64> = (0..n)
        .map(|i| (points[(i + 1) % n] - points[i]).norm())
        .collect();
    steps.sort_by(f64::total_cmp);
    (span, (STRAY_STEPS * steps[n / 2]).max(span))
}

/// The angle between the two faces at the sharp edge at point `corner` (rad): 180 deg less the profile's turn
/// there over a span either side, where both faces are nearly straight (a NACA 0006's trailing edge: 8 deg).
pub(crate) fn edge_angle(points: &[Vector2<f64>], corner: usize) -> f64 {
    let (span, longest_step) = direction_scales(points);
    std::f64::consts::PI - turn_at(points, corner, span, longest_step)
}

/// The sharp edges of a closed profile whose points run along it: the indices where the direction turns by more
/// than [`CORNER_TURN_RAD`] over a span either side, one per edge (the sharpest of the points within a span).
pub(crate) fn find_corners(points: &[Vector2<f64>]) -> Vec<usize> {
    let n = points.len();
    if n < 6 {
        return Vec::new();
    }
    let (span, longest_step) = direction_scales(points);
    // An edge turns the profile at a point: over an eighth of the span it turns nearly as far as over the whole.
    // A round nose turns it in proportion to the length (a thin section's nose turns it by more than 90 deg over
    // the span: NACA 0003's, of 0.1 mm radius at 100 mm chord, by 105-111 deg, and by 28-39 deg over an eighth;
    // its trailing edge by 176 deg over either).
    let turns: Vec<f64> = (0..n)
        .map(|i| {
            let turn = turn_at(points, i, span, longest_step);
            if turn > CORNER_TURN_RAD
                && turn_at(points, i, span / 8.0, longest_step) < CONCENTRATED * turn
            {
                0.0
            } else {
                turn
            }
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
            corners.push(apex_near(points, i, span, longest_step));
        }
    }
    corners.sort_unstable();
    corners
}

/// The edge's own point among those within a span of point i, where the profile turns most sharply: the one
/// farthest along d_in - d_out (the directions into and out of the edge over the span), which is where the two
/// faces' lines meet whether the edge is convex or concave. Where the points crowd round a thin edge (cosine-spaced
/// scans: 20-30 um apart at a NACA trailing edge) the turn over the span is the same within the noise at the edge's
/// point and at its neighbours, and the sharpest by turn was once a point 57 um along the face (NACA 7606 at 250
/// mm), so the faces were made to cross there; along the bisector a neighbour t away lies nearly 2 t back, far
/// beyond the noise.
fn apex_near(points: &[Vector2<f64>], i: usize, span: f64, longest_step: f64) -> usize {
    let n = points.len();
    let (Some(before), Some(after)) = (
        point_a_span_away(points, i, -1, span, longest_step),
        point_a_span_away(points, i, 1, span, longest_step),
    ) else {
        return i;
    };
    let (Some(incoming), Some(outgoing)) = (
        (points[i] - points[before]).try_normalize(0.0),
        (points[after] - points[i]).try_normalize(0.0),
    ) else {
        return i;
    };
    let towards_apex = incoming - outgoing;
    let within = (after + n - before) % n;
    (0..=within)
        .map(|k| (before + k) % n)
        .max_by(|&a, &b| {
            points[a]
                .dot(&towards_apex)
                .total_cmp(&points[b].dot(&towards_apex))
        })
        .unwrap_or(i)
}

/// The faces of a closed profile with sharp edges at `corners` (sorted indices): one face from each edge to the
/// next, both edges' points included. A single edge's profile is split again at [`JOINTS_OF_ONE_EDGE`], where the
/// faces overlap by [`JOINT_OVERLAP`] of the perimeter either side.
pub(crate) fn split_at_corners(points: &[Vector2<f64>], corners: &[usize]) -> Vec<FacePoints> {
    let n = points.len();
    let run = |from: usize, to: usize| -> Vec<usize> {
        let len = (to + n - from) % n;
        let len = if len == 0 { n } else { len };
        (0..=len).map(|k| (from + k) % n).collect()
    };
    let sharp = |at: usize| FaceEnd { at, sharp: true };
    match corners {
        [] => Vec::new(),
        [corner] => {
            // The point first reached at each fraction of the perimeter from the edge.
            let total = perimeter(points);
            let mut along = vec![0.0; n + 1];
            for k in 0..n {
                let (i, next) = ((corner + k) % n, (corner + k + 1) % n);
                along[k + 1] = along[k] + (points[next] - points[i]).norm();
            }
            let reached = |fraction: f64| -> usize {
                let k = along.partition_point(|&a| a < fraction * total).min(n);
                (corner + k) % n
            };
            let mut ends = vec![sharp(*corner)];
            ends.extend(JOINTS_OF_ONE_EDGE.iter().map(|&f| FaceEnd {
                at: reached(f),
                sharp: false,
            }));
            ends.push(sharp(*corner));
            ends.windows(2)
                .enumerate()
                .map(|(k, pair)| {
                    let from = if pair[0].sharp {
                        pair[0].at
                    } else {
                        reached(JOINTS_OF_ONE_EDGE[k - 1] - JOINT_OVERLAP)
                    };
                    let to = if pair[1].sharp {
                        pair[1].at
                    } else {
                        reached(JOINTS_OF_ONE_EDGE[k] + JOINT_OVERLAP)
                    };
                    FacePoints {
                        indices: run(from, to),
                        start: pair[0],
                        end: pair[1],
                    }
                })
                .collect()
        }
        _ => (0..corners.len())
            .map(|k| {
                let (from, to) = (corners[k], corners[(k + 1) % corners.len()]);
                FacePoints {
                    indices: run(from, to),
                    start: sharp(from),
                    end: sharp(to),
                }
            })
            .collect(),
    }
}

/// The positions in `face.indices` of its own span's ends: where it meets the faces before and after it (a smooth
/// joint lies inside the overlap the face shares with its neighbour).
pub(crate) fn own_span(face: &FacePoints) -> (usize, usize) {
    let last = face.indices.len() - 1;
    let position = |end: FaceEnd, default: usize| {
        if end.sharp {
            default
        } else {
            face.indices
                .iter()
                .position(|&i| i == end.at)
                .unwrap_or(default)
        }
    };
    (position(face.start, 0), position(face.end, last))
}

/// The face split in two at a smooth joint at its point `k` (a position in `face.indices`), the two overlapping by
/// [`JOINT_OVERLAP`] of the perimeter either side of the joint, as the faces of [`split_at_corners`] do, but never
/// past the face's own span's ends.
pub(crate) fn split_face(
    points: &[Vector2<f64>],
    face: &FacePoints,
    k: usize,
    perimeter_mm: f64,
) -> [FacePoints; 2] {
    let (first, last) = own_span(face);
    let at = |j: usize| points[face.indices[j]];
    let overlap = JOINT_OVERLAP * perimeter_mm;
    let mut before = k;
    let mut length = 0.0;
    while before > first && length < overlap {
        length += (at(before) - at(before - 1)).norm();
        before -= 1;
    }
    let mut after = k;
    length = 0.0;
    while after < last && length < overlap {
        length += (at(after + 1) - at(after)).norm();
        after += 1;
    }
    let joint = FaceEnd {
        at: face.indices[k],
        sharp: false,
    };
    [
        FacePoints {
            indices: face.indices[..=after].to_vec(),
            start: face.start,
            end: joint,
        },
        FacePoints {
            indices: face.indices[before..].to_vec(),
            start: joint,
            end: face.end,
        },
    ]
}

/// Outward unit normals of a face's points (in order along a counter-clockwise profile of perimeter
/// `perimeter_mm`), each from the chord between the face's points half a span either side (one-sided at the face's
/// ends, so that no normal looks across a sharp edge to the other face).
pub(crate) fn face_normals(
    points: &[Vector2<f64>],
    face: &[usize],
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
            // Counter-clockwise round the material, the outside is on the right.
            let normal = Vector2::new(tangent.y, -tangent.x);
            normal.try_normalize(0.0).unwrap_or_else(Vector2::x)
        })
        .collect()
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
        // Scanned at 400 points round and densely (20 000: steps of 1 um at the edges, 30 um mid-chord), and a
        // section so thin that its nose turns by 105 deg over the span.
        for (digits, chord) in [
            ("2412", 100.0),
            ("0006", 100.0),
            ("0003", 100.0),
            ("6412", 250.0),
        ] {
            for count in [400, 20_000] {
                let points = section(digits, chord, count);
                // Point 0 is the trailing edge; the leading edge (point count / 2) is round.
                assert_eq!(
                    find_corners(&points),
                    vec![0],
                    "NACA {digits} at {chord} mm, {count} points"
                );
            }
        }
    }

    #[test]
    fn a_symmetric_section_s_trailing_edge_angle_is_read_from_its_points() {
        // NACA 00tt with the closed edge's coefficient: each face leaves the edge at a slope of 5 t (0.2969 / 2 -
        // 0.1260 - 2 x 0.3516 + 3 x 0.2843 - 4 x 0.1036) = -1.21025 t.
        for (digits, t) in [("0006", 0.06), ("0012", 0.12), ("0024", 0.24)] {
            let exact = 2.0 * (1.21025f64 * t).atan();
            for count in [400, 4000] {
                let angle = edge_angle(&section(digits, 100.0, count), 0);
                assert!(
                    (angle - exact).abs() < 0.2f64.to_radians(),
                    "NACA {digits}, {count} points: {} deg, the section's {} deg",
                    angle.to_degrees(),
                    exact.to_degrees()
                );
            }
        }
    }

    #[test]
    fn a_thin_edge_among_crowded_points_is_the_point_farthest_along_its_bisector() {
        // NACA 7606 at 250 mm, 400 points cosine-spaced (25 um apart at the trailing edge, an 8 deg edge), 2 um of
        // noise along the normal: on draw 9 the sharpest turn over the span was at point 2, 57 um along the lower
        // face, and the faces were made to cross there.
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let clean = section("7606", 250.0, 400);
        let normals = crate::geometry::normals::ordered_profile_normals(&clean);
        for draw in 0..12 {
            let mut rng = rand::rngs::StdRng::seed_from_u64(draw);
            let noise = Normal::new(0.0, 0.002).unwrap();
            let measured: Vec<Vector2<f64>> = clean
                .iter()
                .zip(&normals)
                .map(|(p, n)| p + n * noise.sample(&mut rng))
                .collect();
            assert_eq!(find_corners(&measured), vec![0], "draw {draw}");
        }
    }

    #[test]
    fn a_stray_point_is_no_edge() {
        let mut points = section("2412", 100.0, 400);
        points[80] = Vector2::new(400.0, 20.0);
        assert_eq!(find_corners(&points), vec![0]);
    }

    #[test]
    fn one_edge_gives_three_faces_overlapping_at_smooth_joints() {
        let points = section("2412", 100.0, 400);
        let faces = split_at_corners(&points, &[0]);
        assert_eq!(faces.len(), 3);
        assert_eq!(faces[0].indices[0], 0);
        assert_eq!(*faces[2].indices.last().unwrap(), 0);
        let sharp: Vec<(bool, bool)> = faces.iter().map(|f| (f.start.sharp, f.end.sharp)).collect();
        assert_eq!(sharp, [(true, false), (false, false), (false, true)]);
        for pair in faces.windows(2) {
            // Each joint is inside both faces it joins, with points on either side.
            let joint = pair[0].end;
            assert_eq!(joint, pair[1].start);
            let inside = |face: &FacePoints| {
                let k = face.indices.iter().position(|&i| i == joint.at).unwrap();
                k > 5 && k + 5 < face.indices.len()
            };
            assert!(inside(&pair[0]) && inside(&pair[1]), "{joint:?}");
        }
        // The nose (index 200) is inside the middle face, away from its joints.
        let nose = &faces[1].indices;
        let k = nose.iter().position(|&i| i == 200).unwrap();
        assert!(
            k > nose.len() / 4 && k < 3 * nose.len() / 4,
            "{k} of {}",
            nose.len()
        );
    }

    #[test]
    fn a_face_split_in_two_keeps_its_ends_and_overlaps_round_the_new_joint() {
        let points = section("2412", 100.0, 400);
        let total = perimeter(&points);
        let nose = &split_at_corners(&points, &[0])[1];
        let (first, last) = own_span(nose);
        assert_eq!(nose.indices[first], nose.start.at);
        assert_eq!(nose.indices[last], nose.end.at);
        let k = first + (last - first) / 4;
        let [before, after] = split_face(&points, nose, k, total);
        assert_eq!((before.start, after.end), (nose.start, nose.end));
        let joint = FaceEnd {
            at: nose.indices[k],
            sharp: false,
        };
        assert_eq!((before.end, after.start), (joint, joint));
        // Together they hold the face's points, each of them once outside the overlap.
        assert_eq!(before.indices[0], nose.indices[0]);
        assert_eq!(after.indices.last(), nose.indices.last());
        let overlap_start = nose.indices.len() - after.indices.len();
        assert_eq!(&nose.indices[overlap_start..], &after.indices[..]);
        assert_eq!(&nose.indices[..before.indices.len()], &before.indices[..]);
        // The overlap runs about JOINT_OVERLAP of the perimeter either side of the joint, within the own span.
        let length = |from: usize, to: usize| -> f64 {
            (from..to)
                .map(|j| (points[nose.indices[j + 1]] - points[nose.indices[j]]).norm())
                .sum()
        };
        let ahead = length(k, before.indices.len() - 1);
        let behind = length(overlap_start, k);
        for side in [ahead, behind] {
            assert!(
                side >= JOINT_OVERLAP * total && side < JOINT_OVERLAP * total + 2.0,
                "{side} mm of overlap"
            );
        }
        // Split near its own span's start, the overlap stops there.
        let [_, late] = split_face(&points, nose, first + 2, total);
        assert_eq!(late.indices.len(), nose.indices.len() - first);
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
