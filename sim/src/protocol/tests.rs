//! The controller driven line by line with a hand-turned clock.

use std::path::Path;

use nalgebra::{Point2, Point3};
use zeroset_drivers::wire::{Data, ResponseKind};

use super::*;
use crate::config::SimConfig;
use crate::part::curve::SampledCurve;
use crate::part::propeller::Propeller;
use crate::part::Part;

struct Bench {
    controller: Controller,
    propeller: Arc<Propeller>,
    now: f64,
}

impl Bench {
    fn new() -> Self {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/sims/propeller.toml");
        let config = SimConfig::load(&path).unwrap();
        let crate::config::PartSpec::Propeller(spec) = &config.parts["propeller"] else {
            panic!("propeller.toml holds the propeller");
        };
        let propeller = Arc::new(Propeller::new(spec.clone()).unwrap());
        let part: Arc<dyn Part> = propeller.clone();
        Bench {
            controller: Controller::new(&config.machines[0], part),
            propeller,
            now: 0.0,
        }
    }

    /// Sends a line and returns what comes back by the time the transaction completes (or `wait`
    /// seconds pass, whichever is first).
    fn send(&mut self, line: &str, wait: f64) -> Vec<String> {
        let mut out: Vec<String> = self
            .controller
            .receive(line.parse().unwrap(), self.now)
            .iter()
            .map(|r| r.to_string())
            .collect();
        let until = self.now + wait;
        while let Some(deadline) = self.controller.next_deadline() {
            if deadline > until {
                self.now = until;
                break;
            }
            self.now = self.now.max(deadline);
            out.extend(self.controller.poll(self.now).iter().map(|r| r.to_string()));
        }
        out
    }

    /// The surface point of blade A's section at `radius` straight above the chord's middle.
    fn top_of_blade_a(&self, radius: f64) -> Point3<f64> {
        let frame = self.propeller.section_frame(0, radius);
        let section = SampledCurve::new(self.propeller.section_curve(0, radius));
        let top = section.nearest(&Point2::new(0.0, 100.0)).on_curve;
        frame.world(top.point.x, top.point.y, 0.0)
    }

    fn ready(&mut self) {
        self.send("00001 StartSession()", 0.0);
        self.send("00002 Home()", 100.0);
        self.send("00003 ChangeTool(\"Probe1\")", 0.0);
    }
}

#[test]
fn outside_a_session_only_start_and_end_are_accepted() {
    let mut bench = Bench::new();
    assert_eq!(
        bench.send("00001 Home()", 1.0),
        [
            "00001 &",
            "00001 ! Error(3, 0008, \"Home\", \"Protocol error\")",
            "00001 %"
        ]
    );
    assert_eq!(
        bench.send("00002 EndSession()", 0.0),
        ["00002 &", "00002 %"]
    );
    assert_eq!(
        bench.send("00003 StartSession()", 0.0),
        ["00003 &", "00003 %"]
    );
    let again = bench.send("00004 StartSession()", 0.0);
    assert!(again[1].contains("0008"), "{again:?}");
}

#[test]
fn moves_need_home_and_a_tool() {
    let mut bench = Bench::new();
    bench.send("00001 StartSession()", 0.0);
    let not_homed = bench.send("00002 GoTo(X(10))", 1.0);
    assert!(not_homed[1].contains("0507"), "{not_homed:?}");
    bench.send("00003 ClearAllErrors()", 0.0);
    assert_eq!(bench.send("00004 IsHomed()", 0.0)[1], "00004 # IsHomed(0)");
    let home = bench.send("00005 Home()", 100.0);
    assert_eq!(home, ["00005 &", "00005 %"]);
    assert_eq!(bench.send("00006 IsHomed()", 0.0)[1], "00006 # IsHomed(1)");
    let no_tool = bench.send("00007 PtMeas(X(200), Y(0), Z(100), IJK(0, 0, 1))", 1.0);
    assert!(no_tool[1].contains("1503"), "{no_tool:?}");
    bench.send("00008 ClearAllErrors()", 0.0);
    let unknown = bench.send("00009 ChangeTool(\"Laser\")", 0.0);
    assert!(unknown[1].contains("1502"), "{unknown:?}");
    bench.send("00010 ClearAllErrors()", 0.0);
    assert_eq!(
        bench.send("00011 ChangeTool(\"Probe1\")", 0.0),
        ["00011 &", "00011 %"]
    );
    assert_eq!(
        bench.send("00012 GetProp(Tool.Name(), Tool.AvrRadius())", 0.0)[1],
        "00012 # Tool.Name(\"Probe1\"), Tool.AvrRadius(1)"
    );
}

