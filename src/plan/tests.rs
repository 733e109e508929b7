use std::path::Path;

use nalgebra::{Point2, Point3};
use zeroset_sim::config::{PartSpec, SimConfig};
use zeroset_sim::part::curve::SampledCurve;
use zeroset_sim::part::propeller::Propeller;

use super::*;
use crate::config::{Pose, StationConfig};

const TURN_120: (f64, f64) = (-0.5, 0.866_025_403_784_438_6);

fn propeller_part() -> PartConfig {
    PartConfig::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("config/parts/propeller.toml"))
        .unwrap()
}

/// The propeller's part file, every curve scan's density set by `max_angle_deg` alone.
fn part_at_max_angle() -> PartConfig {
    let mut part = propeller_part();
    part.scan.round_edge_max_angle_deg = None;
    part
}

fn plan() -> Plan {
    Plan::new(&part_at_max_angle(), Isometry3::identity())
}

fn simulated_propeller() -> Propeller {
    let sim =
        SimConfig::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("config/sims/propeller.toml"))
            .unwrap();
    let PartSpec::Propeller(spec) = &sim.parts["propeller"] else {
        panic!("config/sims/propeller.toml holds a propeller");
    };
    Propeller::new(spec.clone()).unwrap()
}

fn key(instance: usize, profile: usize) -> ProfileKey {
    ProfileKey { instance, profile }
}

fn point(x: &Xyz) -> Point3<f64> {
    Point3::new(x.x, x.y, x.z)
}

fn assert_near(actual: &Xyz, expected: [f64; 3], what: &str) {
    let off = (point(actual) - Point3::from(expected)).norm();
    assert!(off < 1e-9, "{what}: {actual:?}, expected {expected:?}");
}

#[test]
fn names_scans_and_descriptions() {
    let plan = plan();
    assert_eq!(plan.part(), "propeller");
    assert_eq!(plan.instance_names(), ["A", "B", "C"]);
    assert_eq!(plan.master(), 0);
    assert_eq!(
        plan.profile_names(),
        ["r100", "r200", "r300", "r400", "r500"]
    );
    assert_eq!(plan.profile_x(2), 300.0);
    assert_eq!(
        plan.describe(key(1, 2)),
        "instance B, profile r300 (x = 300 mm)"
    );
    let teach = plan.teach_scans();
    assert_eq!(teach, (0..5).map(|p| key(0, p)).collect::<Vec<_>>());
    let inspect = plan.inspect_scans();
    assert_eq!(inspect.len(), 15);
    assert_eq!(
        (inspect[0], inspect[5], inspect[14]),
        (key(0, 0), key(1, 0), key(2, 4))
    );
    assert_eq!(plan.scan_settings().step_mm, 1.0);
    assert!(matches!(
        plan.reference_settings(),
        ReferenceSettings::ImplicitPolynomial { degree: 8, .. }
    ));
    assert_eq!(plan.tolerance().upper_mm, 0.1);
}

#[test]
fn blade_b_is_blade_a_turned_120_degrees_about_the_hub_axis() {
    let plan = plan();
    // r300 of blade A starts at (300, 0, 13.32): on blade B that is 300 mm along 120 degrees.
    let a = plan.scan_start(key(0, 2), None);
    assert!((a - Point3::new(300.0, 0.0, 13.32)).norm() < 1e-12, "{a}");
    let b = plan.scan_start(key(1, 2), None);
    let (cos, sin) = TURN_120;
    assert!(
        (b - Point3::new(300.0 * cos, 300.0 * sin, 13.32)).norm() < 1e-9,
        "{b}"
    );
    assert!((b - Point3::new(-150.0, 259.807_621_135_331_6, 13.32)).norm() < 1e-9);
    // Blade C is 240 degrees round: the mirror of B in the xz plane.
    let c = plan.scan_start(key(2, 2), None);
    assert!(
        (c - Point3::new(-150.0, -259.807_621_135_331_6, 13.32)).norm() < 1e-9,
        "{c}"
    );
}

#[test]
fn a_fixture_offset_moves_every_instance_after_the_turn() {
    let part_to_machine = Pose {
        x_mm: 10.0,
        y_mm: -5.0,
        z_mm: 12.5,
        rot_z_deg: 90.0,
        ..Pose::default()
    };
    let plan = Plan::new(&propeller_part(), part_to_machine.isometry());
    // A at (300, 0): the fixture turns it to (0, 300) and shifts it.
    let a = plan.scan_start(key(0, 2), None);
    assert!((a - Point3::new(10.0, 295.0, 25.82)).norm() < 1e-9, "{a}");
    // B at 120 degrees, the fixture turns it to 210 degrees.
    let b = plan.scan_start(key(1, 2), None);
    let at_210 = Point3::new(-259.807_621_135_331_6 + 10.0, -150.0 - 5.0, 25.82);
    assert!((b - at_210).norm() < 1e-9, "{b}");
}

