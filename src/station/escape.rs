//! The way out for a probe left near the part: after a scan, an emergency stop, an abort or a daemon restart.
//!
//! A straight move up from where the ball stopped can run through the part (a ball under a blade's lower surface
//! has the blade above it). What the station knows safely is the path the ball was on: the profile's surface
//! points and outward normals (the nominal curve of a curve scan, or the points measured so far), and the scan's
//! entry point, reached by a vertical move down from the clearance height. So the way out follows that path back
//! to the entry, held off the surface by a margin, and leaves vertically the way it came in.

use std::sync::Arc;

use nalgebra::{Point3, Rotation3, Unit, Vector3};
use zeroset_drivers::machine::CurveScan;

use crate::config::Safety;
use crate::geometry::sweep::closest::closest_between_segments;
use crate::geometry::sweep::mesh::MeshPart;
use crate::geometry::sweep::part::PartDistance;

/// A known stretch of surface along which the ball travelled, and where its scan entered.
#[derive(Debug, Clone, PartialEq)]
pub struct KnownPath {
    /// Surface points in the order of travel, machine coordinates, mm. A curve scan's are its nominal points:
    /// near a sharp edge, where the plan fans the probing lines (`plan::fan`), points of the planned ball clear of
    /// the master, up to about 0.8 mm off its surface, so a check against them is the stricter.
    pub surface: Vec<Point3<f64>>,
    /// Their outward unit normals.
    pub normals: Vec<Vector3<f64>>,
    /// Whether the path is a whole closed profile (so it can be followed either way round).
    pub closed: bool,
    /// The index of the point whose offset the scan entered from, vertically.
    pub entry: usize,
}

/// Why no safe way out is known.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EscapeError {
    #[error("the probe is at ({:.3}, {:.3}, {:.3}) mm, {:.1} mm from the path it was scanning, so the way out is not known", .position.x, .position.y, .position.z, .off_path_mm)]
    OffPath {
        position: Point3<f64>,
        off_path_mm: f64,
    },
    #[error("the probe is at ({:.3}, {:.3}, {:.3}) mm, below the clearance height, and no scan path is known around it", .0.x, .0.y, .0.z)]
    Unknown(Point3<f64>),
    /// A leg of the planned way out comes too close to what is known of the part.
    #[error("the way out from ({:.3}, {:.3}, {:.3}) mm is not clear: its leg {leg} to ({:.3}, {:.3}, {:.3}) mm brings the ball to {clearance_mm:.3} mm of {against}", .position.x, .position.y, .position.z, .to.x, .to.y, .to.z)]
    NotClear {
        position: Point3<f64>,
        leg: usize,
        to: Point3<f64>,
        clearance_mm: f64,
        against: &'static str,
    },
}

/// A scan's path, for a way out: the scan as the operator reads it, what is known of its surface, and how far
/// off that surface the ball travels entering and leaving it (mm).
#[derive(Debug, Clone)]
pub struct ScanPath {
    pub name: String,
    pub path: KnownPath,
    pub margin_mm: f64,
}

impl ScanPath {
    /// How far a ball centre at `position` is from this scan: from its known surface, or from the vertical its
    /// scan is entered by, whichever is nearer, mm.
    pub fn distance_mm(&self, position: &Point3<f64>, ball_radius: f64) -> f64 {
        let surface = nearest_on_path(&self.path, position).distance;
        let entry = self.path.entry_offset(ball_radius, self.margin_mm);
        let descent = if position.z >= entry.z {
            (position.xy() - entry.xy()).norm()
        } else {
            (position - entry).norm()
        };
        surface.min(descent)
    }
}

/// What a way out after a stop is planned from, besides the path the worker itself was on, and checked against.
#[derive(Clone, Default)]
pub struct EscapeModel {
    /// The scans the probe may be on, for a worker that knows none (a restarted daemon): the scans a killed daemon
    /// cut short, with the points they measured, then every scan the job plans. The nearest is followed.
    pub paths: Vec<ScanPath>,
    /// The taught part on the machine, every instance (none when teaching: then only the known path counts).
    pub part: Option<Arc<MeshPart>>,
    /// How far the real part may lie from the model, and then some: the job's scan margin, mm.
    pub deviation_margin_mm: f64,
}

