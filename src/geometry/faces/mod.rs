//! A section model with true corners (issue 15): the profile split at its sharp edges into faces, each face an
//! implicit polynomial fitted to its own points, the faces joined where their zero sets meet.
//!
//! One polynomial cannot follow a sharp trailing edge: its zero set can only make a corner where two of its
//! branches cross, so the fit spends its degrees on an X at the edge and still misses it by tens of microns (29.9
//! um on a NACA 2412 at degree 8, BENCHMARKS.md). A face's polynomial only has to follow a smooth curve, and goes on
//! smoothly past the edge; the edge is where the two faces' zero sets cross, found by Newton on both.
//!
//! The part's boundary is each face's zero set trimmed to run from the join with the face before to the join with
//! the face after: the R-function join of the faces' signed distances (seeds 000 and 001) with alpha = 1, min
//! and max, which is exact on the zero set. Near a convex edge the part is inside both faces (their conjunction),
//! near a concave one inside either (their disjunction). Each trimmed face is traced once into a polyline of points
//! on its zero set, and the distance of a point is found by Newton from the polyline's nearest pieces, with a bound
//! (half a piece's length and twice its sag) that proves no other piece lies nearer.

mod fit;
mod loft;
mod refine;
mod split;

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{Matrix2, Vector2};
use serde::{Deserialize, Serialize};

use super::distance::{lagrange_newton, Foot};
use super::implicit::{Implicit, IpModel};
use super::nearest::PointIndex;
use super::sampling::{project_to_zero_set, Aabb};

pub use fit::{fit_faces, FacesFitOptions, FittedFaces};
pub use loft::{check as check_stack, FacedLoft, FacedSection, FacedStackError};

/// Spacing of the traced faces' points, mm: short enough that a piece's sag is nanometres on a nose of 0.4 mm
/// radius (0.02^2 / 8 / 0.4 = 0.1 um), and the bound that proves a foot stays tight.
const TRACE_STEP_MM: f64 = 0.02;
/// A traced face may run this many times the perimeter of the data's box before it is given up as lost.
const TRACE_LENGTH_FACTOR: f64 = 2.0;
/// Newton's iterations to find where two faces meet.
const JOIN_ITERATIONS: usize = 50;
/// Newton's step below which two faces have met, relative to the coordinates' size (rounding, not a length).
const JOIN_TOLERANCE: f64 = 1e-12;
/// How far the faces' meeting point may lie from the edge found in the points, mm (a few scan steps).
const JOIN_SEARCH_MM: f64 = 2.0;

/// Where one face ends and the next begins.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Join {
    /// The point, mm: on both faces at a sharp edge; between them, within their fit, at a smooth joint.
    pub point: [f64; 2],
    /// A sharp edge (the faces cross there) or a smooth joint (the faces overlap and run on together).
    pub sharp: bool,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FacesError {
    #[error("face {face}: {source}")]
    Fit {
        face: usize,
        source: super::fit3l::FitError,
    },
    #[error(
        "faces {before} and {after} do not meet within {JOIN_SEARCH_MM} mm of the sharp edge at ({:.3}, {:.3}) mm \
         (their fitted curves run apart there)", at[0], at[1]
    )]
    NoMeeting {
        before: usize,
        after: usize,
        at: [f64; 2],
    },
    #[error(
        "face {face}'s fitted curve does not run from its start at ({:.3}, {:.3}) mm to its end at ({:.3}, {:.3}) mm \
         ({problem})", from[0], from[1], to[0], to[1]
    )]
    Untraceable {
        face: usize,
        from: [f64; 2],
        to: [f64; 2],
        problem: &'static str,
    },
    #[error("a profile with faces needs at least two faces and one join per face; got {faces} faces and {joins} joins")]
    Shape { faces: usize, joins: usize },
}

/// A sharp edge's two faces at the edge: their outward normals, and whether the part's angle there is convex.
#[derive(Debug, Clone, Copy)]
struct Edge {
    before: Vector2<f64>,
    after: Vector2<f64>,
    convex: bool,
}

impl Edge {
    /// The side of a point whose nearest part is the edge at `apex`: the R-function join of the faces' tangent
    /// lines there (outside either for a convex edge, outside both for a concave one).
    fn side(&self, apex: &Vector2<f64>, p: &Vector2<f64>) -> f64 {
        let offset = p - apex;
        let (a, b) = (offset.dot(&self.before), offset.dot(&self.after));
        let outside = if self.convex {
            a > 0.0 || b > 0.0
        } else {
            a > 0.0 && b > 0.0
        };
        if outside {
            1.0
        } else {
            -1.0
        }
    }
}

