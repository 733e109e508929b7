//! Whether a scan that ended well is whole: a line of points lost on the way (the machine's data lines carry
//! several points each) leaves a hole the machine never reports. A scan along a nominal curve is followed along
//! that curve: each ball centre is placed at its arc length on the nominal path (the surface's, and the ball
//! centres'), and a step along it longer than the scan's spacing allows, or a start or an end short of the
//! curve's, is a gap. A teach scan has no nominal: its ball centres must lie no further apart than its step
//! allows, turn across a step by no more than its angle allows where it is spaced by turn too, and close where
//! they began.

use std::fmt;

use nalgebra::{Point3, Vector3};

use zeroset_drivers::machine::{Density, InPlaneSpacing};

use super::escape::KnownPath;
use super::motion::{Scan, ScanMotion};

/// A step is a gap when it is longer than this many times the median of the steps before it...
const LOCAL_FACTOR: f64 = 3.0;
/// ...and longer than this many times the spacing there: the longest nominal segment the step spans (a curve
/// scan) or the step (a teach scan), since a machine reports at least one point per nominal, and a teach scan
/// one per step. The spacing is local, not the curve's largest: a blade's nominals crowd at its edges, and a
/// line of points lost there is shorter than one spacing of its faces.
const SPACING_FACTOR: f64 = 1.5;
/// How many steps the local median looks back over.
const WINDOW: usize = 10;
/// A teach scan spaced by turn as well (`InPlaneSpacing::Spacing`) steps finer than its distance round a nose or a
/// sharp edge's roll, where a line of points lost is shorter than one distance step: there a step is a gap when
/// the path turns across it by more than its angle allows. The turn is read between chords of this many steps
/// before and after it (ball centres carry the probe's noise: over one step of a roll round a 1 mm ball at 2.5
/// deg, 44 um, 2 um of noise turns a chord by 4 deg, over three by 1.2 deg)...
const TURN_CHORD_STEPS: usize = 3;
/// ...and a step is a gap when that turn exceeds what the chords themselves turn (`TURN_CHORD_STEPS` + 1 steps of
/// the scan's angle at most) by this many of its angles: a hole of three points or more (a data line holds ten).
const TURN_LOST_STEPS: f64 = 3.0;
/// How far ahead along the nominal path the next point is looked for, in nominal spacings: far enough for any
/// hole, near enough that the two faces of a thin edge are not confused.
const LOOK_AHEAD: f64 = 40.0;

/// A hole in a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Gap {
    /// The last point before the hole (`None`: the hole is at the scan's start).
    pub after: Option<usize>,
    /// Where the hole begins (a ball centre, machine coordinates, mm).
    pub at: Point3<f64>,
    /// How long the hole is along the scan, mm.
    pub length_mm: f64,
}

impl fmt::Display for Gap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let after = match self.after {
            Some(i) => format!("after point {i}"),
            None => "at its start".to_string(),
        };
        write!(
            f,
            "a gap of {:.1} mm {after}, at ({:.3}, {:.3}, {:.3}) mm",
            self.length_mm, self.at.x, self.at.y, self.at.z
        )
    }
}

/// The first hole in the ball centres of a scan of `motion` that ended well, if any; the ball's radius is
/// `ball_radius_mm`.
pub fn find_gap(motion: &ScanMotion, centres: &[Point3<f64>], ball_radius_mm: f64) -> Option<Gap> {
    match &motion.scan {
        Scan::Curve(_) => curve_gap(motion, centres, ball_radius_mm),
        Scan::InPlane(scan) => teach_gap(motion, centres, &scan.spacing, scan.stop_diameter),
    }
}