#[test]
fn a_move_takes_the_time_of_its_trapezoid() {
    let mut bench = Bench::new();
    bench.ready();
    let start = bench.now;
    bench.send(
        "00004 SetProp(Tool.GoToPar.Speed(50), Tool.GoToPar.Accel(500))",
        0.0,
    );
    let reply = bench.send("00005 GoTo(X(0), Y(0), Z(300))", 100.0);
    assert_eq!(reply, ["00005 &", "00005 %"]);
    // 100 mm at 50 mm/s with 0.1 s ramps.
    assert!(
        (bench.now - start - 2.1).abs() < 1e-9,
        "{}",
        bench.now - start
    );
    let reply = bench.send("00006 Get(X(), Y(), Z())", 0.0);
    assert_eq!(reply[1], "00006 # X(0), Y(0), Z(300)");
    let clamped = bench.send("00007 SetProp(Tool.GoToPar.Speed(5000))", 0.0);
    assert_eq!(
        clamped[1],
        "00007 ! Error(1, 0504, \"SetProp\", \"Argument out of range\")"
    );
    assert_eq!(
        bench.send("00008 GetProp(Tool.GoToPar.Speed())", 0.0)[1],
        "00008 # Tool.GoToPar.Speed(500)"
    );
}

#[test]
fn leaving_the_volume_or_cutting_the_part_is_refused() {
    let mut bench = Bench::new();
    bench.ready();
    let out = bench.send("00004 GoTo(X(5000))", 10.0);
    assert!(out[1].contains("2500"), "{out:?}");
    bench.send("00005 ClearAllErrors()", 0.0);
    // Straight down through blade A at radius 200.
    bench.send("00006 GoTo(X(200), Y(0), Z(200))", 100.0);
    let out = bench.send("00007 GoTo(X(200), Y(0), Z(-200))", 100.0);
    assert_eq!(
        out[1], "00007 ! Error(3, 2504, \"GoTo\", \"Collision\")",
        "{out:?}"
    );
    let stopped = bench.controller.position(bench.now);
    let surface = bench.propeller.nearest(&stopped);
    assert!((surface.signed_distance - 1.0).abs() < 1e-5, "{surface:?}");
    let refused = bench.send("00008 GoTo(X(200), Y(0), Z(200))", 100.0);
    assert!(refused[1].contains("0514"), "{refused:?}");
    assert_eq!(
        bench.send("00009 ClearAllErrors()", 0.0),
        ["00009 &", "00009 %"]
    );
    assert_eq!(
        bench.send("00010 GoTo(X(200), Y(0), Z(200))", 100.0),
        ["00010 &", "00010 %"]
    );
}