#[test]
fn a_master_other_than_the_first_instance_stays_in_place() {
    let mut part = propeller_part();
    part.instances.master = "B".into();
    let plan = Plan::new(&part, Isometry3::identity());
    assert_eq!(plan.master(), 1);
    assert_eq!(plan.instance_to_machine(1), Isometry3::identity());
    // A comes before B: it is B's frame turned back by one step.
    let a = plan.scan_start(key(0, 0), None);
    let (cos, sin) = TURN_120;
    assert!(
        (a - Point3::new(100.0 * cos, -100.0 * sin, 23.98)).norm() < 1e-9,
        "{a}"
    );
}

#[test]
fn instances_turn_about_the_configured_axis_point() {
    let mut part = propeller_part();
    part.instances.axis_point_mm = [10.0, 0.0, 0.0];
    let plan = Plan::new(&part, Isometry3::identity());
    // r100 starts 90 mm from the axis: blade B's start is 90 mm along 120 degrees from (10, 0).
    let b = plan.scan_start(key(1, 0), None);
    let (cos, sin) = TURN_120;
    assert!(
        (b - Point3::new(10.0 + 90.0 * cos, 90.0 * sin, 23.98)).norm() < 1e-9,
        "{b}"
    );
}

/// The teach scan of blade A at radius 200, as the end-to-end test's scan that the simulator completes:
/// started on the surface from above, in the plane x = 200, heading along +y, ending where it began.
#[test]
fn the_teach_scan_of_blade_a_starts_on_the_simulated_surface_in_the_plane_x() {
    let scan = plan().in_plane_scan(key(0, 1));
    let truth = simulated_propeller();
    let frame = truth.section_frame(0, 200.0);
    let section = SampledCurve::new(truth.section_curve(0, 200.0));
    let local = frame.local(&point(&scan.start));
    assert!(
        local.z.abs() < 1e-12,
        "off the plane x = 200: {:?}",
        scan.start
    );
    let off = section
        .nearest(&Point2::new(local.x, local.y))
        .signed_distance;
    assert!(off.abs() < 0.05, "{off} mm off blade A");
    assert_near(&scan.start, [200.0, 0.0, 16.34], "start");
    assert_near(&scan.start_normal, [0.0, 0.0, 1.0], "start normal");
    assert_near(&scan.plane_normal, [1.0, 0.0, 0.0], "plane normal");
    assert_near(&scan.direction, [200.0, 10.0, 16.34], "direction point");
    assert_near(&scan.end, [200.0, 0.0, 17.34], "end");
    assert_near(&scan.end_normal, [0.0, 0.0, 1.0], "end normal");
    assert_eq!((scan.stop_diameter, scan.passes), (3.0, 1));
    assert_eq!(
        scan.spacing,
        InPlaneSpacing::Spacing {
            max_distance: 1.0,
            max_angle: 10f64.to_radians()
        }
    );
}

#[test]
fn the_teach_scan_of_another_instance_turns_its_plane_with_it() {
    let scan = plan().in_plane_scan(key(1, 1));
    let (cos, sin) = TURN_120;
    assert_near(&scan.plane_normal, [cos, sin, 0.0], "plane normal");
    assert_near(&scan.start, [200.0 * cos, 200.0 * sin, 16.34], "start");
    // The heading +y of blade A is turned too.
    assert_near(
        &scan.direction,
        [200.0 * cos - 10.0 * sin, 200.0 * sin + 10.0 * cos, 16.34],
        "direction point",
    );
    assert_near(&scan.start_normal, [0.0, 0.0, 1.0], "start normal");
}

/// Scan nominals per taught step of [`circle`] at the propeller's scan density (1 mm, 10 deg): ceil(5.18 / 1).
const PER_STEP: usize = 6;

/// Twelve nominals round a circle of radius 10 in the plane x = 200 about (200, 0, 20), counterclockwise
/// from +y: the one at 90 degrees (index 3) points straight up.
fn circle() -> Vec<NominalPoint> {
    (0..12)
        .map(|k| {
            let (sin, cos) = (k as f64 * 30.0).to_radians().sin_cos();
            NominalPoint {
                point: [200.0, 10.0 * cos, 20.0 + 10.0 * sin],
                normal: [0.0, cos, sin],
            }
        })
        .collect()
}

