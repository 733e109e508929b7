//! Ways out of a circle, and the property that a way out planned from anywhere along a scan's moves is clear of
//! the real part or refused (`property`).

use super::*;

/// A circle of radius 20 mm in the plane x = 100, centre at z = 0, scanned from its top.
pub(crate) fn circle(closed_points: usize) -> KnownPath {
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
    let err = way_out(Point3::new(100.0, 0.0, -40.0), Some(&path), 1.0, 2.0, 150.0).unwrap_err();
    assert!(matches!(err, EscapeError::OffPath { .. }), "{err}");
    let err = way_out(Point3::new(1.0, 2.0, 3.0), None, 1.0, 2.0, 150.0).unwrap_err();
    assert!(
        err.to_string().contains("below the clearance height"),
        "{err}"
    );
}

mod property;
