//! Gaps found where lines of points were lost, and none in whole scans: round a circle, along a NACA 4412 with
//! its sharp trailing edge (the real blade 0.4 mm off the nominal, as blade B), and in a teach scan.

use nalgebra::{Point3, Vector3};
use zeroset_drivers::machine::{CurveScan, Density, InPlaneScan, InPlaneSpacing, Nominal, Xyz};
use zeroset_sim::naca::Naca4;

use super::*;
use crate::config::Safety;
use crate::plan::ProfileKey;
use crate::station::escape::KnownPath;

fn safety() -> Safety {
    Safety {
        clearance_z_mm: 150.0,
        max_ball_radius_mm: 1.5,
        move_margin_mm: 0.5,
    }
}

/// The ball's radius, mm.
const BALL: f64 = 1.0;

const KEY: ProfileKey = ProfileKey {
    instance: 1,
    profile: 0,
};

fn curve_motion(path: KnownPath) -> ScanMotion {
    curve_motion_at(
        path,
        Density::Spacing {
            max_distance: 1.0,
            max_angle: 0.2,
        },
    )
}

/// As [`curve_motion`], the machine reporting points at `density`.
fn curve_motion_at(path: KnownPath, density: Density) -> ScanMotion {
    let scan = Scan::Curve(CurveScan {
        closed: true,
        nominals: Vec::new(),
        max_deviation: 3.0,
        min_radius: 1.0,
        density,
    });
    ScanMotion::plan(KEY, "B r300".into(), scan, path, 5.0, &safety()).unwrap()
}

/// A NACA 4412 of 100 mm chord in the plane x = 300, entered at the top of its upper surface; `count` nominals.
fn naca_path(count: usize) -> KnownPath {
    let naca = Naca4::from_digits("4412", 100.0, true).unwrap();
    let points: Vec<Point3<f64>> = naca
        .points(count)
        .into_iter()
        .map(|[x, z]| Point3::new(300.0, x - 50.0, z))
        .collect();
    let n = points.len();
    let normals: Vec<Vector3<f64>> = (0..n)
        .map(|i| {
            let d = points[(i + 1) % n] - points[(i + n - 1) % n];
            Vector3::new(0.0, d.z, -d.y).normalize()
        })
        .collect();
    let top = (0..n / 2)
        .max_by(|&a, &b| points[a].z.total_cmp(&points[b].z))
        .unwrap();
    // Entered at the top: the path starts there, as the station's curve scans do.
    let order: Vec<usize> = (0..n).map(|k| (top + k) % n).collect();
    KnownPath {
        surface: order.iter().map(|&i| points[i]).collect(),
        normals: order.iter().map(|&i| normals[i]).collect(),
        closed: true,
        entry: 0,
    }
}

/// Ball centres of a whole closed scan over `path`: the ball (1 mm) on a surface `offset` mm off the nominal,
/// `per` points per nominal spacing.
fn centres(path: &KnownPath, offset: f64, per: usize) -> Vec<Point3<f64>> {
    let n = path.surface.len();
    (0..n)
        .flat_map(|i| {
            let j = (i + 1) % n;
            (0..per).map(move |k| (i, j, k as f64 / per as f64))
        })
        .map(|(i, j, t)| {
            let p = path.surface[i] + (path.surface[j] - path.surface[i]) * t;
            let normal = (path.normals[i] * (1.0 - t) + path.normals[j] * t).normalize();
            p + normal * (BALL + offset)
        })
        .collect()
}

#[test]
fn a_whole_scan_has_no_gap_even_round_a_sharp_edge_and_off_the_nominal() {
    for (count, per, offset) in [(120, 1, 0.0), (200, 2, 0.4), (200, 3, -0.4), (400, 1, 1.0)] {
        let path = naca_path(count);
        let motion = curve_motion(path.clone());
        let scan = centres(&path, offset, per);
        assert_eq!(
            find_gap(&motion, &scan, BALL),
            None,
            "{count} nominals, {per} per spacing"
        );
    }
}