#[test]
fn a_curve_scan_starts_at_the_most_upward_normal_and_keeps_the_taught_order() {
    let plan = plan();
    let nominals = circle();
    let scan = plan.curve_scan(key(0, 1), &nominals, &[], 1.5);
    assert!(scan.closed);
    // Each taught step (30 deg, 5.18 mm) is cut into PER_STEP at the scan's 1 mm: taught nominal k is the
    // scan's PER_STEP k-th.
    assert_eq!(scan.nominals.len(), 12 * PER_STEP);
    assert_near(&scan.nominals[0].point, [200.0, 0.0, 30.0], "first point");
    assert_near(&scan.nominals[0].normal, [0.0, 0.0, 1.0], "first normal");
    // Then on round the circle the way it was taught, wrapping past the end of the list.
    let (sin, cos) = 120f64.to_radians().sin_cos();
    assert_near(
        &scan.nominals[PER_STEP].point,
        [200.0, 10.0 * cos, 20.0 + 10.0 * sin],
        "second",
    );
    assert_near(
        &scan.nominals[11 * PER_STEP].point,
        nominals[2].point,
        "last",
    );
    assert_eq!(scan.max_deviation, 3.0);
    assert_eq!(scan.min_radius, 1.0);
    assert_eq!(scan.density, Density::AtNominals);
    // Between them, points at most 1 mm apart on the chords, normals turning at most 10 deg.
    let n = scan.nominals.len();
    for i in 0..n {
        let (a, b) = (scan.nominals[i], scan.nominals[(i + 1) % n]);
        assert!(
            (point(&b.point) - point(&a.point)).norm() <= 1.0 + 1e-9,
            "step {i}"
        );
        let (na, nb) = (point(&a.normal).coords, point(&b.normal).coords);
        assert!(na.angle(&nb) <= 10f64.to_radians() + 1e-9, "turn {i}");
        assert!((na.norm() - 1.0).abs() < 1e-12);
    }
    let start = plan.scan_start(key(0, 1), Some(&nominals));
    assert!(
        (start - Point3::new(200.0, 0.0, 30.0)).norm() < 1e-9,
        "{start}"
    );
}

#[test]
fn a_curve_scan_starts_clear_of_a_sharp_edge_where_the_profile_leaves_room() {
    // A thin section in the plane x = 200: its upper face (z = 1, every 2 mm from y = -40 to 38) leans so that
    // its normal points most nearly up at y = 38, 2 mm before the sharp edge at y = 40 (three nominals at one
    // point, a fan of normals). The scan starts at the most upward normal 15 mm or more from the edge: y = 24.
    let normal = |y: f64, z: f64| {
        let n = Vector3::new(0.0, y, z).normalize();
        [n.x, n.y, n.z]
    };
    let mut nominals: Vec<NominalPoint> = (0..40)
        .map(|k| {
            let y = -40.0 + 2.0 * k as f64;
            NominalPoint {
                point: [200.0, y, 1.0],
                normal: normal(0.01 * (y - 38.0), 1.0),
            }
        })
        .collect();
    nominals.extend([30.0f64, 90.0, 150.0].map(|deg| NominalPoint {
        point: [200.0, 40.0, 0.0],
        normal: normal(deg.to_radians().sin(), deg.to_radians().cos()),
    }));
    nominals.extend((0..40).map(|k| NominalPoint {
        point: [200.0, 38.0 - 2.0 * k as f64, -1.0],
        normal: [0.0, 0.0, -1.0],
    }));
    nominals.push(NominalPoint {
        point: [200.0, -41.0, 0.0],
        normal: [0.0, -1.0, 0.0],
    });
    let start = plan().scan_start(key(0, 1), Some(&nominals));
    assert!(
        (start - Point3::new(200.0, 24.0, 1.0)).norm() < 1e-9,
        "{start}"
    );
}

