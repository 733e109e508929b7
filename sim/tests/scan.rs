//! A session, homing and closed profile scans through the real binary over a pseudo-terminal, checked
//! against the simulator's own analytic ground truth.

mod common;

use std::time::Instant;

use common::{config_path, propeller, scan_values, Client, Sim};
use nalgebra::{Point2, Point3, Vector3};
use zeroset_sim::config::{PartSpec, SimConfig};
use zeroset_sim::part::curve::SampledCurve;
use zeroset_sim::part::supershape::Supershape;

const SCALE: f64 = 100.0;
/// Noise is 2 um per axis: 7 sigma of one axis bounds every point of a scan.
const WITHIN_NOISE: f64 = 0.014;

/// The plane scan command around a section: start above `top` probing down, stop back at the start, a point
/// every 1 mm.
fn scan_command(
    tag: &str,
    top: Point3<f64>,
    plane_normal: Vector3<f64>,
    towards: Vector3<f64>,
) -> String {
    scan_command_stepped(tag, top, plane_normal, towards, 1.0)
}

/// ... with `StepW` = `step`.
fn scan_command_stepped(
    tag: &str,
    top: Point3<f64>,
    plane_normal: Vector3<f64>,
    towards: Vector3<f64>,
    step: f64,
) -> String {
    let d = top + towards * 10.0;
    let e = top + Vector3::z();
    format!(
        "{tag} ScanInPlaneEndIsSphere({:.5}, {:.5}, {:.5}, 0, 0, 1, {}, {}, {}, {:.5}, {:.5}, {:.5}, {step}, \
         {:.5}, {:.5}, {:.5}, 3, 1, 0, 0, 1)",
        top.x, top.y, top.z, plane_normal.x, plane_normal.y, plane_normal.z, d.x, d.y, d.z, e.x, e.y, e.z
    )
}

/// A session on a homed simulator with Probe1 and scan reports of X, Y, Z and IJK, the probe 20 mm above the
/// top of blade A's section at radius 200 mm (returned, as a surface point).
fn above_blade_a_at_200(sim: &Sim) -> (Client, Point3<f64>) {
    let mut client = Client::open(sim.path("cmm1"));
    assert_eq!(
        client.transact("00001 StartSession()"),
        ["00001 &", "00001 %"]
    );
    assert_eq!(
        client.transact("00002 GetDMEVersion()"),
        ["00002 &", "00002 # DMEVersion(\"1.4.3\")", "00002 %"]
    );
    assert_eq!(client.transact("00003 IsHomed()")[1], "00003 # IsHomed(0)");
    assert_eq!(client.transact("00004 Home()"), ["00004 &", "00004 %"]);
    assert_eq!(client.transact("00005 IsHomed()")[1], "00005 # IsHomed(1)");
    client.transact("00006 ChangeTool(\"Probe1\")");
    client.transact("00007 OnScanReport(X(), Y(), Z(), IJK())");

    let truth = propeller("propeller.toml");
    let frame = truth.section_frame(0, 200.0);
    let section = SampledCurve::new(truth.section_curve(0, 200.0));
    let top = section.nearest(&Point2::new(0.0, 100.0)).on_curve.point;
    let top = frame.world(top.x, top.y, 0.0);
    let above = format!(
        "00008 GoTo(X(200), Y({:.4}), Z({:.4}))",
        top.y,
        top.z + 20.0
    );
    assert_eq!(client.transact(&above), ["00008 &", "00008 %"]);
    (client, top)
}

/// The ball centres and reported normals of a scan's data lines tagged `tag`.
fn scanned(lines: &[String], tag: &str) -> Vec<(Point3<f64>, Vector3<f64>)> {
    let values = scan_values(lines, tag);
    assert_eq!(values.len() % 6, 0);
    values
        .chunks(6)
        .map(|v| {
            (
                Point3::new(v[0], v[1], v[2]),
                Vector3::new(v[3], v[4], v[5]),
            )
        })
        .collect()
}