#[test]
fn a_lost_line_of_points_is_a_gap_wherever_it_was_lost() {
    let path = naca_path(200);
    let motion = curve_motion(path.clone());
    let whole = centres(&path, 0.4, 2);
    for lost_from in [0, 37, 150, 199, 330, whole.len() - 10] {
        let mut scan = whole.clone();
        scan.drain(lost_from..lost_from + 10);
        let gap = find_gap(&motion, &scan, BALL)
            .unwrap_or_else(|| panic!("10 points lost at {lost_from}"));
        assert!(gap.length_mm > 3.0, "{gap}");
        match lost_from {
            0 => assert_eq!(gap.after, None),
            _ => assert_eq!(gap.after, Some(lost_from - 1), "{gap}"),
        }
    }
    // Nothing at all is a gap too.
    assert!(find_gap(&motion, &[], BALL).is_some());
}

fn teach_motion() -> ScanMotion {
    teach_motion_spaced(InPlaneSpacing::Step(1.0))
}

fn teach_motion_spaced(spacing: InPlaneSpacing) -> ScanMotion {
    let start = Point3::new(100.0, 0.0, 20.0);
    let path = KnownPath {
        surface: vec![start],
        normals: vec![Vector3::new(0.0, 0.0, 1.0)],
        closed: false,
        entry: 0,
    };
    let xyz = |x, y, z| Xyz::new(x, y, z);
    let scan = Scan::InPlane(InPlaneScan {
        start: xyz(100.0, 0.0, 20.0),
        start_normal: xyz(0.0, 0.0, 1.0),
        plane_normal: xyz(1.0, 0.0, 0.0),
        direction: xyz(100.0, 1.0, 20.0),
        spacing,
        end: xyz(100.0, 0.0, 20.0),
        stop_diameter: 3.0,
        passes: 1,
        end_normal: xyz(0.0, 0.0, 1.0),
    });
    ScanMotion::plan(KEY, "A r100".into(), scan, path, 5.0, &safety()).unwrap()
}

#[test]
fn a_teach_scan_is_whole_when_its_steps_are_and_it_closes() {
    // Round a circle of 20 mm (ball centres on 21 mm) at 1 mm steps, ending inside the stop sphere.
    let centre = |k: usize| {
        let t = std::f64::consts::FRAC_PI_2 + k as f64 / 21.0;
        Point3::new(100.0, 21.0 * t.cos(), 21.0 * t.sin())
    };
    let turn = (std::f64::consts::TAU * 21.0).floor() as usize;
    let whole: Vec<Point3<f64>> = (0..turn).map(centre).collect();
    let motion = teach_motion();
    assert_eq!(find_gap(&motion, &whole, BALL), None);
    let mut holed = whole.clone();
    holed.drain(60..70);
    assert_eq!(find_gap(&motion, &holed, BALL).unwrap().after, Some(59));
    let cut = &whole[..turn - 10];
    assert_eq!(find_gap(&motion, cut, BALL).unwrap().after, Some(turn - 11));
}