#[test]
fn round_edges_are_scanned_finer_and_a_sharp_edges_roll_keeps_the_scans_angle() {
    // The taught circle (radius 10 mm, a nominal every 30 deg, 5.18 mm apart): at 4 deg round its round edges
    // each step is cut in 8 (the scan's 1 mm would cut it in 6); beside a sharp edge's apex (at the nominal of
    // 0 deg, (y, z) = (10, 20)) the scan's 10 deg and 1 mm leave 6.
    let mut part = propeller_part();
    part.scan.round_edge_max_angle_deg = Some(4.0);
    let plan = Plan::new(&part, Isometry3::identity());
    let turn = |a: &Xyz, b: &Xyz| {
        Vector3::new(a.x, a.y, a.z)
            .angle(&Vector3::new(b.x, b.y, b.z))
            .to_degrees()
    };
    let largest_turn = |scan: &CurveScan| {
        let n = scan.nominals.len();
        (0..n)
            .map(|i| turn(&scan.nominals[i].normal, &scan.nominals[(i + 1) % n].normal))
            .fold(0.0, f64::max)
    };
    let round = plan.curve_scan(key(0, 1), &circle(), &[], 1.5);
    assert_eq!(round.nominals.len(), 12 * 8);
    assert!(largest_turn(&round) <= 4.0, "{}", largest_turn(&round));
    let edge = SharpEdge {
        apex: [10.0, 20.0],
        from_normal: [0.0, 1.0],
        turn_rad: -std::f64::consts::FRAC_PI_2,
    };
    let sharp = plan.curve_scan(key(0, 1), &circle(), &[edge], 1.5);
    assert_eq!(sharp.nominals.len(), 10 * 8 + 2 * 6);
    // Six pieces of 30 deg by normals interpolated along their chord: about 5 deg, 5.1 at the middle. The
    // nominals within the fan's 1 mm of the apex (the apex and one 0.86 mm off it each side) probe along lines
    // through its pivot instead, and are left out.
    let apex = Point3::new(200.0, 10.0, 20.0);
    let off_the_fan = |n: &Nominal| (point(&n.point) - apex).norm() >= 1.0;
    let n = sharp.nominals.len();
    let pairs_off_the_fan: Vec<(Nominal, Nominal)> = (0..n)
        .map(|i| (sharp.nominals[i], sharp.nominals[(i + 1) % n]))
        .filter(|(a, b)| off_the_fan(a) && off_the_fan(b))
        .collect();
    assert_eq!(pairs_off_the_fan.len(), n - 4);
    let beside_edge = pairs_off_the_fan
        .iter()
        .map(|(a, b)| turn(&a.normal, &b.normal))
        .fold(0.0, f64::max);
    assert!(beside_edge > 5.0 && beside_edge < 5.2, "{beside_edge}");
    // Without the key every step is cut at the scan's own 1 mm and 10 deg.
    let coarse = self::plan().curve_scan(key(0, 1), &circle(), &[edge], 1.5);
    assert_eq!(coarse.nominals.len(), 12 * PER_STEP);
}

#[test]
fn a_curve_scan_on_blade_b_turns_points_and_normals() {
    let plan = plan();
    let scan = plan.curve_scan(key(1, 1), &circle(), &[], 1.5);
    let (cos, sin) = TURN_120;
    // The top (200, 0, 30) turned onto blade B; its normal, up, stays up.
    assert_near(
        &scan.nominals[0].point,
        [200.0 * cos, 200.0 * sin, 30.0],
        "first point",
    );
    assert_near(&scan.nominals[0].normal, [0.0, 0.0, 1.0], "first normal");
    // The nominal at 0 degrees, (200, 10, 20) with normal +y, is the ninth taught after the top.
    let side = scan.nominals[9 * PER_STEP];
    assert_near(
        &side.point,
        [200.0 * cos - 10.0 * sin, 200.0 * sin + 10.0 * cos, 20.0],
        "side point",
    );
    assert_near(&side.normal, [-sin, cos, 0.0], "side normal");
    let start = plan.scan_start(key(1, 1), Some(&circle()));
    assert!((start - point(&scan.nominals[0].point)).norm() < 1e-12);
}

#[test]
fn a_fixture_turn_that_tilts_nothing_keeps_the_upward_start() {
    // Upward means +z in machine coordinates: a turn about z changes no normal's z.
    let turned = Pose {
        rot_z_deg: 37.0,
        ..Pose::default()
    };
    let plan = Plan::new(&part_at_max_angle(), turned.isometry());
    let scan = plan.curve_scan(key(2, 0), &circle(), &[], 1.5);
    assert_near(&scan.nominals[0].normal, [0.0, 0.0, 1.0], "first normal");
    let z: Vec<f64> = scan.nominals.iter().map(|n| n.point.z).collect();
    assert_eq!(z.len(), 12 * PER_STEP);
    assert!(
        (z[0] - 30.0).abs() < 1e-9 && (z[6 * PER_STEP] - 10.0).abs() < 1e-9,
        "{z:?}"
    );
}

