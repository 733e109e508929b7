//! The station's I++ client and the simulated CMM over a real pseudo-terminal: a session, homing, a closed
//! profile scan checked against the simulator's analytic blade, an abort, an emergency stop, a disconnect and
//! reconnect, and every fault kind with the error the client reports.

use std::time::Duration;

use futures::StreamExt;
use nalgebra::{Point2, Point3, Vector3};
use zeroset_drivers::client::Client;
use zeroset_drivers::machine::{
    ErrorKind, Event, InPlaneScan, InPlaneSpacing, Machine, ScanPoint, TransportError, Xyz,
};
use zeroset_sim::part::curve::SampledCurve;

use crate::sim::{propeller, quick, Sim};

/// The simulator's noise is 2 um per axis: 7 sigma of one axis bounds every point of a scan.
const WITHIN_NOISE_MM: f64 = 0.014;
const BALL_RADIUS_MM: f64 = 1.0;

fn xyz(p: &Point3<f64>) -> Xyz {
    Xyz::new(p.x, p.y, p.z)
}

/// A started, homed machine with Probe1 (1 mm ball).
async fn ready(sim: &Sim) -> Client {
    let client = sim.client("cmm1", quick());
    client.start_session().await.expect("a session");
    assert!(!client.is_homed().await.expect("IsHomed"));
    client.home().await.expect("homing");
    assert!(client.is_homed().await.expect("IsHomed"));
    client.change_tool("Probe1").await.expect("the tool");
    let radius = client.tool_radius().await.expect("the tool radius");
    assert!(
        (radius - BALL_RADIUS_MM).abs() < 1e-9,
        "Probe1 is a 1 mm ball: {radius}"
    );
    client
}

/// The closed in-plane scan of blade A's section at radius 200 mm, starting above its top.
fn blade_a_section_scan() -> (InPlaneScan, Point3<f64>) {
    let truth = propeller();
    let frame = truth.section_frame(0, 200.0);
    let section = SampledCurve::new(truth.section_curve(0, 200.0));
    let top = section.nearest(&Point2::new(0.0, 100.0)).on_curve.point;
    let top = frame.world(top.x, top.y, 0.0);
    let scan = InPlaneScan {
        start: xyz(&top),
        start_normal: Xyz::new(0.0, 0.0, 1.0),
        plane_normal: Xyz::new(1.0, 0.0, 0.0),
        direction: xyz(&(top + Vector3::y() * 10.0)),
        spacing: InPlaneSpacing::Step(1.0),
        end: xyz(&(top + Vector3::z())),
        stop_diameter: 3.0,
        passes: 1,
        end_normal: Xyz::new(0.0, 0.0, 1.0),
    };
    (scan, top)
}

async fn above(client: &Client, top: &Point3<f64>) {
    client
        .go_to(Xyz::new(200.0, top.y, top.z + 20.0))
        .await
        .expect("the move above the blade");
}

#[tokio::test(flavor = "current_thread")]
async fn a_closed_profile_scan_of_blade_a_lies_on_the_simulated_section_within_the_noise() {
    let sim = Sim::start("propeller.toml");
    let client = ready(&sim).await;
    let (plan, top) = blade_a_section_scan();
    above(&client, &top).await;
    let scanning = client.scanning().expect("the simulator scans");
    let stream = scanning.scan_in_plane(plan).await.expect("the scan starts");
    let points: Vec<ScanPoint> = stream.map(|p| p.expect("a point")).collect().await;
    assert!(points.len() > 300, "{} points", points.len());
    let truth = propeller();
    let frame = truth.section_frame(0, 200.0);
    let section = SampledCurve::new(truth.section_curve(0, 200.0));
    for point in &points {
        let centre = Point3::new(point.centre.x, point.centre.y, point.centre.z);
        let normal = Vector3::new(point.normal.x, point.normal.y, point.normal.z);
        // A CMM reports the ball centre: the surface is one radius back along the normal.
        let surface = centre - normal * BALL_RADIUS_MM;
        let local = frame.local(&surface);
        assert!(
            local.z.abs() < WITHIN_NOISE_MM,
            "off the plane x = 200 mm: {surface}"
        );
        let off = section
            .nearest(&Point2::new(local.x, local.y))
            .signed_distance;
        assert!(
            off.abs() < WITHIN_NOISE_MM,
            "{off} mm off blade A's section at {surface}"
        );
    }
    client.end_session().await.expect("the end of the session");
}

