//! Aborts, the emergency stop and every fault kind, through the real binary: the error each reports.

mod common;

use std::time::{Duration, Instant};

use common::{config_path, propeller, Client, Sim, REPLY};
use nalgebra::Point2;
use zeroset_drivers::wire::WireError;
use zeroset_sim::part::curve::SampledCurve;

/// A PtMeas straight down onto the top of blade A at radius 200, and a plane scan from there.
fn onto_blade_a(tag: &str) -> (String, String) {
    let truth = propeller("propeller.toml");
    let frame = truth.section_frame(0, 200.0);
    let section = SampledCurve::new(truth.section_curve(0, 200.0));
    let top = section.nearest(&Point2::new(0.0, 100.0)).on_curve.point;
    let top = frame.world(top.x, top.y, 0.0);
    let ptmeas = format!(
        "{tag} PtMeas(X(200), Y({:.5}), Z({:.5}), IJK(0, 0, 1))",
        top.y, top.z
    );
    let scan = format!(
        "{tag} ScanInPlaneEndIsSphere(200, {y:.5}, {z:.5}, 0, 0, 1, 1, 0, 0, 200, {:.5}, {z:.5}, 1, \
         200, {y:.5}, {:.5}, 3, 1, 0, 0, 1)",
        top.y + 10.0,
        top.z + 1.0,
        y = top.y,
        z = top.z,
    );
    (ptmeas, scan)
}

fn error_code(line: &str) -> &str {
    line.split(", ").nth(1).unwrap_or("")
}

#[test]
fn abort_mid_scan_aborts_it_and_wants_clear_all_errors() {
    // 10x: the scan takes about 1.6 s, time enough to abort it in the middle.
    let sim = Sim::start(&config_path("propeller.toml"), 10.0);
    let mut client = Client::open(sim.path("cmm1"));
    client.ready();
    client.transact("00004 GoTo(X(200), Y(0), Z(100))");
    let (_, scan) = onto_blade_a("00005");
    client.send(&scan);
    assert_eq!(client.response(REPLY).unwrap().to_string(), "00005 &");
    let first_points = client.response(REPLY).unwrap().to_string();
    assert!(first_points.starts_with("00005 # "), "{first_points}");
    let aborted = client.transact("E0006 AbortE()");
    let tail: Vec<&str> = aborted
        .iter()
        .map(String::as_str)
        .skip_while(|l| l.starts_with("00005 # "))
        .collect();
    assert_eq!(
        tail,
        [
            "E0006 &",
            "00005 ! Error(2, 0006, \"ScanInPlaneEndIsSphere\", \"Transaction aborted (Use ClearAllErrors To Continue)\")",
            "00005 %",
            "E0006 %"
        ]
    );
    assert_eq!(
        client.transact("E0007 GetErrStatusE()")[1],
        "E0007 # ErrStatus(1)"
    );
    let refused = client.transact("00008 GoTo(X(200), Y(0), Z(150))");
    assert_eq!(error_code(&refused[1]), "0514", "{refused:?}");
    assert_eq!(
        client.transact("00009 ClearAllErrors()"),
        ["00009 &", "00009 %"]
    );
    assert_eq!(
        client.transact("00010 GoTo(X(200), Y(0), Z(150))"),
        ["00010 &", "00010 %"]
    );
}

#[test]
fn an_emergency_stop_stops_motion_until_clear_all_errors() {
    let mut sim = Sim::start(&config_path("propeller.toml"), 10.0);
    let mut client = Client::open(sim.path("cmm1"));
    client.ready();
    // About 0.7 s of wall time at 10x.
    client.send("00004 GoTo(X(400), Y(400), Z(300))");
    assert_eq!(client.response(REPLY).unwrap().to_string(), "00004 &");
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(sim.control("fault cmm1 estop"), "ok fault cmm1 estop");
    let stop: Vec<String> = (0..3)
        .map(|_| client.response(REPLY).unwrap().to_string())
        .collect();
    assert_eq!(
        stop[0],
        "E0000 ! Error(3, 0500, \"EmergencyStop\", \"Emergency stop\")"
    );
    assert_eq!(error_code(&stop[1]), "0006");
    assert_eq!(stop[2], "00004 %");
    client.transact("00005 Get(X(), Y(), Z())");
    for (tag, command) in [("00006", "GoTo(X(0))"), ("00007", "Home()")] {
        let refused = client.transact(&format!("{tag} {command}"));
        assert_eq!(error_code(&refused[1]), "0514", "{refused:?}");
    }
    client.transact("00008 ClearAllErrors()");
    assert_eq!(
        client.transact("00009 GoTo(X(0), Y(0), Z(400))"),
        ["00009 &", "00009 %"]
    );
}