/// Waypoints between consecutive points of the way out are at most this far apart, mm, and closer where the
/// normal turns, so the straight moves between them stay near the offset curve.
const WAYPOINT_SPACING_MM: f64 = 2.0;
const WAYPOINT_TURN_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;
/// How far the ball may be from the known path's centre positions (plus the margin) and still be on it: the
/// retract after a scan and the points measured after the last one recorded.
const ON_PATH_TOLERANCE_MM: f64 = 3.0;
/// How far from the vertical over a scan's entry the ball may be and still be on its descent (or its final rise):
/// the difference between the planned ball and the real one, mm.
const ON_DESCENT_TOLERANCE_MM: f64 = 0.5;
/// How much nearer than it started the ball may come on a way out's first leg, mm: the rounding and noise of the
/// position the machine reports, so that a lift-off straight off the surface is not refused for a micron.
const FIRST_LEG_SLACK_MM: f64 = 0.005;

impl KnownPath {
    /// The nominal curve of a curve scan, entered at its first nominal (the plan puts the entry there).
    pub fn of_curve_scan(scan: &CurveScan) -> Self {
        let (surface, normals) = scan
            .nominals
            .iter()
            .map(|n| {
                (
                    Point3::new(n.point.x, n.point.y, n.point.z),
                    Vector3::new(n.normal.x, n.normal.y, n.normal.z),
                )
            })
            .unzip();
        KnownPath {
            surface,
            normals,
            closed: scan.closed,
            entry: 0,
        }
    }

    /// Refuses a path no move may be planned from: empty, an entry beyond its points, a point that is not finite
    /// or a normal that is not a unit vector (a zero normal would send NaN targets).
    pub fn validate(&self) -> Result<(), String> {
        if self.surface.is_empty() || self.surface.len() != self.normals.len() {
            return Err(format!(
                "the known path has {} points and {} normals",
                self.surface.len(),
                self.normals.len()
            ));
        }
        if self.entry >= self.surface.len() {
            return Err(format!(
                "the entry {} is beyond the path's {} points",
                self.entry,
                self.surface.len()
            ));
        }
        let bad = self.surface.iter().zip(&self.normals).position(|(p, n)| {
            !(p.coords.iter().all(|c| c.is_finite()) && (n.norm() - 1.0).abs() < 1e-6)
        });
        match bad {
            Some(i) => Err(format!(
                "point {i} of the known path, ({:.3}, {:.3}, {:.3}) mm with normal ({}, {}, {}), is not a finite \
                 point with a unit normal; teach the part again",
                self.surface[i].x,
                self.surface[i].y,
                self.surface[i].z,
                self.normals[i].x,
                self.normals[i].y,
                self.normals[i].z
            )),
            None => Ok(()),
        }
    }

    /// Where the ball enters and leaves this path: above the entry point by the ball radius and `margin`.
    pub fn entry_offset(&self, ball_radius: f64, margin: f64) -> Point3<f64> {
        self.surface[self.entry] + self.normals[self.entry] * (ball_radius + margin)
    }
}

/// The offset points strictly between path points `a` and `b` whose normals turn by more than the waypoint turn:
/// the surface point interpolated along the segment and the normal turned from one to the other about their
/// common perpendicular, at `offset` mm, no two more than the waypoint turn apart. None for normals too near
/// opposite to say which way round (the way out's check then judges the straight leg).
fn round_the_turn(path: &KnownPath, a: usize, b: usize, offset: f64) -> Vec<Point3<f64>> {
    let (from, to) = (path.normals[a], path.normals[b]);
    let Some(axis) = Unit::try_new(from.cross(&to), 1e-6) else {
        return Vec::new();
    };
    let turn = from.angle(&to);
    let steps = (turn / WAYPOINT_TURN_RAD).ceil() as usize;
    (1..steps)
        .map(|k| {
            let t = k as f64 / steps as f64;
            let normal = Rotation3::from_axis_angle(&axis, turn * t) * from;
            path.surface[a] + (path.surface[b] - path.surface[a]) * t + normal * offset
        })
        .collect()
}

