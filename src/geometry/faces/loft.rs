//! A stack of profiles with sharp edges as one 3-D model (issue 15): each face of each profile lofted through the
//! same face of every other profile, so that every sharp edge runs as a crease through every profile's edge.
//!
//! Point s of a face's curve (by arc length, as a fraction of the face's length) is the same place of the part in
//! every profile: through those points runs a cubic spline along x (with two profiles, a straight line,
//! the ruled loft the station's clearance model uses between its profiles, `analysis::part_mesh`). A blade twists
//! and tapers between its profiles: a point of its section moves on an arc, which a straight line cuts short
//! (130 um off midway on the simulated blade's 100 mm spacing, BENCHMARKS.md) and the spline follows. The loft
//! is carried as triangles: rings of points every [`RING_STEP_MM`] at most round each profile, thinned where
//! the section is flat, joined by rings along x no farther apart than [`X_MOTION_MM`] of sideways motion or than
//! keeps the splines within [`THIN_TOLERANCE_MM`] of their chords; every vertex lies on the smooth loft, which
//! the triangles follow within `surface_mm`; the profiles' ring points lie on their faces' curves, their pieces
//! within `sag_mm`.
//!
//! Why not seed 003's blend, which `interp` applies to whole profiles: a face's polynomial reads as a distance
//! only near its own curve, and blending two faces reads each at the other's curve. On a NACA 2412 stack whose
//! chord shrinks from 20 to 18.5 mm and turns 3 deg over 15 mm, the blend carried along with the sharp edge put
//! the section 1/16 of the way along 0.7 mm off the first profile at its nose, and no section of a 1.5 % taper
//! could be traced through; the loft has no such limit, since it never reads a face away from its curve.
//!
//! Its distance is exact for the triangles: the nearest triangle by the R*-tree's branch and bound over the
//! triangles' boxes (each box's distance a lower bound for its triangles), the nearest point of each examined in
//! closed form (`sweep::mesh`). The sign is the side of the point in the loft's section through it.

use nalgebra::{Point3, Vector2, Vector3};
use rayon::prelude::*;

use super::{FacedProfile, FacesError, Join};
use crate::geometry::distance::{DistanceError, Foot};
use crate::geometry::implicit::IpModel;
use crate::geometry::sampling::{project_to_zero_set, Aabb};
use crate::geometry::sweep::mesh::MeshPart;
use crate::geometry::sweep::part::PartDistance;
use crate::geometry::trace::inside_closed;

/// The longest piece of a ring, mm: the faces are traced every 0.02 mm, and resampled no coarser.
const RING_STEP_MM: f64 = 0.02;
/// How far a ring point may move sideways between consecutive rings along x, mm: keeps each triangle's box small
/// for the search (a point of a twisting blade's section sweeps millimetres across between profiles).
const X_MOTION_MM: f64 = 1.0;
/// How far a ring point left out may lie from the chord that replaces it, and a quad twist out of its two
/// triangles, mm.
const THIN_TOLERANCE_MM: f64 = 5e-5;
/// Ring points one kept point may skip to the next, at most (bounds the thinning's cost on straight flanks).
const MAX_THINNED_SPAN: usize = 64;
/// Points this far beyond the first or last profile's plane still count as in it (a probe's x scatters too).
const PLANE_TOLERANCE_MM: f64 = 0.05;

/// One profile of a faced stack: its plane, its faces counter-clockwise round the part with the join ending each,
/// and the box of its fitted points.
#[derive(Debug, Clone)]
pub struct FacedSection {
    pub x: f64,
    pub faces: Vec<IpModel<2>>,
    pub joins: Vec<Join>,
    pub domain: Aabb<2>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FacedStackError {
    #[error("a stack needs at least two profiles, got {0}")]
    TooFewProfiles(usize),
    #[error("two profiles lie at x = {0} mm; profiles must be at distinct positions")]
    SamePosition(f64),
    #[error("the profile at x = {x} mm: {source}")]
    Profile { x: f64, source: FacesError },
    #[error(
        "the profiles at x = {a} mm and x = {b} mm do not have the same edges ({detail}): their faces cannot be \
         lofted one to one"
    )]
    Unmatched { a: f64, b: f64, detail: String },
}