/// The ball centres (plane x = 100, (y, z) mm) of a teach scan spaced by 1 mm and 2.5 deg round the polygon
/// `corners` (clockwise seen from +x, so the scan goes round the part the one way), rolling round each convex
/// corner and leaving one face for the next at once at a concave one, with 2 um of seeded noise.
fn spaced_teach_centres(corners: &[[f64; 2]]) -> Vec<Point3<f64>> {
    let n = corners.len();
    let v = |i: usize| nalgebra::Vector2::from(corners[i % n]);
    let along = |i: usize| (v(i + 1) - v(i)).normalize();
    // Outward normal of a clockwise polygon: the edge's direction turned +90 deg.
    let out = |i: usize| nalgebra::Vector2::new(-along(i).y, along(i).x);
    let step_angle = 2.5f64.to_radians();
    let mut path: Vec<nalgebra::Vector2<f64>> = Vec::new();
    for i in 0..n {
        // Each face's centre line runs between where it leaves the corners at its ends.
        let trim = |before: usize, after: usize| {
            // A concave corner (turning anticlockwise here): the centre lines meet BALL * tan(half the turn) from
            // it along each face.
            if along(before).perp(&along(after)) > 0.0 {
                BALL * (along(before).angle(&along(after)) / 2.0).tan()
            } else {
                0.0
            }
        };
        let (from, to) = (trim(i + n - 1, i), trim(i, i + 1));
        let length = (v(i + 1) - v(i)).norm() - from - to;
        let steps = length.ceil() as usize;
        for k in 0..steps {
            path.push(v(i) + along(i) * (from + length * k as f64 / steps as f64) + out(i) * BALL);
        }
        // Round the next corner, if it is convex (turning clockwise): the ball rolls on its apex.
        if along(i).perp(&along(i + 1)) < 0.0 {
            let turn = along(i).angle(&along(i + 1));
            let steps = (turn / step_angle).ceil() as usize;
            for k in 0..steps {
                let a = -turn * k as f64 / steps as f64;
                path.push(v(i + 1) + nalgebra::Rotation2::new(a) * out(i) * BALL);
            }
        }
    }
    // Seeded noise, uniform with 2 um standard deviation on each axis.
    let mut state: u64 = 7;
    let mut noise = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.002 * 12f64.sqrt()
    };
    path.iter()
        .map(|p| Point3::new(100.0, p.x + noise(), p.y + noise()))
        .collect()
}

#[test]
fn a_teach_scan_spaced_by_turn_is_a_gap_where_points_are_lost_round_a_roll_and_not_at_a_concave_corner(
) {
    let spaced = teach_motion_spaced(InPlaneSpacing::Spacing {
        max_distance: 1.0,
        max_angle: 2.5f64.to_radians(),
    });
    // A thin plate, 40 x 2 mm, its ends sharp edges the ball rolls round in 72 steps of 2.5 deg (44 um), clockwise
    // from its top left.
    let plate = spaced_teach_centres(&[[-20.0, 1.0], [20.0, 1.0], [20.0, -1.0], [-20.0, -1.0]]);
    assert_eq!(find_gap(&spaced, &plate, BALL), None);
    // Points lost round the right end's roll (it starts after the 40 points of the top face): a line of ten, and
    // three. The step's spacing alone (1 mm, the old check) misses the three: 0.18 mm.
    for lost in [10, 3] {
        let mut holed = plate.clone();
        holed.drain(60..60 + lost);
        assert_eq!(
            find_gap(&spaced, &holed, BALL).map(|gap| gap.after),
            Some(Some(59)),
            "{lost} lost"
        );
        if lost == 3 {
            assert_eq!(find_gap(&teach_motion(), &holed, BALL), None);
        }
    }
    // A step down in the top face: a concave corner (the ball leaves the floor for the wall at once, its centres
    // turning 90 deg the other way with no point between) and a convex one it rolls round.
    let stepped = spaced_teach_centres(&[
        [-20.0, 1.0],
        [0.0, 1.0],
        [0.0, 3.0],
        [20.0, 3.0],
        [20.0, -1.0],
        [-20.0, -1.0],
    ]);
    assert_eq!(find_gap(&spaced, &stepped, BALL), None);
}

/// Drops `lost` points of a whole scan at each of `froms` in turn: each loss is a gap found after the point
/// before it, with a length.
fn assert_losses_found_where_lost(
    motion: &ScanMotion,
    whole: &[Point3<f64>],
    lost: usize,
    froms: impl IntoIterator<Item = usize>,
) {
    for from in froms {
        let mut scan = whole.to_vec();
        scan.drain(from..from + lost);
        let gap =
            find_gap(motion, &scan, BALL).unwrap_or_else(|| panic!("{lost} points lost at {from}"));
        assert_eq!(gap.after, Some(from - 1), "{lost} lost at {from}: {gap}");
        assert!(gap.length_mm > 0.0, "{gap}");
    }
}