/// The way back round the open end of a path for a ball that went round it unreported (a teach scan stopped just
/// past a sharp edge, its last report before the edge): straight away from the last known point by `margin` mm (to
/// at least the ball and the margin from it), then round that point at that distance, back the way the ball went
/// (about the axis that turns the path's normals into its direction of travel), to over the last point. None when the
/// foot is neither on the path's last segment nor the ball within the path tolerance of the end, or the end gives
/// no direction of travel: then the ball is inside the known surface, not round its end.
fn round_the_open_end(
    path: &KnownPath,
    foot: &Foot,
    position: &Point3<f64>,
    ball_radius: f64,
    margin: f64,
) -> Option<Vec<Point3<f64>>> {
    let offset = ball_radius + margin;
    let n = path.surface.len();
    if path.closed || n < 2 {
        return None;
    }
    let (pivot, normal) = (path.surface[n - 1], path.normals[n - 1]);
    // On the last segment, or within the reach of the end the way out allows a path (round a thin edge and back
    // under the face, the nearest segment is one before).
    if foot.segment != n - 2 && (position - pivot).norm() > offset + ON_PATH_TOLERANCE_MM {
        return None;
    }
    // The way the path turns its normals into its direction of travel, over the whole path: a plane scan's normal,
    // signed by the side the part is on. The last segment alone can point anywhere when its end was placed from
    // positions reported either side of a sharp turn.
    let turning: Vector3<f64> = (0..n - 1)
        .map(|i| path.normals[i].cross(&(path.surface[i + 1] - path.surface[i])))
        .sum();
    let axis = Unit::try_new(turning, 1e-9)?;
    let away = (position - pivot).try_normalize(1e-9)?;
    let mut turned = normal.cross(&away).dot(&axis).atan2(normal.dot(&away));
    if turned < 0.0 {
        turned += std::f64::consts::TAU;
    }
    // Radially off a point of the part never nearer the part where it is convex; under a face behind the end the
    // radial lift runs nearly along the face, so it goes the whole margin beyond where the ball is.
    let radius = offset.max((position - pivot).norm() + margin);
    let steps = (turned / WAYPOINT_TURN_RAD).ceil() as usize;
    let mut arc = vec![pivot + away * radius];
    arc.extend((1..steps).map(|k| {
        let back = turned * (1.0 - k as f64 / steps as f64);
        pivot + Rotation3::from_axis_angle(&axis, back) * normal * radius
    }));
    arc.push(pivot + normal * radius);
    Some(arc)
}

