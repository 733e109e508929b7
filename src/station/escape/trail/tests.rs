//! The trail against a knife-edged blade section: the ball's travel round the edge, never reported as scan points,
//! becomes known path, and the way out follows it back round the edge instead of lifting across it blind.

use super::*;
use crate::geometry::sweep::closest::closest_between_segments;
use crate::station::escape::{way_out, EscapeError};
use zeroset_drivers::machine::{InPlaneSpacing, Xyz};

const RADIUS_MM: f64 = 0.5;
const MARGIN_MM: f64 = 5.0;
const CLEARANCE_Z_MM: f64 = 150.0;

/// A thin blade section in the plane x = 100: the upper face from (y, z) = (0, 1) down to a knife edge at (40, 0), the
/// lower face from there back to (0, -1).
struct Blade;

impl Blade {
    fn upper() -> Vector3<f64> {
        Vector3::new(0.0, 1.0, 40.0).normalize()
    }

    fn lower() -> Vector3<f64> {
        Vector3::new(0.0, 1.0, -40.0).normalize()
    }

    fn edge() -> Point3<f64> {
        Point3::new(100.0, 40.0, 0.0)
    }

    fn corners() -> [Point3<f64>; 3] {
        [
            Point3::new(100.0, 0.0, 1.0),
            Self::edge(),
            Point3::new(100.0, 0.0, -1.0),
        ]
    }

    /// The ball centre and its contact's normal every `step` mm of centre travel: along the upper face, round the
    /// edge (the centre on an arc of the ball radius), back along the lower face.
    fn centres(step: f64) -> Vec<(Point3<f64>, Vector3<f64>)> {
        let [top, edge, bottom] = Self::corners();
        let face = (top - edge).norm();
        let angle = |n: Vector3<f64>| n.z.atan2(n.y);
        let (from, to) = (angle(Self::upper()), angle(Self::lower()));
        let round = (from - to) * RADIUS_MM;
        let mut out = Vec::new();
        let mut s = 0.0;
        while s < 2.0 * face + round {
            let (contact, normal) = if s < face {
                (top + (edge - top) * (s / face), Self::upper())
            } else if s < face + round {
                let a = from - (s - face) / RADIUS_MM;
                (edge, Vector3::new(0.0, a.cos(), a.sin()))
            } else {
                (
                    edge + (bottom - edge) * ((s - face - round) / face),
                    Self::lower(),
                )
            };
            out.push((contact + normal * RADIUS_MM, normal));
            s += step;
        }
        out
    }