#[test]
fn a_single_point_lost_anywhere_from_a_scan_at_its_nominals_is_a_gap_there() {
    // One point per nominal (the station's curve scans), the surface 0.4 mm off the nominal, entered at the top
    // and at the trailing edge's fan: any one point, or any two together, lost.
    let path = naca_path(200);
    for entry in [0, edge(&path, Edge::Trailing)] {
        let mut path = path.clone();
        path.entry = entry;
        let motion = curve_motion_at(path.clone(), Density::AtNominals);
        let mut whole = centres(&path, 0.4, 1);
        whole.rotate_left(entry);
        assert_eq!(find_gap(&motion, &whole, BALL), None);
        for lost in [1, 2] {
            assert_losses_found_where_lost(
                &motion,
                &whole,
                lost,
                [1, 17, 99, 100, 150, whole.len() - lost],
            );
            let gap = find_gap(&motion, &whole[lost..], BALL).expect("the first points lost");
            assert_eq!(gap.after, None, "{gap}");
        }
        assert!(find_gap(&motion, &[], BALL).is_some());
        // More points than nominals is no gap.
        assert_eq!(find_gap(&motion, &centres(&path, 0.4, 2), BALL), None);
    }
}

/// `path` (see [`with_fan`]) with the lines round its sharp trailing edge fanned out from a pivot 1 mm inside it,
/// aimed at a 1.5 mm ball's centres, as the plan probes them (`plan::fan`).
fn with_fanned_lines(path: &KnownPath) -> KnownPath {
    let trailing = edge(path, Edge::Trailing);
    let n = path.surface.len();
    let (from, to) = (
        path.normals[(trailing + n - 1) % n],
        path.normals[(trailing + 1) % n],
    );
    let apex = path.surface[trailing];
    let sharp = crate::analysis::edges::SharpEdge {
        apex: [apex.y, apex.z],
        from_normal: [from.y, from.z],
        turn_rad: (from.y * to.z - from.z * to.y).atan2(from.dot(&to)),
    };
    let xyz = |v: &Vector3<f64>| Xyz::new(v.x, v.y, v.z);
    let nominals: Vec<Nominal> = path
        .surface
        .iter()
        .zip(&path.normals)
        .map(|(p, n)| Nominal {
            point: xyz(&p.coords),
            normal: xyz(n),
        })
        .collect();
    let fanned = crate::plan::fan::fanned(&nominals, &[sharp], 1.0, 1.5);
    KnownPath {
        surface: fanned
            .iter()
            .map(|n| Point3::new(n.point.x, n.point.y, n.point.z))
            .collect(),
        normals: fanned
            .iter()
            .map(|n| Vector3::new(n.normal.x, n.normal.y, n.normal.z))
            .collect(),
        ..path.clone()
    }
}

#[test]
fn a_point_lost_on_a_fanned_line_round_a_sharp_edge_is_a_gap_there() {
    // One point per nominal, the ball on each fanned line 0.4 mm beyond the master's: any one point or two lost
    // round the edge, or just before or after it, is found where it was lost.
    let path = with_fan(&naca_path(200), 16);
    let trailing = edge(&path, Edge::Trailing);
    let fanned = with_fanned_lines(&path);
    let moved = (0..path.surface.len())
        .filter(|&i| (fanned.surface[i] - path.surface[i]).norm() > 1e-9)
        .count();
    assert!(moved >= 14, "{moved} nominals fanned");
    let motion = curve_motion_at(fanned.clone(), Density::AtNominals);
    let whole = centres(&fanned, 0.4, 1);
    assert_eq!(find_gap(&motion, &whole, BALL), None);
    for lost in [1, 2] {
        assert_losses_found_where_lost(&motion, &whole, lost, trailing - 2..trailing + 18);
    }
}

#[test]
fn the_last_few_points_lost_where_the_nominals_crowd_are_a_gap() {
    // The NACA's nominals crowd at its edges: entered at the leading edge, the scan ends there, where a data
    // line cut short (its last points lost) is shorter than one spacing of the faces.
    for (count, per, offset) in [(200, 1, 0.4), (272, 1, -0.4), (390, 1, 0.0), (200, 2, 0.4)] {
        let path = naca_path(count);
        let (motion, whole) = whole_scan_entered_at(&path, edge(&path, Edge::Leading), offset, per);
        for lost in 1 + per..=10 {
            let cut = &whole[..whole.len() - lost];
            let gap = find_gap(&motion, cut, BALL)
                .unwrap_or_else(|| panic!("{count} nominals, the last {lost} points lost"));
            assert_eq!(gap.after, Some(cut.len() - 1), "{gap}");
        }
        // And the first line, where the scan enters (the nominals there grow apart too fast for a point or
        // two to tell from their spacing).
        let gap = find_gap(&motion, &whole[10..], BALL).expect("the first line lost");
        assert_eq!(gap.after, None, "{gap}");
    }
}