/// A traced face: its points on the zero set, counter-clockwise round the part, from the join before to the join
/// after; and the edges at its ends (`None` at a smooth joint).
struct Arc {
    points: Vec<Vector2<f64>>,
    start_edge: Option<Edge>,
    end_edge: Option<Edge>,
}

/// A profile of faces joined at sharp edges, ready to measure distances to.
pub struct FacedProfile {
    faces: Vec<IpModel<2>>,
    joins: Vec<Join>,
    arcs: Vec<Arc>,
    /// Every arc's points, indexed together: entry `starts[j] + k` is arc j's point k.
    index: PointIndex<2>,
    starts: Vec<usize>,
    /// No point of an arc piece lies nearer to a point than the nearer of the piece's ends less this, mm.
    reach: f64,
    /// Feet given without proof: Newton failed on a piece that could hold a nearer point.
    unproved: AtomicUsize,
}

impl FacedProfile {
    /// Face j runs counter-clockwise round the part from `joins[j - 1]` to `joins[j]` (cyclically); each face's
    /// polynomial is positive outside the part. `domain` is the box of the fitted points.
    pub fn new(
        faces: Vec<IpModel<2>>,
        joins: Vec<Join>,
        domain: &Aabb<2>,
    ) -> Result<Self, FacesError> {
        if faces.len() < 2 || joins.len() != faces.len() {
            return Err(FacesError::Shape {
                faces: faces.len(),
                joins: joins.len(),
            });
        }
        let n = faces.len();
        let extent = domain.max - domain.min;
        let max_length = TRACE_LENGTH_FACTOR * 2.0 * (extent.x + extent.y);
        let limits = domain.scaled(1.5);
        let edge_at = |j: usize| -> Option<Edge> {
            let join = joins[j];
            join.sharp.then(|| {
                let apex = Vector2::from(join.point);
                let before = faces[j].value_gradient(&apex).1.normalize();
                let after = faces[(j + 1) % n].value_gradient(&apex).1.normalize();
                Edge {
                    before,
                    after,
                    convex: before.perp(&after) > 0.0,
                }
            })
        };
        let mut arcs = Vec::with_capacity(n);
        for (j, face) in faces.iter().enumerate() {
            let (from, to) = (joins[(j + n - 1) % n].point, joins[j].point);
            let points = trace_face(face, &from.into(), &to.into(), max_length, &limits).map_err(
                |problem| FacesError::Untraceable {
                    face: j,
                    from,
                    to,
                    problem,
                },
            )?;
            arcs.push(Arc {
                points,
                start_edge: edge_at((j + n - 1) % n),
                end_edge: edge_at(j),
            });
        }
        let mut starts = Vec::with_capacity(n);
        let mut all = Vec::new();
        let mut reach: f64 = 0.0;
        for (arc, face) in arcs.iter().zip(&faces) {
            starts.push(all.len());
            all.extend_from_slice(&arc.points);
            for piece in arc.points.windows(2) {
                let middle = (piece[0] + piece[1]) / 2.0;
                let length = (piece[1] - piece[0]).norm();
                let sag = project_to_zero_set(face, &middle, length)
                    .map_or(length, |on| (on - middle).norm());
                reach = reach.max(length / 2.0 + 2.0 * sag);
            }
        }
        Ok(Self {
            index: PointIndex::new(&all),
            faces,
            joins,
            arcs,
            starts,
            reach: reach + 1e-9,
            unproved: AtomicUsize::new(0),
        })
    }

    pub fn joins(&self) -> &[Join] {
        &self.joins
    }

    /// The traced faces end to end: a closed outline of the part, counter-clockwise, mm.
    pub fn outline(&self) -> Vec<Vector2<f64>> {
        self.arcs
            .iter()
            .flat_map(|arc| arc.points[..arc.points.len() - 1].iter().copied())
            .collect()
    }

    /// Which arc and which of its points an index entry is.
    fn locate(&self, entry: usize) -> (usize, usize) {
        let j = self.starts.partition_point(|&s| s <= entry) - 1;
        (j, entry - self.starts[j])
    }

    /// How many feet so far were given without proof (see [`Self::foot`]).
    pub fn unproved(&self) -> usize {
        self.unproved.load(Ordering::Relaxed)
    }