    /// How far the straight leg from `a` to `b` comes to the blade, mm (the ball centre's distance).
    fn least_distance(a: &Point3<f64>, b: &Point3<f64>) -> f64 {
        let [top, edge, bottom] = Self::corners();
        [(top, edge), (edge, bottom)]
            .iter()
            .map(|(p, q)| {
                let (s, t) = closest_between_segments(a, b, p, q);
                (s - t).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }
}

/// The teach scan as the station plans it: from the upper face's start along +y, the part below.
fn plan() -> InPlaneScan {
    let n = Blade::upper();
    InPlaneScan {
        start: Xyz::new(100.0, 0.0, 1.0),
        start_normal: Xyz::new(n.x, n.y, n.z),
        plane_normal: Xyz::new(1.0, 0.0, 0.0),
        direction: Xyz::new(100.0, 1.0, 1.0 - 1.0 / 40.0),
        spacing: InPlaneSpacing::Step(1.0),
        end: Xyz::new(100.0, 0.0, 1.0),
        stop_diameter: 3.0,
        passes: 1,
        end_normal: Xyz::new(n.x, n.y, n.z),
    }
}

/// The known path once the scan's first `count` points (every 1 mm of travel) are reported.
fn reported(points: &[(Point3<f64>, Vector3<f64>)], count: usize) -> KnownPath {
    KnownPath {
        surface: points[..count]
            .iter()
            .map(|(c, n)| c - n * RADIUS_MM)
            .collect(),
        normals: points[..count].iter().map(|(_, n)| *n).collect(),
        closed: false,
        entry: 0,
    }
}

/// The machine's position reports up to centre `last`: the descent over the start, then every `every`-th centre.
fn reports(points: &[(Point3<f64>, Vector3<f64>)], last: usize, every: usize) -> Vec<Point3<f64>> {
    let (start, normal) = points[0];
    (1..=3)
        .rev()
        .map(|k| start + normal * (1.5 * k as f64))
        .chain(points[..=last].iter().step_by(every).map(|(c, _)| *c))
        .collect()
}

/// Where the ball stopped: `travel` mm past the last reported point `reported`.
fn stop_after(
    points: &[(Point3<f64>, Vector3<f64>)],
    reported: usize,
    travel: usize,
) -> Point3<f64> {
    points[reported + travel].0
}

#[test]
fn travel_round_a_knife_edge_past_the_last_reported_point_is_followed_back_round_it() {
    let fine = Blade::centres(1.0);
    // For stops from before the edge to well onto the lower face, a data line of 10 points never sent (10 mm), and a report
    // every 2 mm (0.1 s at 20 mm/s) with either parity:
    for last in 30..=40 {
        for every in [2, 3] {
            let stop = stop_after(&fine, last, 10);
            let mut path = reported(&fine, last + 1);
            // The worker's trail: the reports, then where the probe is found at the clear.
            let mut trail = reports(&fine, last + 9, every);
            trail.push(stop);
            let added = extend_by_trail(&mut path, &trail, &plan(), RADIUS_MM);
            // Every report past the last point, and the stop unless the travel turned sharply to reach it.
            let beyond = (0..=last + 9).step_by(every).filter(|&i| i > last).count();
            assert!(
                added == beyond || added == beyond + 1,
                "last {last}, every {every}: {added} added of {beyond} reports and the stop"
            );
            // Each added normal points away from the blade: the ball moved along it by the margin is clear by most
            // of the margin (a normal from reports either side of the edge's turn, or from the last two, is off the
            // true one by up to half the turn between them).
            for (surface, normal) in path.surface[last + 1..]
                .iter()
                .zip(&path.normals[last + 1..])
            {
                let lifted = surface + normal * (RADIUS_MM + MARGIN_MM);
                let clear = Blade::least_distance(&lifted, &lifted);
                assert!(
                    clear >= 0.8 * MARGIN_MM,
                    "last {last}, every {every}: {normal:?} at {surface:?} ({clear:.3} mm)"
                );
            }
            // The way out lifts off from where the ball stopped and never brings it nearer the blade than the
            // ball's radius (touching) on that first leg, nor nearer than the margin after it.
            let moves = way_out(stop, Some(&path), RADIUS_MM, MARGIN_MM, CLEARANCE_Z_MM)
                .unwrap_or_else(|e| panic!("last {last}, every {every}: no way out: {e}"));
            let mut from = stop;
            for (leg, to) in moves.iter().enumerate() {
                let least = Blade::least_distance(&from, to);
                let floor = if leg == 0 {
                    RADIUS_MM - 1e-3
                } else {
                    RADIUS_MM + 0.5
                };
                assert!(
                    least >= floor,
                    "last {last}, every {every}: leg {leg} to {to:?} comes to {least:.3} mm of the blade"
                );
                from = *to;
            }
            assert!(
                (from.z - CLEARANCE_Z_MM).abs() < 1e-9,
                "ends at the clearance height: {from:?}"
            );
        }
    }
}

#[test]
fn without_the_trail_a_stop_a_data_line_past_the_last_point_is_refused() {
    let fine = Blade::centres(1.0);
    // Stops 10 mm on along the upper face, up to the edge: beyond the reach of a blind lift-off.
    for last in 24..=30 {
        let stop = stop_after(&fine, last, 10);
        let blind = reported(&fine, last + 1);
        assert!(
            matches!(
                way_out(stop, Some(&blind), RADIUS_MM, MARGIN_MM, CLEARANCE_Z_MM),
                Err(EscapeError::OffPath { .. })
            ),
            "last {last}: blind, a way out was planned from {stop:?}"
        );
        let mut known = blind.clone();
        let mut trail = reports(&fine, last + 9, 2);
        trail.push(stop);
        assert!(extend_by_trail(&mut known, &trail, &plan(), RADIUS_MM) > 0);
        assert!(
            way_out(stop, Some(&known), RADIUS_MM, MARGIN_MM, CLEARANCE_Z_MM).is_ok(),
            "last {last}: with the trail no way out"
        );
    }
}

#[test]
fn a_trail_that_never_passes_the_last_point_or_never_meets_it_adds_nothing() {
    let fine = Blade::centres(1.0);
    let mut path = reported(&fine, 20);
    let before = reports(&fine, 19, 2);
    assert_eq!(extend_by_trail(&mut path, &before, &plan(), RADIUS_MM), 0);
    let elsewhere = [
        Point3::new(100.0, 20.0, 30.0),
        Point3::new(100.0, 22.0, 30.0),
    ];
    assert_eq!(
        extend_by_trail(&mut path, &elsewhere, &plan(), RADIUS_MM),
        0
    );
    assert_eq!(path.surface.len(), 20);
}