#[test]
fn ptmeas_reports_the_ball_centre_and_normal_or_no_touch() {
    let mut bench = Bench::new();
    bench.ready();
    bench.send("00004 OnPtMeasReport(X(), Y(), Z(), IJK(), ER())", 0.0);
    bench.send("00005 GoTo(X(200), Y(0), Z(100))", 100.0);
    let frame = bench.propeller.section_frame(0, 200.0);
    let section = SampledCurve::new(bench.propeller.section_curve(0, 200.0));
    let nominal = bench.top_of_blade_a(200.0);
    let line = format!(
        "00006 PtMeas(X({:.6}), Y({:.6}), Z({:.6}), IJK(0, 0, 1))",
        nominal.x, nominal.y, nominal.z
    );
    let out = bench.controller.receive(line.parse().unwrap(), bench.now);
    assert_eq!(out.len(), 1);
    let mut lines = Vec::new();
    while let Some(deadline) = bench.controller.next_deadline() {
        bench.now = deadline;
        lines.extend(bench.controller.poll(bench.now));
    }
    let ResponseKind::Data(Data::Calls(calls)) = lines[0].kind() else {
        panic!("{lines:?}");
    };
    let value = |i: usize, k: usize| match &calls[i].args[k] {
        Arg::Number(n) => n.value(),
        other => panic!("{other:?}"),
    };
    let centre = Point3::new(value(0, 0), value(1, 0), value(2, 0));
    let normal = nalgebra::Vector3::new(value(3, 0), value(3, 1), value(3, 2));
    assert_eq!(value(4, 0), 1.0);
    let surface = centre - normal * 1.0;
    let local = frame.local(&surface);
    let distance = section
        .nearest(&Point2::new(local.x, local.y))
        .signed_distance;
    assert!(distance.abs() < 0.02, "{distance}");
    assert!(lines[1].to_string() == "00006 %");

    let miss = bench.send("00007 PtMeas(X(200), Y(0), Z(300), IJK(0, 0, 1))", 100.0);
    assert!(miss[1].contains("1003"), "{miss:?}");
}

/// The points of a scan's data lines (`X, Y, Z, I, J, K` each, the default scan report of ball centres and
/// normals), and its error line if it failed.
fn scan_points_and_error(lines: &[String]) -> (Vec<Point3<f64>>, Option<&String>) {
    let mut points = Vec::new();
    for line in lines.iter().filter(|l| l.contains(" # ")) {
        let values: Vec<f64> = line
            .split_once(" # ")
            .unwrap()
            .1
            .split(',')
            .map(|v| v.trim().parse().unwrap())
            .collect();
        points.extend(values.chunks(6).map(|v| Point3::new(v[0], v[1], v[2])));
    }
    (points, lines.iter().find(|l| l.contains(" ! ")))
}

/// An in-plane scan of blade A at r200, from above the middle of its chord round the section.
fn in_plane_scan_line(bench: &Bench, tag: u32) -> String {
    let top = bench.top_of_blade_a(200.0);
    let (y, z) = (top.y, top.z);
    format!(
        "{tag:05} ScanInPlaneEndIsSphere(200, {y:.5}, {z:.5}, 0, 0, 1, 1, 0, 0, 200, {:.5}, {z:.5}, 1, \
         200, {y:.5}, {:.5}, 3, 1, 0, 0, 1)",
        y + 10.0,
        z + 1.0,
    )
}

/// A curve scan along blade A's upper face at r200, 41 nominals 1 mm apart, 0.5 mm expected deviation.
fn curve_scan_line(bench: &Bench, tag: u32) -> String {
    let frame = bench.propeller.section_frame(0, 200.0);
    let section = SampledCurve::new(bench.propeller.section_curve(0, 200.0));
    let top = section.nearest(&Point2::new(0.0, 100.0)).on_curve;
    let mut data = Vec::new();
    for k in -20..=20 {
        let along = section
            .nearest(&Point2::new(top.point.x + f64::from(k), 100.0))
            .on_curve;
        let p = frame.world(along.point.x, along.point.y, 0.0);
        let n = frame.world_dir(along.normal.x, along.normal.y, 0.0);
        data.push(format!(
            "{:.6}, {:.6}, {:.6}, {:.6}, {:.6}, {:.6}, 1",
            p.x, p.y, p.z, n.x, n.y, n.z
        ));
    }
    format!(
        "{tag:05} ScanOnCurve(Closed(0), Format(X(), Y(), Z(), IJK(), tag), Data({}))",
        data.join(", ")
    )
}