    /// The nearest point of the part to `p` and the signed distance to it (mm, positive outside), proved nearest:
    /// every piece of the traced faces not examined lies farther than it, and on every piece examined Newton found
    /// the nearest point or the piece's ends are. Where Newton failed on a piece that could hold a nearer point, the
    /// foot is still given (the piece's ends bound it to within half a piece) and counted in [`Self::unproved`].
    pub fn foot(&self, p: &Vector2<f64>) -> Option<Foot<2>> {
        let mut best: Option<Foot<2>> = None;
        let mut examined: Vec<(usize, usize)> = Vec::new();
        // The nearest end of a piece where Newton failed, mm.
        let mut failed_at = f64::INFINITY;
        for entry in self.index.nearest_iter(p) {
            let (j, k) = self.locate(entry);
            let arc = &self.arcs[j];
            let vertex = arc.points[k];
            let distance = (p - vertex).norm();
            if best.is_some_and(|b| distance > b.distance.abs() + self.reach) {
                break;
            }
            let at_vertex = Foot {
                point: vertex,
                distance: distance * self.side_at_vertex(j, k, p),
            };
            keep_nearer(&mut best, at_vertex);
            for piece in [k.wrapping_sub(1), k] {
                if piece >= arc.points.len() - 1 || examined.contains(&(j, piece)) {
                    continue;
                }
                examined.push((j, piece));
                match self.foot_on_piece(j, piece, p) {
                    OnPiece::Foot(foot) => keep_nearer(&mut best, foot),
                    OnPiece::Elsewhere => {}
                    OnPiece::Failed => {
                        let ends = &arc.points[piece..piece + 2];
                        let nearer = ends
                            .iter()
                            .map(|e| (p - e).norm())
                            .fold(f64::INFINITY, f64::min);
                        failed_at = failed_at.min(nearer);
                    }
                }
            }
        }
        if best.is_some_and(|b| failed_at - self.reach < b.distance.abs()) {
            self.unproved.fetch_add(1, Ordering::Relaxed);
        }
        best
    }

    /// The part's outward unit normal at `foot`, the foot of `p`: along the offset from the foot to `p`, or, for a
    /// point on the part, the gradient of the face it lies on. `None` for a point on the part at a sharp edge,
    /// where there is no one normal.
    pub fn outward_normal(&self, p: &Vector2<f64>, foot: &Foot<2>) -> Option<Vector2<f64>> {
        if foot.distance.abs() > 1e-9 {
            return Some((p - foot.point) / foot.distance);
        }
        let (j, k) = self.locate(self.index.nearest(&foot.point)?);
        let at_edge = match k {
            0 => self.arcs[j].start_edge.is_some(),
            k => k == self.arcs[j].points.len() - 1 && self.arcs[j].end_edge.is_some(),
        };
        if at_edge && (self.arcs[j].points[k] - foot.point).norm() < 1e-9 {
            return None;
        }
        self.faces[j]
            .value_gradient(&foot.point)
            .1
            .try_normalize(0.0)
    }

    /// The side of `p` seen from point k of arc j: the edge's R-function join at a sharp end, else the face's own.
    fn side_at_vertex(&self, j: usize, k: usize, p: &Vector2<f64>) -> f64 {
        let arc = &self.arcs[j];
        let vertex = arc.points[k];
        let edge = match k {
            0 => arc.start_edge,
            k if k == arc.points.len() - 1 => arc.end_edge,
            _ => None,
        };
        match edge {
            Some(edge) => edge.side(&vertex, p),
            None => {
                let gradient = self.faces[j].value_gradient(&vertex).1;
                if (p - vertex).dot(&gradient) < 0.0 {
                    -1.0
                } else {
                    1.0
                }
            }
        }
    }