#[test]
fn line_faults_garbage_dropped_lines_late_replies_and_a_dead_line() {
    let mut sim = Sim::start(&config_path("propeller.toml"), 100.0);
    let mut client = Client::open(sim.path("cmm1"));
    client.ready();

    assert_eq!(sim.control("fault cmm1 garbage"), "ok fault cmm1 garbage");
    let garbage = client.next(REPLY).unwrap().unwrap_err();
    assert!(
        matches!(garbage.problem(), WireError::IllegalCharacter(_)),
        "{garbage}"
    );
    assert_eq!(client.transact("00004 IsHomed()")[1], "00004 # IsHomed(1)");

    sim.control("fault cmm1 drop-lines 1");
    assert_eq!(
        client.transact("00005 IsHomed()"),
        ["00005 # IsHomed(1)", "00005 %"],
        "the & is lost"
    );

    sim.control("fault cmm1 delay 300");
    let sent = Instant::now();
    let late = client.transact("00006 IsHomed()");
    assert!(sent.elapsed() >= Duration::from_millis(300));
    assert_eq!(late, ["00006 &", "00006 # IsHomed(1)", "00006 %"]);

    sim.control("fault cmm1 disconnect 400");
    client.send("00007 IsHomed()");
    assert!(
        client.next(Duration::from_millis(250)).is_none(),
        "a dead line"
    );
    std::thread::sleep(Duration::from_millis(250));
    // The session was lost with the line; the machine is still homed.
    let lost = client.transact("00008 IsHomed()");
    assert_eq!(error_code(&lost[1]), "0008", "{lost:?}");
    client.transact("00009 StartSession()");
    assert_eq!(client.transact("00010 IsHomed()")[1], "00010 # IsHomed(1)");

    assert!(sim
        .control("fault cmm9 estop")
        .starts_with("error: no machine"));
    assert!(sim
        .control("fault cmm1 meteor")
        .starts_with("error: unknown fault"));
}

#[test]
fn motion_faults_and_their_natural_causes_report_2504_1003_and_1006() {
    let mut sim = Sim::start(&config_path("propeller.toml"), 100.0);
    let mut client = Client::open(sim.path("cmm1"));
    client.ready();
    let (ptmeas, scan) = onto_blade_a("00005");
    client.transact("00004 GoTo(X(200), Y(0), Z(100))");
    let measured = client.transact(&ptmeas);
    assert!(measured[1].starts_with("00005 # X("), "{measured:?}");

    let mut tag = 10;
    let mut expect = |client: &mut Client, command: &str, code: &str| {
        tag += 1;
        let tagged = format!("{tag:05}{}", &command[5..]);
        let out = client.transact(&tagged);
        let error = out
            .iter()
            .find(|l| l.contains(" ! "))
            .cloned()
            .unwrap_or_default();
        assert_eq!(error_code(&error), code, "{tagged}: {out:?}");
        client.transact(&format!("{:05} ClearAllErrors()", tag + 50));
    };

    // On demand.
    sim.control("fault cmm1 collision");
    expect(&mut client, "00000 GoTo(X(200), Y(0), Z(150))", "2504");
    client.transact("00090 GoTo(X(200), Y(0), Z(100))");
    sim.control("fault cmm1 no-touch");
    expect(&mut client, &ptmeas, "1003");
    client.transact("00091 GoTo(X(200), Y(0), Z(100))");
    sim.control("fault cmm1 surface-not-found");
    expect(&mut client, &scan, "1006");

    // From the geometry: down through the blade, a touch in the air, a scan beyond the tip.
    client.transact("00092 GoTo(X(200), Y(0), Z(100))");
    expect(&mut client, "00000 GoTo(X(200), Y(0), Z(-100))", "2504");
    client.transact("00093 GoTo(X(200), Y(0), Z(100))");
    expect(
        &mut client,
        "00000 PtMeas(X(200), Y(0), Z(80), IJK(0, 0, 1))",
        "1003",
    );
    expect(
        &mut client,
        "00000 ScanInPlaneEndIsSphere(620, 0, 0, 0, 0, 1, 1, 0, 0, 620, 10, 0, 1, 620, 0, 1, 3, 1, 0, 0, 1)",
        "1006",
    );
    expect(&mut client, "00000 GoTo(X(5000))", "2500");
}