#[tokio::test(flavor = "current_thread")]
async fn an_abort_mid_scan_ends_the_stream_and_locks_out_motion_until_cleared() {
    let sim = Sim::start("propeller.toml");
    let client = ready(&sim).await;
    let (plan, top) = blade_a_section_scan();
    above(&client, &top).await;
    let mut stream = client
        .scanning()
        .expect("scans")
        .scan_in_plane(plan)
        .await
        .expect("the scan starts");
    let mut received = 0;
    while received < 20 {
        stream.next().await.expect("more points").expect("a point");
        received += 1;
    }
    client.abort().await.expect("AbortE");
    let mut ended_with_error = false;
    while let Some(item) = stream.next().await {
        if item.is_err() {
            ended_with_error = true;
        }
    }
    assert!(
        ended_with_error,
        "an aborted scan does not end as if complete"
    );
    let refused = client
        .go_to(Xyz::new(200.0, top.y, top.z + 30.0))
        .await
        .expect_err("motion is locked out");
    assert!(
        matches!(refused.kind(), ErrorKind::LockedOut { .. }),
        "{refused}"
    );
    client.clear_all_errors().await.expect("ClearAllErrors");
    // Where the probe stopped depends on how many points the simulator scanned before the abort reached it (more
    // on a loaded machine), and the ball stands on the section there. A straight move above the blade can cross
    // the section from its underside (the simulator rightly refuses it as a collision): the move that is safe
    // from any stop is away from the section, along its normal at the nearest point.
    let stopped = client.position().await.expect("the probe's position");
    let truth = propeller();
    let frame = truth.section_frame(0, 200.0);
    let at = frame.local(&Point3::new(stopped.x, stopped.y, stopped.z));
    let nearest = SampledCurve::new(truth.section_curve(0, 200.0))
        .nearest(&Point2::new(at.x, at.y))
        .on_curve
        .point;
    let away = Vector3::new(at.x - nearest.x, at.y - nearest.y, 0.0).normalize() * 2.0;
    let clear = frame.world(at.x + away.x, at.y + away.y, at.z);
    client
        .go_to(xyz(&clear))
        .await
        .expect("motion after the clear");
}

#[tokio::test(flavor = "current_thread")]
async fn an_emergency_stop_locks_out_motion_until_clear_all_errors() {
    let mut sim = Sim::start("propeller.toml");
    let client = ready(&sim).await;
    let mut events = client.events();
    assert_eq!(sim.control("fault cmm1 estop"), "ok fault cmm1 estop");
    let event = tokio::time::timeout(Duration::from_secs(5), events.recv())
        .await
        .expect("an event")
        .expect("open");
    let Event::Unsolicited(error) = event else {
        panic!("expected the E-stop, got {event:?}")
    };
    assert_eq!((error.severity(), error.code()), (3, 500), "{error}");
    let refused = client
        .go_to(Xyz::new(0.0, 0.0, 350.0))
        .await
        .expect_err("no motion after an E-stop");
    assert!(
        matches!(refused.kind(), ErrorKind::LockedOut { .. }),
        "{refused}"
    );
    assert!(
        refused.to_string().contains("cmm1"),
        "the error names the machine: {refused}"
    );
    client.clear_all_errors().await.expect("ClearAllErrors");
    client
        .go_to(Xyz::new(0.0, 0.0, 350.0))
        .await
        .expect("motion after the clear");
}