    /// The foot of `p` on the piece of arc j from its point k to k + 1, by Newton from the chord's nearest point.
    /// Past an arc's end the face's curve goes on beyond a join, where it is not the part: the piece's nearest
    /// point is then its end, itself a point examined. (A piece is 0.02 mm of a smooth curve: the distance along it
    /// has one minimum, in Newton's reach from the chord's nearest point, or none inside it.)
    fn foot_on_piece(&self, j: usize, k: usize, p: &Vector2<f64>) -> OnPiece {
        let points = &self.arcs[j].points;
        let (a, b) = (points[k], points[k + 1]);
        let chord = b - a;
        let length = chord.norm();
        let t = ((p - a).dot(&chord) / (length * length)).clamp(0.0, 1.0);
        let start = a + chord * t;
        let Some(foot) = lagrange_newton(&self.faces[j], p, &start) else {
            return OnPiece::Failed;
        };
        // Converged on another piece's critical point (that piece is examined for its own), or off the arc.
        let along = (foot.point - a).dot(&chord) / length;
        if (foot.point - start).norm() > 2.0 * length || along < -length || along > 2.0 * length {
            return OnPiece::Elsewhere;
        }
        // The foot lies within a piece of piece k: it can only have run past an end from a piece beside one.
        let last = points.len() - 1;
        let before_start = k <= 1 && (foot.point - points[0]).dot(&(points[1] - points[0])) < 0.0;
        let after_end = k + 2 >= last
            && (foot.point - points[last]).dot(&(points[last] - points[last - 1])) > 0.0;
        if before_start || after_end {
            OnPiece::Elsewhere
        } else {
            OnPiece::Foot(foot)
        }
    }
}

/// What Newton found on one piece of a traced face.
enum OnPiece {
    Foot(Foot<2>),
    /// Newton converged away from the piece, or past the arc's end: the piece's nearest point is one of its ends.
    Elsewhere,
    /// Newton did not converge.
    Failed,
}

fn keep_nearer(best: &mut Option<Foot<2>>, candidate: Foot<2>) {
    if best.is_none_or(|b| candidate.distance.abs() < b.distance.abs()) {
        *best = Some(candidate);
    }
}

/// Face `f`'s zero set traced counter-clockwise round the part (the outside, F > 0, on the right) from the
/// projection of `from` to the projection of `to`, points [`TRACE_STEP_MM`] apart, the last one the end itself.
fn trace_face(
    f: &IpModel<2>,
    from: &Vector2<f64>,
    to: &Vector2<f64>,
    max_length: f64,
    limits: &Aabb<2>,
) -> Result<Vec<Vector2<f64>>, &'static str> {
    let step = TRACE_STEP_MM;
    let start = project_to_zero_set(f, from, JOIN_SEARCH_MM).ok_or("its start is off the curve")?;
    let end = project_to_zero_set(f, to, JOIN_SEARCH_MM).ok_or("its end is off the curve")?;
    let tangent_at = |x: &Vector2<f64>| {
        let g = f.value_gradient(x).1;
        Vector2::new(-g.y, g.x).normalize()
    };
    let end_tangent = tangent_at(&end);
    let mut points = vec![start];
    let mut current = start;
    for _ in 0..(max_length / step) as usize {
        if (end - current).norm() <= step {
            points.push(end);
            return Ok(points);
        }
        let next = project_to_zero_set(f, &(current + tangent_at(&current) * step), step)
            .ok_or("the curve turns too sharply to be followed")?;
        if (next - current).norm() < 0.25 * step {
            return Err("the curve stops (a singular point)");
        }
        let passes_end = (current - end).dot(&end_tangent) < 0.0
            && (next - end).dot(&end_tangent) >= 0.0
            && (next - end).norm() < 4.0 * step;
        if passes_end {
            points.push(end);
            return Ok(points);
        }
        let inside = (0..2).all(|i| next[i] >= limits.min[i] && next[i] <= limits.max[i]);
        if !inside {
            return Err("it leaves the data's box");
        }
        points.push(next);
        current = next;
    }
    Err("it runs on past the end")
}

/// Where faces `before` and `after` cross, by Newton on both from `near`: the sharp edge between them.
pub(crate) fn meeting_point(
    before: &IpModel<2>,
    after: &IpModel<2>,
    near: &Vector2<f64>,
) -> Option<Vector2<f64>> {
    let mut x = *near;
    for _ in 0..JOIN_ITERATIONS {
        let (va, ga) = before.value_gradient(&x);
        let (vb, gb) = after.value_gradient(&x);
        let jacobian = Matrix2::new(ga.x, ga.y, gb.x, gb.y);
        let step = jacobian.try_inverse()? * Vector2::new(va, vb);
        x -= step;
        if (x - near).norm() > JOIN_SEARCH_MM || !x.iter().all(|c| c.is_finite()) {
            return None;
        }
        if step.norm() <= JOIN_TOLERANCE * (1.0 + x.norm()) {
            return Some(x);
        }
    }
    None
}

#[cfg(test)]
mod tests;