/// The first step longer than its allowance: `SPACING_FACTOR` times the spacing over it (`spacing(from, to)`),
/// and `LOCAL_FACTOR` times the local median step.
fn first_long_step(positions: &[f64], spacing: impl Fn(f64, f64) -> f64) -> Option<(usize, f64)> {
    let steps: Vec<f64> = positions.windows(2).map(|w| w[1] - w[0]).collect();
    (0..steps.len()).find_map(|i| {
        let mut before: Vec<f64> = steps[i.saturating_sub(WINDOW)..i].to_vec();
        before.sort_by(f64::total_cmp);
        let median = before.get(before.len() / 2).copied().unwrap_or(0.0);
        let allowed =
            (SPACING_FACTOR * spacing(positions[i], positions[i + 1])).max(LOCAL_FACTOR * median);
        (steps[i] > allowed).then_some((i, steps[i]))
    })
}

/// The nominal segments of a curve scan in the order it travels them, as arc lengths from its entry.
struct Segments {
    /// (where the segment starts, its length), mm, starts increasing.
    spans: Vec<(f64, f64)>,
    /// The longest of all, for a path that has none ahead of its entry.
    widest: f64,
}

impl Segments {
    /// The longest segment that overlaps `from..to` (arc lengths from the entry, mm); a step that spans none
    /// (it lies on one segment's end) gets the segment it touches.
    fn spacing(&self, from: f64, to: f64) -> f64 {
        let spans = &self.spans;
        if spans.is_empty() {
            return self.widest;
        }
        let first = spans
            .partition_point(|&(start, length)| start + length < from)
            .min(spans.len() - 1);
        let past = spans
            .partition_point(|&(start, _)| start <= to)
            .max(first + 1);
        spans[first..past.min(spans.len())]
            .iter()
            .map(|&(_, length)| length)
            .fold(0.0, f64::max)
    }
}

/// A curve scan is followed twice, along its nominal surface path and along its nominal ball-centre path (each
/// nominal moved out along its normal by the ball's radius), and a gap along either is a gap. The surface path
/// alone misses a hole round a sharp edge: there the master's nominals are one point with a fan of normals (and
/// the plan's fanned lines, `plan::fan`, spread them only across the planned ball's contact, about 1.6 mm), so the
/// surface path has little or no length where the ball rolls a half turn round it, several points of the scan (the
/// 1000-fault campaign lost 20 there, C r200 with 370 of 390 points, and the surface path saw 2.5 mm missing, less
/// than its spacing allowed). The centre path alone, in its first campaign, passed a scan whose last 2 points were
/// lost on a face (C r500, 270 of 272) that the surface path sees.
fn curve_gap(motion: &ScanMotion, centres: &[Point3<f64>], ball_radius_mm: f64) -> Option<Gap> {
    let path = &motion.path;
    let centre_path: Vec<Point3<f64>> = path
        .surface
        .iter()
        .zip(&path.normals)
        .map(|(p, n)| p + n * ball_radius_mm)
        .collect();
    match &motion.scan {
        Scan::Curve(scan) if scan.density == Density::AtNominals => {
            let reach = scan.max_deviation + ball_radius_mm;
            missing_at_nominals(path, &centre_path, reach, centres)
        }
        _ => gap_along(motion, &path.surface, centres)
            .or_else(|| gap_along(motion, &centre_path, centres)),
    }
}