#[test]
fn a_scan_that_loses_its_touch_sends_its_first_half_then_1003_and_stops_where_it_touched_last() {
    for (what, scan) in [
        ("in plane", in_plane_scan_line as fn(&Bench, u32) -> String),
        ("on curve", curve_scan_line),
    ] {
        let mut bench = Bench::new();
        bench.ready();
        bench.send("00003 OnScanReport(X(), Y(), Z(), IJK())", 0.0);
        bench.send("00004 ScanOnCurveHint(0.5, 0.5)", 0.0);
        bench.send("00005 ScanOnCurveDensity(AtNominals(1))", 0.0);
        bench.send("00006 GoTo(X(200), Y(0), Z(100))", 100.0);
        let whole = bench.send(&scan(&bench, 7), 1000.0);
        let (all, error) = scan_points_and_error(&whole);
        assert!(error.is_none() && all.len() > 20, "{what}: {whole:?}");
        assert_eq!(whole.last().unwrap(), "00007 %", "{what}");

        bench.send("00008 GoTo(X(200), Y(0), Z(100))", 100.0);
        bench.controller.arm(Armed {
            no_touch: true,
            ..Armed::default()
        });
        let lost = bench.send(&scan(&bench, 9), 1000.0);
        let (half, error) = scan_points_and_error(&lost);
        let error = error.unwrap_or_else(|| panic!("{what}: {lost:?}"));
        assert!(error.contains(", 1003, "), "{what}: {error}");
        assert_eq!(bench.controller.armed(), Armed::default(), "{what}");
        assert_eq!(half.len(), all.len() / 2, "{what}");
        for (a, b) in half.iter().zip(&all) {
            assert!((a - b).norm() < 0.05, "{what}: {a} against {b}");
        }
        let last = half.last().unwrap();
        let here = bench.controller.position(bench.now + 10.0);
        assert!(
            (here - last).norm() < 0.05,
            "{what}: stopped at {here}, last touched {last}"
        );
        let refused = bench.send("00010 GoTo(X(200), Y(0), Z(100))", 100.0);
        assert!(refused[1].contains("0514"), "{what}: {refused:?}");
    }
}

#[test]
fn abort_stops_a_scan_and_wants_clear_all_errors() {
    let mut bench = Bench::new();
    bench.ready();
    bench.send("00004 GoTo(X(200), Y(0), Z(100))", 100.0);
    let top = bench.top_of_blade_a(200.0);
    let (y, z) = (top.y, top.z);
    let scan = format!(
        "00005 ScanInPlaneEndIsSphere(200, {y:.5}, {z:.5}, 0, 0, 1, 1, 0, 0, 200, {:.5}, {z:.5}, 0.5, \
         200, {y:.5}, {:.5}, 3, 1, 0, 0, 1)",
        y + 10.0,
        z + 1.0
    );
    let scan = scan.as_str();
    let first = bench.send(scan, 2.0);
    assert!(first.len() >= 2, "{first:?}");
    assert!(!first.iter().any(|l| l == "00005 %"), "{first:?}");
    let moved_before = bench.controller.position(bench.now);
    let aborted: Vec<String> = bench
        .controller
        .receive("E0006 AbortE()".parse().unwrap(), bench.now)
        .iter()
        .map(|r| r.to_string())
        .collect();
    assert_eq!(
        aborted,
        [
            "E0006 &",
            "00005 ! Error(2, 0006, \"ScanInPlaneEndIsSphere\", \"Transaction aborted (Use ClearAllErrors To Continue)\")",
            "00005 %",
            "E0006 %"
        ]
    );
    assert_eq!(bench.controller.next_deadline(), None);
    assert_eq!(bench.controller.position(bench.now + 10.0), moved_before);
    let status = bench.send("E0007 GetErrStatusE()", 0.0);
    assert_eq!(status[1], "E0007 # ErrStatus(1)");
    let refused = bench.send("00008 Home()", 100.0);
    assert!(refused[1].contains("0514"), "{refused:?}");
    bench.send("00009 ClearAllErrors()", 0.0);
    assert_eq!(
        bench.send("E0010 GetErrStatusE()", 0.0)[1],
        "E0010 # ErrStatus(0)"
    );
}

#[test]
fn commands_waiting_behind_a_failing_one_are_aborted() {
    let mut bench = Bench::new();
    bench.ready();
    let mut out = bench
        .controller
        .receive("00004 GoTo(X(5000))".parse().unwrap(), bench.now);
    out.extend(
        bench
            .controller
            .receive("00005 Home()".parse().unwrap(), bench.now),
    );
    let lines: Vec<String> = out.iter().map(|r| r.to_string()).collect();
    assert_eq!(lines[0], "00004 &");
    assert!(lines[1].contains("2500"));
    assert_eq!(lines[2], "00004 %");
    assert_eq!(lines[3], "00005 &");
    assert!(lines[4].contains("0514"), "{lines:?}");
}