/// The loft between consecutive profiles: each ring point's curve along x, the cubic spline through the same point
/// of every profile, given by its ends and its second derivatives there.
struct Segment {
    a: f64,
    b: f64,
    /// The rings' points at x = a and at x = b.
    ends: [Vec<Vector2<f64>>; 2],
    /// The splines' second derivatives there, mm^-1.
    bends: [Vec<Vector2<f64>>; 2],
    /// Rings between the two, along x.
    steps: usize,
    /// How far a chord between those rings may lie from its spline, mm.
    along_mm: f64,
}

impl Segment {
    /// The loft's section at x (within the segment): each point's spline there.
    fn ring_at(&self, x: f64) -> impl Iterator<Item = Vector2<f64>> + '_ {
        let h = self.b - self.a;
        let u = ((x - self.a) / h).clamp(0.0, 1.0);
        let v = 1.0 - u;
        let (wa, wb) = (h * h / 6.0 * (v * v * v - v), h * h / 6.0 * (u * u * u - u));
        (0..self.ends[0].len()).map(move |i| {
            self.ends[0][i] * v
                + self.ends[1][i] * u
                + self.bends[0][i] * wa
                + self.bends[1][i] * wb
        })
    }
}

/// A stack of faced profiles lofted face by face, ready to measure distances to.
pub struct FacedLoft {
    segments: Vec<Segment>,
    mesh: MeshPart,
    /// How far the rings' pieces may lie from the faces' curves, mm (their largest chord sag).
    pub sag_mm: f64,
    /// How far the triangles may lie from the loft's smooth surface through their vertices, mm: a quad's twist out
    /// of its two triangles plus a chord's sag from its spline along x.
    pub surface_mm: f64,
}

impl FacedLoft {
    /// The loft of `sections` (sorted along x here), every pair of neighbours with the same edges.
    pub fn new(mut sections: Vec<FacedSection>) -> Result<Self, FacedStackError> {
        check(&mut sections)?;
        let traced: Vec<FacedProfile> = sections
            .par_iter()
            .map(|s| {
                FacedProfile::new(s.faces.clone(), s.joins.clone(), &s.domain)
                    .map_err(|source| FacedStackError::Profile { x: s.x, source })
            })
            .collect::<Result<_, _>>()?;
        // Face j of the first profile is face order[k][j] of profile k: each profile's faces start wherever its
        // scan found its first edge.
        let n = sections[0].faces.len();
        let mut order: Vec<Vec<usize>> = vec![(0..n).collect()];
        for pair in sections.windows(2) {
            let shift = matching_shift(&pair[0], &pair[1])?;
            let next = order[order.len() - 1]
                .iter()
                .map(|&j| (j + shift) % n)
                .collect();
            order.push(next);
        }
        // Every profile's ring: each face resampled by arc length to one count in all the profiles, so that point i
        // of every ring is the same place of the same face; `starts` are the faces' first points (their joins).
        let mut rings: Vec<Vec<Vector2<f64>>> = vec![Vec::new(); sections.len()];
        let mut starts = Vec::with_capacity(n);
        for j in 0..n {
            let arcs: Vec<&[Vector2<f64>]> = order
                .iter()
                .zip(&traced)
                .map(|(faces, profile)| profile.arcs[faces[j]].points.as_slice())
                .collect();
            let longest = arcs.iter().map(|arc| length(arc)).fold(0.0, f64::max);
            let pieces = (longest / RING_STEP_MM).ceil().max(1.0) as usize;
            starts.push(rings[0].len());
            for (k, arc) in arcs.iter().enumerate() {
                let face = &sections[k].faces[order[k][j]];
                rings[k].extend(on_curve(face, resampled(arc, pieces)));
            }
        }
        let xs: Vec<f64> = sections.iter().map(|s| s.x).collect();
        let bends = spline_second_derivatives(&xs, &rings);
        let mut segments = Vec::with_capacity(sections.len() - 1);
        let mut sag_mm: f64 = 0.0;
        for k in 0..sections.len() - 1 {
            let h = xs[k + 1] - xs[k];
            let bend = bends[k]
                .iter()
                .chain(&bends[k + 1])
                .map(|m| m.norm())
                .fold(0.0, f64::max);
            // The curves along x are chords between rings: sag |p''| dx^2 / 8, with p'' linear between profiles.
            let for_bend = (h / (8.0 * THIN_TOLERANCE_MM / bend.max(f64::MIN_POSITIVE)).sqrt())
                .ceil() as usize;
            let steps = steps_along_x(&rings[k], &rings[k + 1]).max(for_bend).max(1);
            let kept = thinned(&rings[k], &rings[k + 1], &starts, steps);
            for pair in kept.windows(2) {
                // The piece across a join lies on no one face: the smooth joint's gap, or none at a sharp edge.
                if starts.contains(&pair[1]) {
                    continue;
                }
                let j = starts.partition_point(|&s| s <= pair[0]) - 1;
                for (m, ring) in [k, k + 1].into_iter().zip([&rings[k], &rings[k + 1]]) {
                    let face = &sections[m].faces[order[m][j]];
                    sag_mm = sag_mm.max(chord_sag(face, &ring[pair[0]], &ring[pair[1]]));
                }
            }
            let pick = |values: &[Vector2<f64>]| kept.iter().map(|&i| values[i]).collect();
            segments.push(Segment {
                a: xs[k],
                b: xs[k + 1],
                ends: [pick(&rings[k]), pick(&rings[k + 1])],
                bends: [pick(&bends[k]), pick(&bends[k + 1])],
                steps,
                along_mm: bend * (h / steps as f64).powi(2) / 8.0,
            });
        }
        let (mesh, surface_mm) = triangulated(&segments);
        Ok(Self {
            segments,
            mesh,
            sag_mm,
            surface_mm,
        })
    }