/// A scan with one point per nominal (`AtNominals`, the station's curve scans) that came back short has lost
/// points, however few: a lost data line of a point or two leaves a hole no spacing shows (the 1000-fault campaign
/// lost a closed scan's last point, A r300 with 350 of 351, when the machine chose the points by spacing). The
/// hole is before the first point that lies ahead of its own nominal, or at the end when every point has its own.
/// `centre_path` is the path's nominals moved out along their normals by the ball's radius (the scan's first
/// point at the path's entry), and each nominal's probing line reaches `reach` either side of it.
///
/// Which nominal a point belongs to: the one whose probing line (through its centre-path point along its normal,
/// where the machine moves the ball's centre) passes nearest it, from two nominals before its own to two past the
/// farthest it can have moved ahead. Why not the nearest point of the centre path: round a sharp edge the plan's
/// lines fan out from a pivot inside it (`plan::fan`), 0.26 mm apart on the centre path, and a point 0.4 mm out
/// along its line lay nearer a neighbour's stretch of the path: one point lost there was reported 8 points late.
fn missing_at_nominals(
    path: &KnownPath,
    centre_path: &[Point3<f64>],
    reach: f64,
    centres: &[Point3<f64>],
) -> Option<Gap> {
    let (closed, entry) = (path.closed, path.entry);
    let n = centre_path.len();
    if centres.len() >= n || n < 2 {
        return None;
    }
    let missing = n - centres.len();
    // Nominal `k` (unwrapped: it may run past the end of a closed path).
    let index = |k: usize| if closed { k % n } else { k.min(n - 1) };
    let at = |k: usize| centre_path[index(k)];
    // Where along the path, in nominals from the scan's first, point `i` lies.
    let place = |i: usize| -> f64 {
        let own = entry + i;
        let off_line = |k: usize| {
            let (a, along) = (at(k), path.normals[index(k)]);
            let t = (centres[i] - a).dot(&along).clamp(-reach, reach);
            (centres[i] - (a + along * t)).norm()
        };
        let nearest = (own.saturating_sub(2)..own + missing + 2)
            .min_by(|&a, &b| off_line(a).total_cmp(&off_line(b)))
            .expect("a range of nominals");
        nearest as f64 - entry as f64
    };
    let first_ahead = (0..centres.len()).find(|&i| place(i) > i as f64 + 0.5);
    let spacing = |k: usize| (at(k + 1) - at(k)).norm();
    let (after, from) = match first_ahead {
        _ if centres.is_empty() => (None, 0),
        Some(0) => (None, 0),
        Some(i) => (Some(i - 1), i),
        None => (Some(centres.len() - 1), centres.len()),
    };
    Some(Gap {
        after,
        at: after.map_or(centre_path[entry], |i| centres[i]),
        length_mm: (from..from + missing).map(|i| spacing(entry + i)).sum(),
    })
}