/// The moves that take the ball from `position` to the clearance height: off the known surface along its normal
/// to `margin` mm beyond the ball, along the path at that offset back to the entry, then straight up. Empty when
/// the ball is already at or above the clearance height.
///
/// The first leg leaves from where the ball is, not from a recorded point: straight away from the nearest point of
/// the known surface (its normal there), which only increases the clearance from a surface that is convex there or
/// concave with a radius larger than the ball and the margin. A ball that stopped past the end of an open path (a
/// teach scan's last points not yet reported) lifts across its own unreported travel: perpendicular to the chord
/// from the last reported centre, on the outside; such a stretch no longer than the margin's allowance is taken
/// as locally convex, a longer one is refused. A ball that went round the open end unreported and lies on the
/// inner side of the last known surface (round a knife edge) goes back round that end's last point (`round_the_open_end`).
pub fn way_out(
    position: Point3<f64>,
    path: Option<&KnownPath>,
    ball_radius: f64,
    margin: f64,
    clearance_z: f64,
) -> Result<Vec<Point3<f64>>, EscapeError> {
    if position.z >= clearance_z {
        return Ok(Vec::new());
    }
    let Some(path) = path.filter(|p| !p.surface.is_empty()) else {
        return Err(EscapeError::Unknown(position));
    };
    // Over the entry, on the vertical the scan is entered and left by: straight up the way it came.
    let exit = path.entry_offset(ball_radius, margin);
    let over_entry = (position.xy() - exit.xy()).norm() <= ON_DESCENT_TOLERANCE_MM
        && position.z >= exit.z - ON_DESCENT_TOLERANCE_MM;
    if over_entry {
        return Ok(vec![Point3::new(position.x, position.y, clearance_z)]);
    }
    // On the entry's normal beyond the ball's contact: where a scan's own approach stops (a curve scan moves out
    // along the first nominal's normal by the expected deviation and the search distance before it probes).
    let along_normal = (position - path.surface[path.entry]).dot(&path.normals[path.entry]);
    let on_entry_normal = along_normal >= ball_radius
        && (path.surface[path.entry] + path.normals[path.entry] * along_normal - position).norm()
            <= ON_DESCENT_TOLERANCE_MM;
    if on_entry_normal {
        let mut moves = vec![exit, Point3::new(exit.x, exit.y, clearance_z.max(exit.z))];
        moves.dedup_by(|b, a| (*b - *a).norm() < 1e-9);
        return Ok(moves);
    }
    let foot = nearest_on_path(path, &position);
    if foot.distance > ball_radius + margin + ON_PATH_TOLERANCE_MM {
        return Err(EscapeError::OffPath {
            position,
            off_path_mm: foot.distance - ball_radius,
        });
    }
    let normal = foot.normal;
    let inside = (position - foot.point).dot(&normal) < 0.0;
    let (lift, join) = if inside {
        match round_the_open_end(path, &foot, &position, ball_radius, margin) {
            Some(arc) => (arc, path.surface.len() - 1),
            // The ball centre lies on the inner side of the known surface, away from an open end it could have
            // gone round: that surface is not where the part is, and no move away from it can be trusted.
            None => {
                return Err(EscapeError::OffPath {
                    position,
                    off_path_mm: -foot.distance,
                })
            }
        }
    } else if foot.past_end {
        let last = path.surface.len() - 1;
        let centre = path.surface[last] + path.normals[last] * ball_radius;
        let chord = position - centre;
        // Outward and perpendicular to the chord, in the plane of the chord and the last normal.
        let out = (normal - chord * (normal.dot(&chord) / chord.norm_squared().max(1e-300)))
            .try_normalize(1e-9)
            .unwrap_or(normal);
        (vec![position + out * margin], last)
    } else {
        let away = (position - foot.point)
            .try_normalize(1e-9)
            .filter(|u| u.dot(&normal) > 0.0)
            .unwrap_or(normal);
        let lift = (ball_radius + margin - foot.distance).max(0.0);
        (vec![position + away * lift], foot.toward_entry)
    };
    let offset = |i: usize| path.surface[i] + path.normals[i] * (ball_radius + margin);
    let mut moves = lift;
    let mut last = join;
    let mut previous = join;
    moves.push(offset(join));
    for i in walk(join, path.entry, path.surface.len(), path.closed) {
        if path.normals[i].angle(&path.normals[previous]) > WAYPOINT_TURN_RAD {
            // A sharp turn between two neighbours (a knife edge's fan, or reports 2 mm apart either side of it):
            // round it at the offset, as the ball went round, not along the chord that cuts the edge.
            if last != previous {
                moves.push(offset(previous));
            }
            moves.extend(round_the_turn(path, previous, i, ball_radius + margin));
            moves.push(offset(i));
            last = i;
        } else {
            let far = (path.surface[i] - path.surface[last]).norm() >= WAYPOINT_SPACING_MM;
            let turned = path.normals[i].angle(&path.normals[last]) >= WAYPOINT_TURN_RAD;
            if far || turned || i == path.entry {
                moves.push(offset(i));
                last = i;
            }
        }
        previous = i;
    }
    let exit = offset(path.entry);
    moves.push(Point3::new(exit.x, exit.y, clearance_z.max(exit.z)));
    moves.dedup_by(|b, a| (*b - *a).norm() < 1e-9);
    Ok(moves)
}