#[test]
fn emergency_stop_is_unsolicited_and_blocks_motion() {
    let mut bench = Bench::new();
    bench.ready();
    bench.controller.receive(
        "00004 GoTo(X(300), Y(300), Z(300))".parse().unwrap(),
        bench.now,
    );
    bench.now += 0.5;
    let stop: Vec<String> = bench
        .controller
        .emergency_stop(bench.now)
        .iter()
        .map(|r| r.to_string())
        .collect();
    assert_eq!(
        stop[0],
        "E0000 ! Error(3, 0500, \"EmergencyStop\", \"Emergency stop\")"
    );
    assert!(stop[1].starts_with("00004 ! Error(2, 0006"));
    let refused = bench.send("00005 GoTo(X(0))", 10.0);
    assert!(refused[1].contains("0514"));
    bench.send("00006 ClearAllErrors()", 0.0);
    assert_eq!(
        bench.send("00007 GoTo(X(0))", 100.0),
        ["00007 &", "00007 %"]
    );
}

#[test]
fn move_reports_follow_the_motion_until_stopped() {
    let mut bench = Bench::new();
    bench.ready();
    assert_eq!(
        bench.send(
            "E0004 OnMoveReportE(Time(0.2), Dis(20), X(), Y(), Z())",
            0.0
        ),
        ["E0004 &", "E0004 %"]
    );
    let again = bench.send("E0005 OnMoveReportE(Dis(1), X())", 0.0);
    assert!(again[1].contains("0515"));
    let out = bench.send("00006 GoTo(X(0), Y(0), Z(200))", 100.0);
    let reports: Vec<&String> = out.iter().filter(|l| l.starts_with("E0004 #")).collect();
    assert!(reports.len() >= 5, "{out:?}");
    assert_eq!(out.last().unwrap(), "00006 %");
    assert_eq!(
        bench.send("00007 StopDaemon(E0004)", 0.0),
        ["00007 &", "00007 %"]
    );
    let gone = bench.send("00008 StopDaemon(E0004)", 0.0);
    assert!(gone[1].contains("0513"));
}

#[test]
fn unknown_commands_and_bad_arguments_have_their_codes() {
    let mut bench = Bench::new();
    bench.ready();
    let out = bench.send("00004 Fly(X(1))", 0.0);
    assert!(out[1].contains("0501"), "{out:?}");
    bench.send("00005 ClearAllErrors()", 0.0);
    let out = bench.send("00006 OnScanReport(R())", 0.0);
    assert!(out[1].contains("0510"), "{out:?}");
    bench.send("00007 ClearAllErrors()", 0.0);
    let out = bench.send("00008 ScanInPlaneEndIsSphere(1, 2, 3)", 0.0);
    assert!(out[1].contains("0502"), "{out:?}");
    bench.send("00009 ClearAllErrors()", 0.0);
    let out = bench.send("00010 PtMeas(X(200), IJK(0, 0, 0))", 0.0);
    assert!(out[1].contains("1010"), "{out:?}");
    let bad = "\u{1b}[0m".parse::<Command>().unwrap_err();
    let reply = bench.controller.bad_line(&bad);
    assert!(reply[0].to_string().starts_with("E0000 ! Error("));
    assert_eq!(
        bench.send("00011 GetDMEVersion()", 0.0)[1].as_str(),
        "00011 ! Error(2, 0514, \"GetDMEVersion\", \"Use ClearAllErrors to continue\")"
    );
    bench.send("00012 ClearAllErrors()", 0.0);
    assert_eq!(
        bench.send("00013 GetDMEVersion()", 0.0)[1],
        "00013 # DMEVersion(\"1.4.3\")"
    );
    assert_eq!(
        bench.send("00014 GetMachineClass()", 0.0)[1],
        "00014 # GetMachineClass(CartCMM)"
    );
}