#[test]
fn a_closed_profile_of_blade_a_at_radius_200_lies_on_its_analytic_section() {
    let sim = Sim::start(&config_path("propeller.toml"), SCALE);
    let (mut client, top) = above_blade_a_at_200(&sim);
    let truth = propeller("propeller.toml");
    let frame = truth.section_frame(0, 200.0);
    let section = SampledCurve::new(truth.section_curve(0, 200.0));

    let started = Instant::now();
    let lines = client.transact(&scan_command("00009", top, Vector3::x(), Vector3::y()));
    let took = started.elapsed();
    assert_eq!(lines[0], "00009 &");
    assert_eq!(lines.last().unwrap(), "00009 %");
    let points = scanned(&lines, "00009");

    // Every point: the ball centre minus the radius along the reported normal is on the section.
    for (centre, normal) in &points {
        assert!((normal.norm() - 1.0).abs() < 1e-4);
        let surface = centre - normal * 1.0;
        let local = frame.local(&surface);
        assert!(
            local.z.abs() < WITHIN_NOISE,
            "off the plane x = 200: {surface}"
        );
        let distance = section
            .nearest(&Point2::new(local.x, local.y))
            .signed_distance;
        assert!(
            distance.abs() < WITHIN_NOISE,
            "{distance} mm off at {surface}"
        );
    }

    // Once around, 1 mm apart, closing where it started.
    let around: f64 = points.windows(2).map(|w| (w[1].0 - w[0].0).norm()).sum();
    let dense = section.dense(4000);
    let perimeter: f64 = (0..dense.len())
        .map(|i| (dense[(i + 1) % dense.len()].point - dense[i].point).norm())
        .sum();
    let centre_path = perimeter + std::f64::consts::TAU * 1.0;
    assert!(
        (around - centre_path).abs() < 3.0,
        "scanned {around} mm of a {centre_path} mm centre path"
    );
    assert!(points.windows(2).all(|w| (w[1].0 - w[0].0).norm() < 1.05));
    assert!((points[0].0 - points.last().unwrap().0).norm() < 1.05);

    // At 20 mm/s (ScanPar default), the scan alone takes path / speed of machine time.
    let machine_seconds = took.as_secs_f64() * SCALE;
    assert!(
        machine_seconds > around / 20.0,
        "{machine_seconds} s for {around} mm"
    );
    assert!(sim.stop().success());
}

#[test]
fn a_profile_scanned_with_step_0_is_spaced_by_scan_unknown_density_in_distance_and_turn() {
    // Spec 11.3.1.1: StepW 0 takes ScanUnknownDensity's spacing. The section at radius 200 mm has a nose of
    // 2.7 mm radius and a sharp trailing edge the 1 mm ball rolls round: with 1 mm steps the ball's normal
    // turns by up to 57 deg between points there; spaced by 10 deg as well, by no more than that.
    let sim = Sim::start(&config_path("propeller.toml"), SCALE);
    let (mut client, top) = above_blade_a_at_200(&sim);
    assert_eq!(
        client.transact("00009 ScanUnknownDensity(Dis(1), Angle(10))"),
        ["00009 &", "00009 %"]
    );
    let spaced = scan_command_stepped("00010", top, Vector3::x(), Vector3::y(), 0.0);
    let points = scanned(&client.transact(&spaced), "00010");
    let turns: Vec<f64> = points
        .windows(2)
        .map(|w| w[0].1.angle(&w[1].1).to_degrees())
        .collect();
    // The reported normals carry the probe's noise: 10 deg within a tenth of a degree.
    let widest = turns.iter().copied().fold(0.0, f64::max);
    assert!(widest < 10.1 && widest > 9.0, "widest turn {widest} deg");
    assert!(points.windows(2).all(|w| (w[1].0 - w[0].0).norm() < 1.05));
    let by_turn = turns.iter().filter(|&&t| t > 9.0).count();
    assert!(by_turn > 16, "only {by_turn} points spaced by their turn");

    // The same scan by 1 mm steps: fewer points, turning up to 57 deg round the trailing edge.
    client.transact("00011 GoTo(X(200), Y(0), Z(100))");
    let stepped = scanned(
        &client.transact(&scan_command("00012", top, Vector3::x(), Vector3::y())),
        "00012",
    );
    let widest_stepped = stepped
        .windows(2)
        .map(|w| w[0].1.angle(&w[1].1).to_degrees())
        .fold(0.0, f64::max);
    assert!(widest_stepped > 30.0, "{widest_stepped} deg");
    assert!(
        points.len() > stepped.len() + by_turn / 2,
        "{} against {}",
        points.len(),
        stepped.len()
    );

    // Refused: a density that is not positive, or none given.
    for (line, code) in [
        ("00013 ScanUnknownDensity(Angle(-1))", "0509"),
        ("00015 ScanUnknownDensity()", "0502"),
    ] {
        let reply = client.transact(line);
        assert!(reply[1].contains(code), "{line}: {reply:?}");
        client.transact("00014 ClearAllErrors()");
    }
    assert!(sim.stop().success());
}