    /// The x range of the model, mm: the first profile's plane to the last's.
    pub fn span(&self) -> (f64, f64) {
        (self.segments[0].a, self.segments[self.segments.len() - 1].b)
    }

    pub fn triangle_count(&self) -> usize {
        self.mesh.triangle_count()
    }

    /// The nearest point of the loft to `q` and the signed distance to it (mm, positive outside).
    pub fn foot(&self, q: &Vector3<f64>) -> Result<Foot<3>, DistanceError> {
        let (first, last) = self.span();
        if q.x < first - PLANE_TOLERANCE_MM || q.x > last + PLANE_TOLERANCE_MM {
            return Err(DistanceError::OutsideModelRange);
        }
        // The mesh is open (no caps at the end profiles), so its distance is unsigned.
        let nearest = self.mesh.point_proximity(&Point3::from(*q));
        let d = nearest.distance_mm.abs();
        Ok(Foot {
            point: nearest.part_point.coords,
            distance: if self.inside(q) { -d } else { d },
        })
    }

    /// Whether `q` lies inside the loft's section through it (crossing number).
    fn inside(&self, q: &Vector3<f64>) -> bool {
        let x = q.x.clamp(self.span().0, self.span().1);
        let segment = self
            .segments
            .iter()
            .find(|s| x <= s.b)
            .unwrap_or(&self.segments[self.segments.len() - 1]);
        let ring: Vec<Vector2<f64>> = segment.ring_at(x).collect();
        inside_closed(&ring, &Vector2::new(q.y, q.z))
    }
}

/// Two or more profiles at distinct x (sorted here), each pair of neighbours with the same edges: what can be
/// checked of a faced stack without tracing its faces.
pub fn check(sections: &mut [FacedSection]) -> Result<(), FacedStackError> {
    if sections.len() < 2 {
        return Err(FacedStackError::TooFewProfiles(sections.len()));
    }
    sections.sort_by(|a, b| a.x.total_cmp(&b.x));
    for pair in sections.windows(2) {
        if pair[0].x == pair[1].x {
            return Err(FacedStackError::SamePosition(pair[0].x));
        }
        matching_shift(&pair[0], &pair[1])?;
    }
    Ok(())
}

/// The shift s pairing face j of `a` with face j + s of `b`: of those keeping every join's kind, the one whose
/// joins lie nearest each other's (each profile's faces start wherever its scan found its first edge).
fn matching_shift(a: &FacedSection, b: &FacedSection) -> Result<usize, FacedStackError> {
    let n = a.joins.len();
    let unmatched = || {
        let sharp = |s: &FacedSection| s.joins.iter().filter(|j| j.sharp).count();
        FacedStackError::Unmatched {
            a: a.x,
            b: b.x,
            detail: format!(
                "{} faces with {} sharp edge(s) against {} faces with {}",
                a.faces.len(),
                sharp(a),
                b.faces.len(),
                sharp(b)
            ),
        }
    };
    if b.joins.len() != n {
        return Err(unmatched());
    }
    let apart = |s: usize| -> f64 {
        (0..n)
            .map(|j| {
                (Vector2::from(a.joins[j].point) - Vector2::from(b.joins[(j + s) % n].point)).norm()
            })
            .sum()
    };
    (0..n)
        .filter(|&s| (0..n).all(|j| a.joins[j].sharp == b.joins[(j + s) % n].sharp))
        .min_by(|&s, &t| apart(s).total_cmp(&apart(t)))
        .ok_or_else(unmatched)
}