/// The way out from `position` (`way_out`), each leg checked before anything moves, for the ball (the shank is
/// judged as for the contact scan it leaves: a vertical stylus under a blade has its shank through the blade, which
/// a real station avoids with a probe head that turns the stylus): once off the surface the ball never comes nearer
/// the known surface, nor the taught part model, than the move margin; on the first leg, which may start in
/// contact, it never comes nearer than it started. A way out that fails either is refused: nothing is moved.
pub fn plan_escape(
    position: Point3<f64>,
    path: Option<(&KnownPath, f64)>,
    ball_radius: f64,
    safety: &Safety,
    model: &EscapeModel,
) -> Result<Vec<Point3<f64>>, EscapeError> {
    let (known, margin) = match path {
        Some((path, margin)) => (Some(path), margin),
        None => (None, 0.0),
    };
    let moves = match way_out(position, known, ball_radius, margin, safety.clearance_z_mm) {
        Ok(moves) => moves,
        Err(error) => return straight_up_if_free(position, ball_radius, safety, model, error),
    };
    check_way_out(
        position,
        &moves,
        known,
        ball_radius,
        safety,
        model.part.as_deref(),
    )?;
    Ok(moves)
}

/// Checks the moves from `position` before anything moves: once off the surface the ball never comes nearer the
/// known surface, nor the taught part model, than the move margin; on the first leg, which may start in contact,
/// it never comes nearer than it started (less the slack of a reported position).
pub fn check_way_out(
    position: Point3<f64>,
    moves: &[Point3<f64>],
    known: Option<&KnownPath>,
    ball_radius: f64,
    safety: &Safety,
    part: Option<&MeshPart>,
) -> Result<(), EscapeError> {
    let wanted = safety.move_margin_mm;
    let mut from = position;
    for (leg, &to) in moves.iter().enumerate() {
        let mut against: Vec<(&'static str, f64, f64)> = Vec::new();
        if let Some(path) = known {
            let start = surface_distance(path, &from, &from) - ball_radius;
            let least = surface_distance(path, &from, &to) - ball_radius;
            against.push(("the known surface", start, least));
        }
        if let Some(part) = part {
            let start = part.distance(&from) - ball_radius;
            let needed = first_leg_floor(leg, start - part.chord_tolerance_mm(), wanted);
            let least = ball_clearance(part, &from, &to, ball_radius, needed);
            // The mesh lies within its chord tolerance of the model: a lift-off may seem to dip by as much.
            against.push((
                "the taught part model",
                start - part.chord_tolerance_mm(),
                least,
            ));
        }
        for (what, start, least) in against {
            if least < first_leg_floor(leg, start, wanted) {
                return Err(EscapeError::NotClear {
                    position,
                    leg,
                    to,
                    clearance_mm: least,
                    against: what,
                });
            }
        }
        from = to;
    }
    Ok(())
}

/// The least clearance a leg must keep, mm: the move margin, or on the first leg, which may start in contact
/// (or, against the nominal model, inside it by the part's deviation), what it started with.
fn first_leg_floor(leg: usize, start: f64, wanted: f64) -> f64 {
    if leg == 0 {
        start.min(wanted) - FIRST_LEG_SLACK_MM
    } else {
        wanted
    }
}

/// Off every known path, the one way out that can still be proven: straight up, if the taught model says the
/// ball stays clear of it all the way by the job's deviation margin (the real part lies within the expected
/// deviation of the model, and the margin is that plus 2 mm). Otherwise `error`: nothing moves.
fn straight_up_if_free(
    position: Point3<f64>,
    ball_radius: f64,
    safety: &Safety,
    model: &EscapeModel,
    error: EscapeError,
) -> Result<Vec<Point3<f64>>, EscapeError> {
    let Some(part) = model.part.as_deref() else {
        return Err(error);
    };
    let top = Point3::new(position.x, position.y, safety.clearance_z_mm);
    let needed = model.deviation_margin_mm.max(safety.move_margin_mm) + part.chord_tolerance_mm();
    let least = ball_clearance(part, &position, &top, ball_radius, needed);
    if least >= needed {
        Ok(vec![top])
    } else {
        Err(error)
    }
}

/// The least clearance (mm) of a ball moved straight from `a` to `b` against `part`, by conservative advancement
/// (the distance is 1-Lipschitz along the centre's path, so a step no longer than the gap above `needed` cannot
/// pass below it). `needed` may be negative (a leg starting inside the nominal model), and the whole leg is still
/// checked. Once below `needed` it goes on towards contact to find how near the ball comes.
fn ball_clearance(
    part: &MeshPart,
    a: &Point3<f64>,
    b: &Point3<f64>,
    radius: f64,
    needed: f64,
) -> f64 {
    const RESOLUTION_MM: f64 = 1e-4;
    let length = (b - a).norm();
    let mut t = 0.0;
    let mut least = f64::INFINITY;
    loop {
        let gap = part.distance(&(a + (b - a) * t)) - radius;
        least = least.min(gap);
        let failed = least < needed;
        if t >= 1.0 || length == 0.0 || (failed && (gap <= 0.0 || needed <= 0.0)) {
            return least;
        }
        let target = if failed { 0.0 } else { needed };
        t = (t + (gap - target).max(RESOLUTION_MM) / length).min(1.0);
    }
}

/// The least distance from the segment [a, b] of ball centres to the known surface's polyline.
fn surface_distance(path: &KnownPath, a: &Point3<f64>, b: &Point3<f64>) -> f64 {
    let n = path.surface.len();
    let segments = if path.closed || n == 1 { n } else { n - 1 };
    (0..segments)
        .map(|i| {
            let (s, t) =
                closest_between_segments(a, b, &path.surface[i], &path.surface[(i + 1) % n]);
            (s - t).norm()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The point of the known surface nearest a ball centre.
struct Foot {
    point: Point3<f64>,
    /// The surface normal there, interpolated between the path's normals.
    normal: Vector3<f64>,
    distance: f64,
    /// Of the two path points around the foot, the one on the way to the entry.
    toward_entry: usize,
    /// The foot is the end of an open path and the centre lies beyond it.
    past_end: bool,
    /// The index of the first point of the segment the foot lies on (0 for a one-point path).
    segment: usize,
}

fn nearest_on_path(path: &KnownPath, centre: &Point3<f64>) -> Foot {
    let n = path.surface.len();
    let segments = if path.closed { n } else { n.saturating_sub(1) };
    let mut best = Foot {
        point: path.surface[0],
        normal: path.normals[0],
        distance: (centre - path.surface[0]).norm(),
        toward_entry: 0,
        past_end: false,
        segment: 0,
    };
    for i in 0..segments {
        let j = (i + 1) % n;
        let (a, b) = (path.surface[i], path.surface[j]);
        let ab = b - a;
        let t = ((centre - a).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
        let point = a + ab * t;
        let distance = (centre - point).norm();
        if distance < best.distance {
            let normal = (path.normals[i] * (1.0 - t) + path.normals[j] * t)
                .try_normalize(1e-9)
                .unwrap_or(path.normals[i]);
            // The way out joins the path at the nearer of the segment's ends.
            let toward_entry = if t <= 0.5 { i } else { j };
            best = Foot {
                point,
                normal,
                distance,
                toward_entry,
                past_end: false,
                segment: i,
            };
        }
    }
    if !path.closed {
        let last = n - 1;
        let beyond = n > 1 && {
            let along = path.surface[last] - path.surface[last - 1];
            (best.point - path.surface[last]).norm() < 1e-12
                && (centre - path.surface[last]).dot(&along) > 0.0
        };
        if beyond {
            best.past_end = true;
            best.toward_entry = last;
        }
    }
    best
}

/// The indices from `from` (exclusive) to `to` (inclusive): the shorter way round a closed path, else straight.
fn walk(from: usize, to: usize, len: usize, closed: bool) -> Vec<usize> {
    if from == to {
        return Vec::new();
    }
    if closed {
        let forward = (to + len - from) % len;
        let backward = (from + len - to) % len;
        if forward <= backward {
            (1..=forward).map(|k| (from + k) % len).collect()
        } else {
            (1..=backward).map(|k| (from + len - k) % len).collect()
        }
    } else if to < from {
        (to..from).rev().collect()
    } else {
        (from + 1..=to).collect()
    }
}

mod trail;
pub use trail::extend_by_trail;

#[cfg(test)]
pub(crate) mod tests;