#[test]
fn a_section_of_the_supershape_nut_satisfies_its_implicit_function() {
    let config = SimConfig::load(&config_path("nut.toml")).unwrap();
    let PartSpec::Supershape(spec) = config.parts["nut"] else {
        panic!("nut.toml holds a supershape");
    };
    let nut = Supershape::new(spec).unwrap();
    let sim = Sim::start(&config_path("nut.toml"), SCALE);
    let mut client = Client::open(sim.path("cmm1"));
    client.ready();
    client.transact("00004 OnScanReport(X(), Y(), Z(), IJK(), Q())");
    let side = nut.outline().at(0.5).point; // theta = 0: on +x
    let start = Point3::new(side.x + 1.0, side.y, 12.0);
    client.transact("00005 GoTo(X(60), Y(0), Z(12))");
    let command = format!(
        "00006 ScanInPlaneEndIsSphere({:.5}, 0, 12, 1, 0, 0, 0, 0, 1, {:.5}, 10, 12, 1, {:.5}, 0, 12, 3, 1, 1, 0, 0)",
        start.x - 1.0,
        start.x,
        start.x
    );
    let lines = client.transact(&command);
    let values = scan_values(&lines, "00006");
    assert!(values.len() >= 7 * 240, "{} values", values.len());
    for v in values.chunks(7) {
        let surface = Point3::new(v[0], v[1], v[2]) - Vector3::new(v[3], v[4], v[5]);
        assert_eq!(v[6], 0.0, "Q of a good point");
        let f = spec.implicit(surface.x, surface.y);
        assert!((f * 40.0).abs() < WITHIN_NOISE, "F = {f} at {surface}");
        assert!((surface.z - 12.0).abs() < WITHIN_NOISE);
    }
}

#[test]
fn a_scan_along_blade_a_nominal_finds_blade_b_below_it() {
    let sim = Sim::start(&config_path("propeller.toml"), SCALE);
    let mut client = Client::open(sim.path("cmm1"));
    client.ready();
    client.transact("00004 OnScanReport(X(), Y(), Z(), IJK())");
    client.transact("00005 ScanOnCurveHint(1.5, 1)");
    client.transact("00006 ScanOnCurveDensity(Dis(1), Angle(10), AtNominals(1))");

    // Blade A's analytic section at radius 200, turned 120 degrees onto blade B: the nominal of B.
    let truth = propeller("propeller.toml");
    let nominal = SampledCurve::new(truth.section_curve(0, 200.0));
    let frame_b = truth.section_frame(1, 200.0);
    let mut data = Vec::new();
    let mut nominals = Vec::new();
    // The upper surface, leading edge and lower surface, clear of the sharp trailing edge.
    for point in nominal
        .dense(80)
        .into_iter()
        .filter(|p| (0.05..0.95).contains(&p.s))
    {
        let p = frame_b.world(point.point.x, point.point.y, 0.0);
        let n = frame_b.world_dir(point.normal.x, point.normal.y, 0.0);
        data.push(format!(
            "{:.5}, {:.5}, {:.5}, {:.6}, {:.6}, {:.6}, 1",
            p.x, p.y, p.z, n.x, n.y, n.z
        ));
        nominals.push(point);
    }
    let above = frame_b.world(0.0, 120.0, 0.0);
    client.transact(&format!(
        "00007 GoTo(X({:.4}), Y({:.4}), Z({:.4}))",
        above.x, above.y, above.z
    ));
    let command = format!(
        "00008 ScanOnCurve(Closed(0), Format(X(), Y(), Z(), IJK(), tag), Data({}))",
        data.join(", ")
    );
    let lines = client.transact(&command);
    assert_eq!(
        lines.last().unwrap(),
        "00008 %",
        "{:?}",
        &lines[lines.len() - 3..]
    );
    let values = scan_values(&lines, "00008");
    assert_eq!(values.len(), 6 * nominals.len(), "a point per nominal");

    let section_b = SampledCurve::new(truth.section_curve(1, 200.0));
    let mut below = Vec::new();
    for (v, nominal) in values.chunks(6).zip(&nominals) {
        let surface = Point3::new(v[0], v[1], v[2]) - Vector3::new(v[3], v[4], v[5]);
        let local = frame_b.local(&surface);
        let on_b = section_b
            .nearest(&Point2::new(local.x, local.y))
            .signed_distance;
        assert!(on_b.abs() < WITHIN_NOISE, "{on_b} mm off blade B");
        below.push(nominal.point.y - local.y);
    }
    // Blade B's shift at radius 200: 0.4 + 0.6 * (200 - 60) / 500 mm down; measured along the nominal
    // normals, the points lie about that far below.
    let mean = below.iter().sum::<f64>() / below.len() as f64;
    assert!(
        (0.35..0.75).contains(&mean),
        "B lies {mean} mm below A's nominal"
    );
}
