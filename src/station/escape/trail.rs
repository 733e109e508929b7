//! A teach scan's travel past its last reported point, from the machine's position reports.
//!
//! A teach scan's known path is the points the machine has reported so far. A controller sends scan points in
//! data lines of several points (the simulator ten), so a stop can leave up to a line of travel unreported: 10 mm
//! at a 1 mm teach step, round an edge as likely as along a face, too far to lift across blind. The I++
//! move-report daemon (`OnMoveReportE`) reports the ball centre every 0.1 s while the machine moves, apart from
//! the scan's data, so that travel is known to within one report. Every reported centre is a place the ball was,
//! touching the part: the surface lies a ball radius from it, along the centre path's normal in the scan plane
//! on the side the scan keeps the part (the ball's centre path is the surface's offset curve, so it shares the
//! surface's normals, round a sharp edge too). Those points extend the known path, and the way out follows them
//! back as it follows measured points.

use nalgebra::{Point3, Vector3};
use zeroset_drivers::machine::InPlaneScan;

use super::KnownPath;

/// Reports (and the last reported point's centre) farther apart than this are not one path, mm: a
/// report interval at the fastest scanning speed, and then some.
const JOIN_MM: f64 = 5.0;
/// A turn of the direction of travel at the trail's end beyond which its end has no normal to trust: twice the way
/// out's waypoint turn.
const SHARP_TURN_RAD: f64 = 20.0 * std::f64::consts::PI / 180.0;
/// Reports closer together than this give no direction of travel, mm.
const LEAST_STEP_MM: f64 = 1e-3;

/// Extends `path`, a teach scan's points so far (ball radius `ball_radius`), past its open end by the ball centres
/// `trail` the machine reported on the scan `plan`, in order, ending with where the ball is now: the surface points
/// a ball radius inside each report beyond the path's last point. The position the ball stopped at gives the last
/// report its direction of travel, and itself the one the ball arrived by, so the end of the path lies where the
/// ball is. Returns how many were added: none when the trail does not reach past it or does not join it; it ends
/// where two reports in a row are farther apart than any report interval (the probe was moved by other means).
pub fn extend_by_trail(
    path: &mut KnownPath,
    trail: &[Point3<f64>],
    plan: &InPlaneScan,
    ball_radius: f64,
) -> usize {
    let vector = |v: &zeroset_drivers::machine::Xyz| Vector3::new(v.x, v.y, v.z);
    let Some(plane) = vector(&plan.plane_normal).try_normalize(1e-9) else {
        return 0;
    };
    let in_plane = |v: Vector3<f64>| v - plane * plane.dot(&v);
    // The side the part is on, for the whole scan: a closed profile scanned one way round keeps it on one side
    // of the direction of travel (a continuity rule would flip round a sharp edge's fan of normals).
    let start_direction = in_plane(vector(&plan.direction) - vector(&plan.start));
    let side = vector(&plan.start_normal).dot(&plane.cross(&start_direction));
    if path.closed || path.surface.is_empty() || side.abs() < 1e-9 {
        return 0;
    }
    let side = side.signum();
    let centre = |i: usize| path.surface[i] + path.normals[i] * ball_radius;
    let last = path.surface.len() - 1;
    let end = centre(last);
    let heading = if last > 0 {
        in_plane(end - centre(last - 1))
    } else {
        start_direction
    };
    // The report nearest the last centre (the later of equals), then the reports beyond it.
    let Some((nearest, gap)) = trail.iter().map(|p| (p - end).norm()).enumerate().fold(
        None,
        |best: Option<(usize, f64)>, (i, d)| match best {
            Some((_, least)) if d > least => best,
            _ => Some((i, d)),
        },
    ) else {
        return 0;
    };
    if gap > JOIN_MM {
        return 0;
    }
    let first = if (trail[nearest] - end).dot(&heading) > LEAST_STEP_MM {
        nearest
    } else {
        nearest + 1
    };
    let mut beyond = vec![end];
    for p in &trail[first.min(trail.len())..] {
        let step = (p - beyond[beyond.len() - 1]).norm();
        if step > JOIN_MM {
            break;
        }
        if step >= LEAST_STEP_MM {
            beyond.push(*p);
        }
    }
    let mut dropped = None;
    // The end's direction of travel is its arriving chord's, whose normal is the one halfway along that chord: off
    // the end's by half the chord's turn. After a sharp turn (round an edge) that is no normal to lift along, so
    // the path ends at the report before, and the ball lies past its end, round it (`way_out`).
    if beyond.len() >= 2 {
        let n = beyond.len();
        let arriving = in_plane(beyond[n - 1] - beyond[n - 2]);
        let before = if n >= 3 {
            in_plane(beyond[n - 2] - beyond[n - 3])
        } else {
            heading
        };
        if arriving.angle(&before) > SHARP_TURN_RAD {
            // Still the way the report before was left.
            dropped = beyond.pop();
        }
    }
    let mut added = 0;
    for j in 1..beyond.len() {
        let next = beyond.get(j + 1).or(dropped.as_ref()).unwrap_or(&beyond[j]);
        let tangent = in_plane(next - beyond[j - 1]);
        let Some(normal) = (plane.cross(&tangent) * side).try_normalize(1e-9) else {
            continue;
        };
        path.surface.push(beyond[j] - normal * ball_radius);
        path.normals.push(normal);
        added += 1;
    }
    added
}

#[cfg(test)]
mod tests;