#[test]
fn nearest_compares_horizontal_distances_and_breaks_ties_by_key() {
    let plan = plan();
    let starts = |k: ProfileKey| match (k.instance, k.profile) {
        (0, 0) => Point3::new(100.0, 0.0, 0.0),
        // Horizontally nearest to the origin, though 500 mm below it.
        (0, 1) => Point3::new(30.0, 40.0, -500.0),
        (1, 0) => Point3::new(0.0, 60.0, 0.0),
        // As near as (0, 1): the tie goes to the smaller key.
        (2, 3) => Point3::new(-50.0, 0.0, 0.0),
        _ => unreachable!("not in the list"),
    };
    let from = Point3::new(0.0, 0.0, 0.0);
    let remaining = [key(1, 0), key(2, 3), key(0, 0), key(0, 1)];
    assert_eq!(plan.nearest(&remaining, from, starts), Some(3));
    let reversed = [key(0, 1), key(0, 0), key(2, 3), key(1, 0)];
    assert_eq!(plan.nearest(&reversed, from, starts), Some(0));
    let without = [key(1, 0), key(2, 3), key(0, 0)];
    assert_eq!(plan.nearest(&without, from, starts), Some(1));
    assert_eq!(plan.nearest(&[], from, starts), None);
}

fn repo(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// A shipped station file, and the plan of one of its parts placed by it.
fn shipped(station: &str, part: &str) -> (StationConfig, Plan) {
    let station = StationConfig::load(&repo(station)).unwrap();
    let part = PartConfig::load(&station.part_path(part)).unwrap();
    let plan = Plan::new(&part, station.part_to_machine.isometry());
    (station, plan)
}

#[test]
fn the_shipped_clearance_clears_the_shipped_parts_and_10_mm_is_refused_with_the_height_needed() {
    // The propeller's highest start is r100's at z = 23.98 mm; the nut, stood up, has its part x up, so its
    // highest start is h19's at z = 19 mm. Each plus max_deviation_mm (3 and 1 mm), the 1.5 mm ball and the
    // 0.5 mm margin.
    for (file, part, highest, needed) in [
        (
            "config/station.toml",
            "propeller",
            "instance A's profile r100 start point lies at z = 23.98 mm",
            28.98,
        ),
        (
            "config/station-nut.toml",
            "nut",
            "instance nut's profile h19 start point lies at z = 19.00 mm",
            22.0,
        ),
    ] {
        let (mut station, plan) = shipped(file, part);
        assert_eq!(station.safety.clearance_z_mm, 150.0);
        check_clearance(&station, &plan, None).unwrap();
        station.safety.clearance_z_mm = 10.0;
        let message = check_clearance(&station, &plan, None)
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with(&repo(file).display().to_string()),
            "{message}"
        );
        assert!(
            message.contains(&format!(
                "[safety] clearance_z_mm = 10 mm does not clear part {part} ({})",
                station.part_path(part).display()
            )),
            "{message}"
        );
        assert!(message.contains(highest), "{message}");
        assert!(
            message.contains(&format!("needs clearance_z_mm above {needed:.2} mm")),
            "{message}"
        );
        // Just below the height needed is refused, just above it accepted.
        station.safety.clearance_z_mm = needed - 0.01;
        assert!(check_clearance(&station, &plan, None).is_err());
        station.safety.clearance_z_mm = needed + 0.01;
        check_clearance(&station, &plan, None).unwrap();
    }
    // Lying flat (the propeller's station), the nut's starts are on its underside: the shipped height clears.
    let (station, plan) = shipped("config/station.toml", "nut");
    check_clearance(&station, &plan, None).unwrap();
}

#[test]
fn taught_nominals_above_the_start_points_raise_the_height_needed() {
    let (mut station, plan) = shipped("config/station.toml", "propeller");
    let mut reference = crate::analysis::test_profiles::taught_ellipses().clone();
    // A trailing edge that stands up near the hub, as the propeller's do: taught, not in the drawing.
    reference.profiles[0].nominals[5].point = [100.0, -40.0, 83.0];
    station.safety.clearance_z_mm = 60.0;
    check_clearance(&station, &plan, None).unwrap();
    let message = check_clearance(&station, &plan, Some(&reference))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("instance A's profile x100 taught nominal 5 lies at z = 83.00 mm"),
        "{message}"
    );
    assert!(
        message.contains("needs clearance_z_mm above 88.00 mm"),
        "{message}"
    );
    station.safety.clearance_z_mm = 88.5;
    check_clearance(&station, &plan, Some(&reference)).unwrap();
}