enum Edge {
    Leading,
    Trailing,
}

/// The nominal at the section's leading edge (least y) or trailing edge (greatest y; the first of a fan).
fn edge(path: &KnownPath, which: Edge) -> usize {
    let y = |i: usize| path.surface[i].y;
    let all = 0..path.surface.len();
    match which {
        Edge::Leading => all.min_by(|&a, &b| y(a).total_cmp(&y(b))),
        Edge::Trailing => all.max_by(|&a, &b| y(a).total_cmp(&y(b)).then(b.cmp(&a))),
    }
    .unwrap()
}

/// The motion of a scan of `path` entered at nominal `entry`, and its whole scan (see [`centres`]), which has
/// no gap.
fn whole_scan_entered_at(
    path: &KnownPath,
    entry: usize,
    offset: f64,
    per: usize,
) -> (ScanMotion, Vec<Point3<f64>>) {
    let mut path = path.clone();
    path.entry = entry;
    let motion = curve_motion(path.clone());
    let mut whole = centres(&path, offset, per);
    whole.rotate_left(entry * per);
    assert_eq!(
        find_gap(&motion, &whole, BALL),
        None,
        "{} nominals entered at {entry}: whole",
        path.surface.len()
    );
    (motion, whole)
}

/// `path` with its sharp trailing edge (its point farthest along +y) made a fan of `count` nominals at that one
/// point, their normals turning from the upper face's to the lower face's, as the master's taught nominals are
/// (the plan then fans their lines out from a pivot inside the edge, `plan::fan`): the ball rolls round the edge
/// while the surface path stays where it is.
fn with_fan(path: &KnownPath, count: usize) -> KnownPath {
    let n = path.surface.len();
    let edge = edge(path, Edge::Trailing);
    let (before, after) = (
        path.normals[(edge + n - 1) % n],
        path.normals[(edge + 1) % n],
    );
    let mut fanned = path.clone();
    let fan: Vec<Vector3<f64>> = (0..count)
        .map(|k| {
            let t = k as f64 / (count - 1) as f64;
            (before * (1.0 - t) + after * t).normalize()
        })
        .collect();
    fanned.normals.splice(edge..=edge, fan);
    fanned
        .surface
        .splice(edge..=edge, std::iter::repeat_n(path.surface[edge], count));
    fanned
}

#[test]
fn the_first_lines_lost_round_a_sharp_trailing_edge_are_a_gap() {
    // Entered on the upper face just ahead of the sharp trailing edge (the top of a pitched blade section is an
    // edge): the scan's first points roll round the edge and come back along the lower face, close to where it
    // entered, which is what is left when its first lines are lost (CI's campaign: C r200 with 370 of 390).
    for (count, per, offset) in [(200, 1, 0.4), (272, 1, -0.4), (390, 1, 0.0), (200, 2, 0.4)] {
        let path = with_fan(&naca_path(count), 16);
        let trailing = edge(&path, Edge::Trailing);
        // Entered one nominal ahead of the edge, as the campaign's C r200 was, or on the edge's fan itself.
        for entry in [trailing - 1, trailing + 12, trailing + 14] {
            let (motion, whole) = whole_scan_entered_at(&path, entry, offset, per);
            for lost in [10, 20] {
                let gap = find_gap(&motion, &whole[lost..], BALL).unwrap_or_else(|| {
                    panic!("{count} nominals, entered at {entry} (edge {trailing}), the first {lost} points lost")
                });
                assert_eq!(gap.after, None, "{gap}");
            }
        }
    }
}
