//! The way out for a probe left near the part: after a scan, an emergency stop, an abort or a daemon restart.
//!
//! A straight move up from where the ball stopped can run through the part (a ball under a blade's lower surface
//! has the blade above it). What the station knows safely is the path the ball was on: the profile's surface
//! points and outward normals (the nominal curve of a curve scan, or the points measured so far), and the scan's
//! entry point, reached by a vertical move down from the clearance height. So the way out follows that path back
//! to the entry, held off the surface by a margin, and leaves vertically the way it came in.

use nalgebra::{Point3, Vector3};
use zeroset_drivers::machine::CurveScan;

/// A known stretch of surface along which the ball travelled, and where its scan entered.
#[derive(Debug, Clone, PartialEq)]
pub struct KnownPath {
    /// Surface points in the order of travel, machine coordinates, mm.
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
}

/// Waypoints between consecutive points of the way out are at most this far apart, mm, and closer where the
/// normal turns, so the straight moves between them stay near the offset curve.
const WAYPOINT_SPACING_MM: f64 = 2.0;
const WAYPOINT_TURN_RAD: f64 = 10.0 * std::f64::consts::PI / 180.0;
/// How far the ball may be from the known path's centre positions (plus the margin) and still be on it: the
/// retract after a scan and the points measured after the last one recorded.
const ON_PATH_TOLERANCE_MM: f64 = 3.0;

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

    /// Where the ball enters and leaves this path: above the entry point by the ball radius and `margin`.
    pub fn entry_offset(&self, ball_radius: f64, margin: f64) -> Point3<f64> {
        self.surface[self.entry] + self.normals[self.entry] * (ball_radius + margin)
    }
}

/// The moves that take the ball from `position` to the clearance height: along the known path, `margin` mm off
/// the surface beyond the ball, back to the entry, then straight up. Empty when the ball is already at or above
/// the clearance height.
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
    let centre = |i: usize| path.surface[i] + path.normals[i] * ball_radius;
    let (nearest, distance) = (0..path.surface.len())
        .map(|i| (i, (centre(i) - position).norm()))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("a non-empty path");
    if distance > margin + ON_PATH_TOLERANCE_MM {
        return Err(EscapeError::OffPath {
            position,
            off_path_mm: distance,
        });
    }
    let offset = |i: usize| path.surface[i] + path.normals[i] * (ball_radius + margin);
    let mut moves = vec![offset(nearest)];
    let mut last = nearest;
    for i in walk(nearest, path.entry, path.surface.len(), path.closed) {
        let far = (path.surface[i] - path.surface[last]).norm() >= WAYPOINT_SPACING_MM;
        let turned = path.normals[i].angle(&path.normals[last]) >= WAYPOINT_TURN_RAD;
        if far || turned || i == path.entry {
            moves.push(offset(i));
            last = i;
        }
    }
    let exit = offset(path.entry);
    moves.push(Point3::new(exit.x, exit.y, clearance_z.max(exit.z)));
    Ok(moves)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle of radius 20 mm in the plane x = 100, centre at z = 0, scanned from its top.
    fn circle(closed_points: usize) -> KnownPath {
        let (surface, normals) = (0..closed_points)
            .map(|k| {
                let t = std::f64::consts::FRAC_PI_2
                    + std::f64::consts::TAU * k as f64 / closed_points as f64;
                let n = Vector3::new(0.0, t.cos(), t.sin());
                (Point3::new(100.0, 0.0, 0.0) + n * 20.0, n)
            })
            .unzip();
        KnownPath {
            surface,
            normals,
            closed: true,
            entry: 0,
        }
    }

    #[test]
    fn above_the_clearance_height_nothing_moves() {
        let moves = way_out(Point3::new(0.0, 0.0, 200.0), None, 1.0, 2.0, 150.0).unwrap();
        assert!(moves.is_empty());
    }

    #[test]
    fn under_the_part_the_way_out_goes_round_it_never_through() {
        let path = circle(360);
        // The ball touches the bottom of the circle: straight up would cross the part.
        let position = Point3::new(100.0, 0.0, -21.0);
        let moves = way_out(position, Some(&path), 1.0, 2.0, 150.0).unwrap();
        let last = moves.last().unwrap();
        assert_eq!(last.z, 150.0);
        assert!(
            (last.y).abs() < 1e-9 && (last.x - 100.0).abs() < 1e-9,
            "{last}"
        );
        // Every straight move keeps the ball (radius 1) clear of the circle (radius 20).
        let mut from = position;
        for to in &moves {
            for k in 0..=100 {
                let p = from + (to - from) * (k as f64 / 100.0);
                let clearance = ((p.y).powi(2) + (p.z).powi(2)).sqrt() - 20.0 - 1.0;
                assert!(
                    clearance > -1e-9,
                    "the move {from} -> {to} cuts the part at {p}"
                );
            }
            from = *to;
        }
        // Half way round one way: about 180 degrees / 10 degrees per waypoint at least.
        assert!(moves.len() >= 18, "{} moves", moves.len());
    }

    #[test]
    fn an_open_path_is_followed_back_to_its_entry() {
        let mut path = circle(360);
        path.surface.truncate(200);
        path.normals.truncate(200);
        path.closed = false;
        let end = path.surface[199] + path.normals[199] * 1.0;
        let moves = way_out(end, Some(&path), 1.0, 2.0, 150.0).unwrap();
        // Backwards through the 200 scanned degrees (y < 0, counter-clockwise from the top), not forwards through
        // the unknown 160.
        let middle = moves[moves.len() / 2];
        assert!(middle.y < 0.0, "goes back over the scanned side: {middle}");
    }

    #[test]
    fn far_from_the_known_path_or_without_one_it_refuses() {
        let path = circle(36);
        let err =
            way_out(Point3::new(100.0, 0.0, -40.0), Some(&path), 1.0, 2.0, 150.0).unwrap_err();
        assert!(matches!(err, EscapeError::OffPath { .. }), "{err}");
        let err = way_out(Point3::new(1.0, 2.0, 3.0), None, 1.0, 2.0, 150.0).unwrap_err();
        assert!(
            err.to_string().contains("below the clearance height"),
            "{err}"
        );
    }
}