fn length(points: &[Vector2<f64>]) -> f64 {
    points.windows(2).map(|w| (w[1] - w[0]).norm()).sum()
}

/// `pieces + 1` points along a polyline, equally spaced by arc length, its two ends included.
fn resampled(points: &[Vector2<f64>], pieces: usize) -> Vec<Vector2<f64>> {
    let total = length(points);
    let mut out = Vec::with_capacity(pieces + 1);
    out.push(points[0]);
    let (mut k, mut walked) = (0, 0.0);
    for i in 1..pieces {
        let target = total * i as f64 / pieces as f64;
        while k + 2 < points.len() && walked + (points[k + 1] - points[k]).norm() < target {
            walked += (points[k + 1] - points[k]).norm();
            k += 1;
        }
        let piece = points[k + 1] - points[k];
        let along = ((target - walked) / piece.norm().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
        out.push(points[k] + piece * along);
    }
    out.push(points[points.len() - 1]);
    out
}

/// The points moved onto the face's curve (they lie on the traced polyline, within its sag of the curve); the
/// ends, a face's joins, are kept where they are, on both faces at a sharp edge.
fn on_curve(face: &IpModel<2>, mut points: Vec<Vector2<f64>>) -> Vec<Vector2<f64>> {
    let last = points.len() - 1;
    for p in &mut points[1..last] {
        if let Some(on) = project_to_zero_set(face, p, RING_STEP_MM) {
            *p = on;
        }
    }
    points
}

/// The second derivatives along x of the cubic splines through point i of every ring, with parabolic run-out
/// (the second derivative at the first and last profile that of the next one in: a point turning with the blade's
/// twist bends as much at its root and tip as beside them; a natural spline's zero there put the simulated blade's
/// loft 47 um off between its outer profiles). Through three profiles, the parabola through them; through two, a
/// straight line. The tridiagonal system is eliminated once, then solved per point.
fn spline_second_derivatives(xs: &[f64], rings: &[Vec<Vector2<f64>>]) -> Vec<Vec<Vector2<f64>>> {
    let k = xs.len();
    let points = rings[0].len();
    let mut bends = vec![vec![Vector2::zeros(); points]; k];
    if k < 3 {
        return bends;
    }
    let h: Vec<f64> = xs.windows(2).map(|w| w[1] - w[0]).collect();
    // Forward elimination of the rows for M_1 .. M_{k-2}: diagonal, and the multiplier carried down.
    let mut diagonal = vec![0.0; k];
    let mut carried = vec![0.0; k];
    for r in 1..k - 1 {
        let below = if r > 1 {
            h[r - 1] * h[r - 1] / diagonal[r - 1]
        } else {
            0.0
        };
        // The run-out: M_0 = M_1 and M_{k-1} = M_{k-2} fold into the first and last rows' diagonals.
        let run_out = if r == 1 { h[0] } else { 0.0 } + if r == k - 2 { h[k - 2] } else { 0.0 };
        diagonal[r] = 2.0 * (h[r - 1] + h[r]) + run_out - below;
        carried[r] = if r > 1 {
            h[r - 1] / diagonal[r - 1]
        } else {
            0.0
        };
    }
    for i in 0..points {
        let mut rhs = vec![Vector2::zeros(); k];
        for r in 1..k - 1 {
            let slope = |m: usize| (rings[m + 1][i] - rings[m][i]) / h[m];
            rhs[r] = (slope(r) - slope(r - 1)) * 6.0 - rhs[r - 1] * carried[r];
        }
        for r in (1..k - 1).rev() {
            let after = if r == k - 2 {
                Vector2::zeros()
            } else {
                bends[r + 1][i]
            };
            bends[r][i] = (rhs[r] - after * h[r]) / diagonal[r];
        }
        bends[0][i] = bends[1][i];
        bends[k - 1][i] = bends[k - 2][i];
    }
    bends
}

/// How far the middle of a piece of ring lies from the face's curve, mm.
fn chord_sag(face: &IpModel<2>, from: &Vector2<f64>, to: &Vector2<f64>) -> f64 {
    let middle = (from + to) / 2.0;
    let reach = (to - from).norm();
    project_to_zero_set(face, &middle, reach).map_or(reach, |on| (on - middle).norm())
}

/// Rings between the profiles along x, so that no ruling moves farther than [`X_MOTION_MM`] sideways between two.
fn steps_along_x(ring_a: &[Vector2<f64>], ring_b: &[Vector2<f64>]) -> usize {
    let motion = ring_a
        .iter()
        .zip(ring_b)
        .map(|(p, q)| (q - p).norm())
        .fold(0.0, f64::max);
    (motion / X_MOTION_MM).ceil().max(1.0) as usize
}

/// The ring points kept (indices, both rings alike): from each one kept, the farthest next that every point
/// between lies within [`THIN_TOLERANCE_MM`] of the chords to, in both rings, and whose quads twist by no more
/// than that out of their triangles; every face's first and last points (its joins) are kept. A blade's flanks,
/// nearly straight, keep a point every tenth of a millimetre or so; its nose and edges every 0.02 mm.
fn thinned(
    ring_a: &[Vector2<f64>],
    ring_b: &[Vector2<f64>],
    starts: &[usize],
    steps: usize,
) -> Vec<usize> {
    let n = ring_a.len();
    let off_chord = |ring: &[Vector2<f64>], from: usize, to: usize, i: usize| {
        let chord = ring[to] - ring[from];
        let offset = ring[i] - ring[from];
        let length = chord.norm();
        if length == 0.0 {
            offset.norm()
        } else {
            offset.perp(&chord).abs() / length
        }
    };
    let fits = |from: usize, to: usize| {
        let twist = ((ring_a[to] - ring_a[from]) - (ring_b[to] - ring_b[from])).norm()
            / (4.0 * steps as f64);
        twist <= THIN_TOLERANCE_MM
            && (from + 1..to).all(|i| {
                off_chord(ring_a, from, to, i) <= THIN_TOLERANCE_MM
                    && off_chord(ring_b, from, to, i) <= THIN_TOLERANCE_MM
            })
    };
    // Every face's first and last point: its joins (at a sharp edge the edge itself, in both faces).
    let mut ends = vec![false; n];
    for &start in starts {
        ends[start] = true;
        ends[start.saturating_sub(1)] = true;
    }
    ends[n - 1] = true;
    let mut kept = vec![0];
    let mut from = 0;
    while from + 1 < n {
        let mut to = from + 1;
        while to + 1 < n && to + 1 - from <= MAX_THINNED_SPAN && !ends[to] && fits(from, to + 1) {
            to += 1;
        }
        kept.push(to);
        from = to;
    }
    kept
}

/// The segments' rings joined by triangles, with rings between the profiles at their steps along x; and how far
/// the triangles may lie from the smooth loft: a quad's twist out of its two triangles (a quarter of |p00 - p10 -
/// p01 + p11|, the bilinear patch's farthest from its diagonal split) plus the chords' sag along x.
fn triangulated(segments: &[Segment]) -> (MeshPart, f64) {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let mut off_surface: f64 = 0.0;
    for segment in segments {
        let count = segment.ends[0].len();
        let steps = segment.steps;
        let base = vertices.len();
        for m in 0..=steps {
            let x = segment.a + (segment.b - segment.a) * m as f64 / steps as f64;
            vertices.extend(segment.ring_at(x).map(|p| Point3::new(x, p.x, p.y)));
        }
        let at = |m: usize, i: usize| base + m * count + i % count;
        for i in 0..count {
            let [ring_a, ring_b] = &segment.ends;
            let spread_a = ring_a[(i + 1) % count] - ring_a[i];
            let spread_b = ring_b[(i + 1) % count] - ring_b[i];
            let twist = (spread_a - spread_b).norm() / (4.0 * steps as f64);
            off_surface = off_surface.max(twist + segment.along_mm);
            for m in 0..steps {
                for triangle in [
                    [at(m, i), at(m, i + 1), at(m + 1, i)],
                    [at(m, i + 1), at(m + 1, i + 1), at(m + 1, i)],
                ] {
                    let [p, q, r] = triangle.map(|v| vertices[v]);
                    // Two faces meeting at a sharp edge share its point: their quads there fold to a line.
                    if (q - p).cross(&(r - p)).norm() > 0.0 {
                        triangles.push(triangle);
                    }
                }
            }
        }
    }
    let mesh = MeshPart::new(vertices, triangles, 0.0).expect("a loft has triangles, all indexed");
    (mesh, off_surface)
}

#[cfg(test)]
mod tests;