/// The first hole in `centres` followed along `nominal`, the scan's nominal path (surface or ball centres).
fn gap_along(motion: &ScanMotion, nominal: &[Point3<f64>], centres: &[Point3<f64>]) -> Option<Gap> {
    let path = &motion.path;
    let n = nominal.len();
    let segments = if path.closed { n } else { n - 1 };
    let length = |i: usize| (nominal[(i + 1) % n] - nominal[i]).norm();
    let mut start_of = Vec::with_capacity(segments + 1);
    let mut total = 0.0;
    for i in 0..segments {
        start_of.push(total);
        total += length(i);
    }
    let spacing = (0..segments).map(length).fold(0.0, f64::max);
    let entry = start_of.get(path.entry).copied().unwrap_or(0.0);
    let mut spans: Vec<(f64, f64)> = (0..segments)
        .filter_map(|i| {
            let mut from = start_of[i] - entry;
            if path.closed && from < 0.0 {
                from += total;
            }
            (from >= 0.0).then(|| (from, length(i)))
        })
        .collect();
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    let travelled = Segments {
        spans,
        widest: spacing,
    };
    // Arc lengths from the entry, in the direction of travel, each looked for ahead of the last.
    let mut positions = Vec::with_capacity(centres.len());
    let mut last = 0.0;
    for centre in centres {
        let mut best = (f64::INFINITY, last);
        for (i, &from) in start_of.iter().enumerate() {
            let (a, b) = (nominal[i], nominal[(i + 1) % n]);
            let ab = b - a;
            let t = ((centre - a).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
            let distance = (centre - (a + ab * t)).norm();
            let mut along = from + t * ab.norm() - entry;
            if path.closed && along < 0.0 {
                along += total;
            }
            let ahead = along - last;
            if (-spacing..=LOOK_AHEAD * spacing).contains(&ahead) && distance < best.0 {
                best = (distance, along);
            }
        }
        last = best.1.max(last);
        positions.push(last);
    }
    let Some(&first) = positions.first() else {
        return Some(Gap {
            after: None,
            at: motion.end,
            length_mm: total,
        });
    };
    if first > SPACING_FACTOR * travelled.spacing(0.0, first) {
        return Some(Gap {
            after: None,
            at: nominal[path.entry],
            length_mm: first,
        });
    }
    if let Some((i, step)) = first_long_step(&positions, |from, to| travelled.spacing(from, to)) {
        return Some(Gap {
            after: Some(i),
            at: centres[i],
            length_mm: step,
        });
    }
    let end = if path.closed { total } else { total - entry };
    let last = positions[positions.len() - 1];
    let short = end - last;
    (short > SPACING_FACTOR * travelled.spacing(last, end)).then(|| Gap {
        after: Some(centres.len() - 1),
        at: centres[centres.len() - 1],
        length_mm: short,
    })
}

fn teach_gap(
    motion: &ScanMotion,
    centres: &[Point3<f64>],
    spacing: &InPlaneSpacing,
    stop_diameter: f64,
) -> Option<Gap> {
    let step = spacing.max_distance();
    let (Some(first), Some(last)) = (centres.first(), centres.last()) else {
        return Some(Gap {
            after: None,
            at: motion.end,
            length_mm: 0.0,
        });
    };
    let mut travelled = vec![0.0];
    for pair in centres.windows(2) {
        travelled.push(travelled[travelled.len() - 1] + (pair[1] - pair[0]).norm());
    }
    let long = first_long_step(&travelled, |_, _| step);
    let turned = match (*spacing, &motion.scan) {
        (InPlaneSpacing::Spacing { max_angle, .. }, Scan::InPlane(scan)) => {
            let n = scan.plane_normal;
            first_wide_turn(centres, max_angle, &Vector3::new(n.x, n.y, n.z))
        }
        _ => None,
    };
    if let Some(i) = [long.map(|(i, _)| i), turned].into_iter().flatten().min() {
        return Some(Gap {
            after: Some(i),
            at: centres[i],
            length_mm: travelled[i + 1] - travelled[i],
        });
    }
    // The scan closes in the stop sphere round its start.
    let short = (last - first).norm();
    (short > SPACING_FACTOR * step + stop_diameter).then(|| Gap {
        after: Some(centres.len() - 1),
        at: *last,
        length_mm: short,
    })
}

/// The first step of a scan spaced by `max_angle` (rad) across which the centres' path turns by more than
/// [`TURN_LOST_STEPS`] of it beyond what the chords of [`TURN_CHORD_STEPS`] before and after it turn, in the sense
/// the scan goes round the part (about `plane_normal`, the scan's plane's): where the ball rolls round it. Across
/// a concave corner the ball leaves one face for the other at once and the centres turn the other way with no
/// point between them, which is no hole.
fn first_wide_turn(
    centres: &[Point3<f64>],
    max_angle: f64,
    plane_normal: &Vector3<f64>,
) -> Option<usize> {
    let k = TURN_CHORD_STEPS;
    let first = centres.first()?;
    // The sense the scan goes round in, by the signed area its centres enclose.
    let sense = centres
        .windows(2)
        .map(|w| (w[0] - first).cross(&(w[1] - first)).dot(plane_normal))
        .sum::<f64>()
        .signum();
    let allowed = (k as f64 + 1.0 + TURN_LOST_STEPS) * max_angle;
    let first = (k..centres.len().saturating_sub(k + 1)).find(|&i| {
        let before = centres[i] - centres[i - k];
        let after = centres[i + 1 + k] - centres[i + 1];
        before.cross(&after).dot(plane_normal) * sense > 0.0 && before.angle(&after) > allowed
    })?;
    // The turn first shows when the hole enters the chord after the step: the hole is the longest step of those
    // up to the chord's end.
    (first..=first + k).max_by(|&a, &b| {
        let length = |j: usize| (centres[j + 1] - centres[j]).norm();
        length(a).total_cmp(&length(b))
    })
}

#[cfg(test)]
mod tests;