#[tokio::test(flavor = "current_thread")]
async fn a_dead_line_is_a_transport_error_and_a_new_link_works_after_it() {
    let mut sim = Sim::start("propeller.toml");
    let client = ready(&sim).await;
    assert!(sim.control("fault cmm1 disconnect 500").starts_with("ok"));
    let failed = client
        .is_homed()
        .await
        .expect_err("nothing comes back over a dead line");
    assert!(
        failed.transport_error().is_some(),
        "a transport fault, not a machine error: {failed}"
    );
    assert!(failed.device_error().is_none());
    drop(client);
    tokio::time::sleep(Duration::from_millis(700)).await;
    let again = sim.client("cmm1", quick());
    again
        .start_session()
        .await
        .expect("a new session after the line came back");
    // The machine itself stayed homed: only the link was lost.
    assert!(again.is_homed().await.expect("IsHomed"));
    again.change_tool("Probe1").await.expect("the tool again");
    again
        .go_to(Xyz::new(0.0, 0.0, 350.0))
        .await
        .expect("motion on the new link");
}

#[tokio::test(flavor = "current_thread")]
async fn each_fault_reports_its_own_error() {
    let mut sim = Sim::start("propeller.toml");
    let client = ready(&sim).await;
    let mut events = client.events();

    // Garbage on the line while nothing is in flight: an event, and the link goes on.
    assert!(sim.control("fault cmm1 garbage").starts_with("ok"));
    let event = tokio::time::timeout(Duration::from_secs(5), events.recv())
        .await
        .expect("an event")
        .expect("open");
    assert!(
        matches!(event, Event::BadLine(_) | Event::Unsolicited(_)),
        "garbage shows as {event:?}"
    );
    client
        .clear_all_errors()
        .await
        .expect("the link goes on after garbage");

    // A dropped line: the command's replies never come, and the client times out on it.
    assert!(sim.control("fault cmm1 drop-lines 3").starts_with("ok"));
    let lost = client
        .is_homed()
        .await
        .expect_err("the replies were dropped");
    assert!(
        matches!(lost.transport_error(), Some(TransportError::Timeout { .. })),
        "{lost}"
    );
    client
        .clear_all_errors()
        .await
        .expect("the link goes on after a timeout");

    // A late reply beyond the acknowledge timeout is a timeout too (the delay is wall-clock time, past the
    // 5 s acknowledge timeout of `quick`).
    assert!(sim.control("fault cmm1 delay 6000").starts_with("ok"));
    let late = client
        .is_homed()
        .await
        .expect_err("the reply came too late");
    assert!(
        matches!(late.transport_error(), Some(TransportError::Timeout { .. })),
        "{late}"
    );
    tokio::time::sleep(Duration::from_millis(1500)).await;
    client
        .clear_all_errors()
        .await
        .expect("the link goes on after a late reply");

    // A collision (2504) is a machine error, and it locks out motion.
    assert!(sim.control("fault cmm1 collision").starts_with("ok"));
    let hit = client
        .go_to(Xyz::new(0.0, 0.0, 300.0))
        .await
        .expect_err("the move collides");
    assert_eq!(hit.device_error().map(|e| e.code()), Some(2504), "{hit}");
    assert!(matches!(
        client
            .go_to(Xyz::new(0.0, 0.0, 350.0))
            .await
            .expect_err("locked out")
            .kind(),
        ErrorKind::LockedOut { .. }
    ));
    client.clear_all_errors().await.expect("ClearAllErrors");

    // No touch (1003) on a point measurement.
    let (_, top) = blade_a_section_scan();
    above(&client, &top).await;
    assert!(sim.control("fault cmm1 no-touch").starts_with("ok"));
    let missed = client
        .pt_meas(Xyz::new(200.0, top.y, top.z), Xyz::new(0.0, 0.0, 1.0))
        .await
        .expect_err("no touch");
    assert_eq!(
        missed.device_error().map(|e| e.code()),
        Some(1003),
        "{missed}"
    );
    client.clear_all_errors().await.expect("ClearAllErrors");

    // Surface not found (1006) on a scan.
    above(&client, &top).await;
    assert!(sim
        .control("fault cmm1 surface-not-found")
        .starts_with("ok"));
    let (plan, _) = blade_a_section_scan();
    let outcome = match client.scanning().expect("scans").scan_in_plane(plan).await {
        Err(error) => error,
        Ok(stream) => {
            let items: Vec<_> = stream.collect().await;
            items
                .into_iter()
                .find_map(Result::err)
                .expect("the scan fails")
        }
    };
    assert_eq!(
        outcome.device_error().map(|e| e.code()),
        Some(1006),
        "{outcome}"
    );
}
