//! The client's protocol logic against a scripted server over an in-memory pipe, under tokio's paused
//! clock so that timeouts take no real time. Reply shapes follow NIST's server logs
//! (ippdme-nist-1.4/ClientServerLogs).

mod peer;

use std::time::Duration;

use futures_util::StreamExt;
use peer::{pair, Peer};
use tokio::io::DuplexStream;
use tokio::task::JoinHandle;
use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::machine::{
    CurveScan, Density, Error, ErrorKind, Event, InPlaneScan, InPlaneSpacing, Machine,
    MoveReportRate, Nominal, TransportError, Xyz,
};
use zeroset_drivers::wire::EventTag;

const MACHINE: &str = "cmm-a";

fn config() -> ClientConfig {
    ClientConfig {
        ack_timeout: Duration::from_secs(2),
        reply_timeout: Duration::from_secs(30),
    }
}

fn start() -> (Client, Peer<DuplexStream>) {
    pair(MACHINE, config())
}

/// Runs `operation` on a clone of `client` in its own task, as a second caller would.
fn spawn<T, F>(client: &Client, operation: impl FnOnce(Client) -> F) -> JoinHandle<T>
where
    F: std::future::Future<Output = T> + Send + 'static,
    T: Send + 'static,
{
    tokio::spawn(operation(client.clone()))
}

fn goto(client: &Client, x: f64) -> JoinHandle<Result<(), Error>> {
    spawn(client, move |client| async move {
        client.go_to(Xyz::new(x, 0.0, 0.0)).await
    })
}

fn locked_out(result: Result<(), Error>) -> bool {
    matches!(
        result.map_err(|error| error.kind().clone()),
        Err(ErrorKind::LockedOut { .. })
    )
}

fn in_plane_plan() -> InPlaneScan {
    InPlaneScan {
        start: Xyz::new(0.0, 0.0, 0.0),
        start_normal: Xyz::new(0.0, 0.0, 1.0),
        plane_normal: Xyz::new(1.0, 0.0, 0.0),
        direction: Xyz::new(0.0, 1.0, 0.0),
        spacing: InPlaneSpacing::Step(0.5),
        end: Xyz::new(0.0, 9.0, 0.0),
        stop_diameter: 1.4,
        passes: 1,
        end_normal: Xyz::new(0.0, 0.0, 1.0),
    }
}

#[tokio::test(start_paused = true)]
async fn runs_transactions_with_ack_data_and_complete() {
    let (client, mut peer) = start();
    let session = spawn(
        &client,
        |client| async move { client.start_session().await },
    );
    peer.expect("00001 StartSession()").await;
    peer.ack_and_complete("00001").await;
    session.await.unwrap().unwrap();

    let homed = spawn(&client, |client| async move { client.is_homed().await });
    peer.expect("00002 IsHomed()").await;
    peer.reply(&["00002 &", "00002 # IsHomed(1)", "00002 %"])
        .await;
    assert!(homed.await.unwrap().unwrap());

    let radius = spawn(&client, |client| async move { client.tool_radius().await });
    peer.expect("00003 GetProp(Tool.AvrRadius())").await;
    peer.reply(&["00003 &", "00003 # Tool.AvrRadius(1.5)", "00003 %"])
        .await;
    assert_eq!(radius.await.unwrap().unwrap(), 1.5);

    let tool = spawn(&client, |client| async move {
        client.change_tool("Probe1").await
    });
    peer.expect("00004 ChangeTool(\"Probe1\")").await;
    peer.ack_and_complete("00004").await;
    tool.await.unwrap().unwrap();

    let position = spawn(&client, |client| async move { client.position().await });
    peer.expect("00005 Get(X(), Y(), Z())").await;
    peer.reply(&["00005 &", "00005 # X(10.5), Y(-2), Z(300.25)", "00005 %"])
        .await;
    assert_eq!(
        position.await.unwrap().unwrap(),
        Xyz::new(10.5, -2.0, 300.25)
    );

    // PtMeas_Client.log: the report format first, then the measurement, answered IJK first.
    let point = spawn(&client, |client| async move {
        client
            .pt_meas(Xyz::new(1.33, -26.0, 30.998), Xyz::new(0.0, 0.0, 1.0))
            .await
    });
    peer.expect("00006 OnPtMeasReport(X(), Y(), Z(), IJK())")
        .await;
    peer.ack_and_complete("00006").await;
    peer.expect("00007 PtMeas(X(1.33), Y(-26), Z(30.998), IJK(0, 0, 1))")
        .await;
    peer.reply(&[
        "00007 &",
        "00007 # IJK(0.00000,0.00000,1.00000), X(1.33000), Y(-26.00000), Z(33.99800)",
        "00007 %",
    ])
    .await;
    let point = point.await.unwrap().unwrap();
    assert_eq!(point.centre, Xyz::new(1.33, -26.0, 33.998));
    assert_eq!(point.normal, Xyz::new(0.0, 0.0, 1.0));
}

#[tokio::test(start_paused = true)]
async fn writes_the_next_command_only_after_the_previous_ack() {
    let (client, mut peer) = start();
    let first = goto(&client, 1.0);
    peer.expect("00001 GoTo(X(1), Y(0), Z(0))").await;
    let second = goto(&client, 2.0);
    peer.expect_silence().await;
    // The & is the flow control: the second goes before the first completes (spec 6.2.3).
    peer.reply(&["00001 &"]).await;
    peer.expect("00002 GoTo(X(2), Y(0), Z(0))").await;
    peer.reply(&["00001 %", "00002 &", "00002 %"]).await;
    first.await.unwrap().unwrap();
    second.await.unwrap().unwrap();
}

#[tokio::test(start_paused = true)]
async fn fast_queue_commands_jump_the_queue() {
    let (client, mut peer) = start();
    let first = goto(&client, 1.0);
    peer.expect("00001 GoTo(X(1), Y(0), Z(0))").await;
    let queued = goto(&client, 2.0);
    peer.expect_silence().await;
    let status = spawn(&client, |client| async move { client.in_error().await });
    // Written while GoTo(X(1)) waits for its & and GoTo(X(2)) waits behind it.
    peer.expect("E0001 GetErrStatusE()").await;
    peer.reply(&["E0001 &", "E0001 # ErrStatus(0)", "E0001 %"])
        .await;
    assert!(!status.await.unwrap().unwrap());
    peer.expect_silence().await;
    peer.reply(&["00001 &"]).await;
    peer.expect("00002 GoTo(X(2), Y(0), Z(0))").await;
    peer.reply(&["00001 %", "00002 &", "00002 %"]).await;
    first.await.unwrap().unwrap();
    queued.await.unwrap().unwrap();
}

#[tokio::test(start_paused = true)]
async fn an_emergency_stop_locks_out_motion_until_clear_all_errors() {
    let (client, mut peer) = start();
    let mut events = client.events();
    peer.reply(&["E0000 ! Error(3, 0500, \"HealthCheck\", \"Emergency stop\")"])
        .await;
    let Event::Unsolicited(stop) = events.recv().await.unwrap() else {
        panic!("expected the unsolicited error event")
    };
    assert_eq!((stop.code(), stop.severity()), (500, 3));

    let refused = client.go_to(Xyz::new(1.0, 0.0, 0.0)).await.unwrap_err();
    assert_eq!(refused.machine(), MACHINE);
    assert_eq!(refused.command(), "GoTo(X(1), Y(0), Z(0))");
    assert!(
        refused.to_string().contains("emergency stop") || refused.to_string().contains("0500"),
        "{refused}"
    );
    assert!(locked_out(client.home().await));
    peer.expect_silence().await;

    // Queries still go out: the spec lets the client ask while in error.
    let homed = spawn(&client, |client| async move { client.is_homed().await });
    peer.expect("00001 IsHomed()").await;
    peer.reply(&["00001 &", "00001 # IsHomed(1)", "00001 %"])
        .await;
    assert!(homed.await.unwrap().unwrap());

    let clear = spawn(
        &client,
        |client| async move { client.clear_all_errors().await },
    );
    peer.expect("00002 ClearAllErrors()").await;
    peer.ack_and_complete("00002").await;
    clear.await.unwrap().unwrap();

    let moved = goto(&client, 1.0);
    peer.expect("00003 GoTo(X(1), Y(0), Z(0))").await;
    peer.ack_and_complete("00003").await;
    moved.await.unwrap().unwrap();
}

#[tokio::test(start_paused = true)]
async fn a_clear_all_errors_does_not_lift_a_stop_that_came_after_it() {
    let (client, mut peer) = start();
    peer.reply(&["E0000 ! Error(3, 0500, \"HealthCheck\", \"Emergency stop\")"])
        .await;
    let clear = spawn(
        &client,
        |client| async move { client.clear_all_errors().await },
    );
    peer.expect("00001 ClearAllErrors()").await;
    peer.reply(&[
        "00001 &",
        "E0000 ! Error(3, 0500, \"HealthCheck\", \"Emergency stop\")",
        "00001 %",
    ])
    .await;
    clear.await.unwrap().unwrap();
    assert!(locked_out(client.go_to(Xyz::new(1.0, 0.0, 0.0)).await));
    peer.expect_silence().await;
}

#[tokio::test(start_paused = true)]
async fn a_machine_error_is_a_device_error_and_locks_out_motion() {
    let (client, mut peer) = start();
    let collision = goto(&client, 500.0);
    peer.expect("00001 GoTo(X(500), Y(0), Z(0))").await;
    peer.reply(&[
        "00001 &",
        "00001 ! Error(3, 2504, \"GoTo\", \"Collision\")",
        "00001 %",
    ])
    .await;
    let error = collision.await.unwrap().unwrap_err();
    let device = error.device_error().expect("a device error");
    assert_eq!((device.code(), device.severity()), (2504, 3));
    assert!(error.transport_error().is_none());
    let text = error.to_string();
    assert!(
        text.contains(MACHINE) && text.contains("GoTo(X(500)") && text.contains("Collision"),
        "{text}"
    );

    assert!(locked_out(client.go_to(Xyz::new(0.0, 0.0, 0.0)).await));
    peer.expect_silence().await;
}

#[tokio::test(start_paused = true)]
async fn a_warning_is_an_event_and_the_command_succeeds() {
    let (client, mut peer) = start();
    let mut events = client.events();
    let speeds = zeroset_drivers::machine::Speeds {
        travel: 900.0,
        probing: 5.0,
        scanning: 10.0,
    };
    let set = spawn(&client, move |client| async move {
        client.set_speeds(speeds).await
    });
    peer.expect(
        "00001 SetProp(Tool.GoToPar.Speed(900), Tool.PtMeasPar.Speed(5), Tool.ScanPar.Speed(10))",
    )
    .await;
    peer.reply(&[
        "00001 &",
        "00001 ! Error(1, 0504, \"SetProp\", \"Argument out of range\")",
        "00001 %",
    ])
    .await;
    set.await.unwrap().unwrap();
    let Event::Warning { error, .. } = events.recv().await.unwrap() else {
        panic!("expected a warning event")
    };
    assert_eq!(error.code(), 504);
    let moved = goto(&client, 1.0);
    peer.expect("00002 GoTo(X(1), Y(0), Z(0))").await;
    peer.ack_and_complete("00002").await;
    moved.await.unwrap().unwrap();
}

#[tokio::test(start_paused = true)]
async fn abort_goes_at_once_holds_the_queue_and_locks_out_motion() {
    let (client, mut peer) = start();
    let moving = goto(&client, 20.0);
    peer.expect("00001 GoTo(X(20), Y(0), Z(0))").await;
    peer.reply(&["00001 &"]).await;
    let abort = spawn(&client, |client| async move { client.abort().await });
    peer.expect("E0001 AbortE()").await;
    // Spec 6.3.1.5: nothing else may be written until the AbortE completes.
    let homed = spawn(&client, |client| async move { client.is_homed().await });
    peer.expect_silence().await;
    // AbortE_TestWhileMoving_Client.log.
    peer.reply(&[
        "E0001 &",
        "00001 ! Error(2, 0006, \"00001 GoTo(X(20), Y(0), Z(0))\", \"Transaction aborted (Use ClearAllErrors to Continue)\")",
        "00001 %",
        "E0001 %",
    ])
    .await;
    abort.await.unwrap().unwrap();
    let aborted = moving.await.unwrap().unwrap_err();
    assert_eq!(aborted.device_error().map(|error| error.code()), Some(6));
    peer.expect("00002 IsHomed()").await;
    peer.reply(&["00002 &", "00002 # IsHomed(1)", "00002 %"])
        .await;
    assert!(homed.await.unwrap().unwrap());

    assert!(locked_out(client.go_to(Xyz::new(0.0, 0.0, 0.0)).await));
    let clear = spawn(
        &client,
        |client| async move { client.clear_all_errors().await },
    );
    peer.expect("00003 ClearAllErrors()").await;
    peer.ack_and_complete("00003").await;
    clear.await.unwrap().unwrap();
    let moved = goto(&client, 0.0);
    peer.expect("00004 GoTo(X(0), Y(0), Z(0))").await;
    peer.ack_and_complete("00004").await;
    moved.await.unwrap().unwrap();
}

fn timeout_of(result: Result<(), Error>) -> &'static str {
    match result.map_err(|error| error.kind().clone()) {
        Err(ErrorKind::Transport(TransportError::Timeout { awaited, .. })) => awaited,
        other => panic!("expected a timeout, got {other:?}"),
    }
}

#[tokio::test(start_paused = true)]
async fn a_missing_ack_times_out_and_frees_the_queue() {
    let (client, mut peer) = start();
    let started = tokio::time::Instant::now();
    let lost = goto(&client, 1.0);
    peer.expect("00001 GoTo(X(1), Y(0), Z(0))").await;
    let next = goto(&client, 2.0);
    assert_eq!(timeout_of(lost.await.unwrap()), "acknowledgement (&)");
    assert_eq!(started.elapsed(), config().ack_timeout);
    peer.expect("00002 GoTo(X(2), Y(0), Z(0))").await;
    // The late lines of the timed-out command are dropped, not taken for the next one's.
    let mut events = client.events();
    peer.reply(&["00001 &", "00001 %", "00002 &", "00002 %"])
        .await;
    next.await.unwrap().unwrap();
    assert!(events.try_recv().is_err(), "late lines are not strays");
}

#[tokio::test(start_paused = true)]
async fn the_reply_timeout_runs_from_the_last_line() {
    let (client, mut peer) = start();
    let slow = goto(&client, 1.0);
    peer.expect("00001 GoTo(X(1), Y(0), Z(0))").await;
    peer.reply(&["00001 &"]).await;
    // Longer than the ack timeout, shorter than the reply timeout: a long move, not a fault.
    tokio::time::sleep(Duration::from_secs(20)).await;
    peer.reply(&["00001 %"]).await;
    slow.await.unwrap().unwrap();

    let stuck = goto(&client, 2.0);
    peer.expect("00002 GoTo(X(2), Y(0), Z(0))").await;
    peer.reply(&["00002 &"]).await;
    let started = tokio::time::Instant::now();
    assert_eq!(timeout_of(stuck.await.unwrap()), "next reply");
    assert_eq!(started.elapsed(), config().reply_timeout);
}

#[tokio::test(start_paused = true)]
async fn a_disconnect_is_a_transport_error_not_a_device_error() {
    let (client, mut peer) = start();
    let mut events = client.events();
    let cut = goto(&client, 1.0);
    peer.expect("00001 GoTo(X(1), Y(0), Z(0))").await;
    peer.reply(&["00001 &"]).await;
    drop(peer);
    let error = cut.await.unwrap().unwrap_err();
    assert!(error.device_error().is_none());
    assert!(matches!(
        error.transport_error(),
        Some(TransportError::Disconnected)
    ));
    assert!(matches!(
        events.recv().await.unwrap(),
        Event::Disconnected(TransportError::Disconnected)
    ));
    let later = client.is_homed().await.unwrap_err();
    assert!(matches!(
        later.transport_error(),
        Some(TransportError::Disconnected)
    ));
}

#[tokio::test(start_paused = true)]
async fn a_garbled_line_fails_the_transaction_in_progress() {
    let (client, mut peer) = start();
    let mut events = client.events();
    let homed = spawn(&client, |client| async move { client.is_homed().await });
    peer.expect("00001 IsHomed()").await;
    peer.reply(&["00001 &"]).await;
    peer.send_raw(b"00001 # IsH\xFFmed(1)\r\n").await;
    let error = homed.await.unwrap().unwrap_err();
    assert!(
        matches!(error.transport_error(), Some(TransportError::BadLine(_))),
        "{error}"
    );
    assert!(matches!(events.recv().await.unwrap(), Event::BadLine(_)));
    // The link carries on: the codec resynchronises at the next CR LF.
    peer.reply(&["00001 %"]).await;
    let again = spawn(&client, |client| async move { client.is_homed().await });
    peer.expect("00002 IsHomed()").await;
    peer.reply(&["00002 &", "00002 # IsHomed(0)", "00002 %"])
        .await;
    assert!(!again.await.unwrap().unwrap());
}

#[tokio::test(start_paused = true)]
async fn scan_points_stream_before_the_scan_completes() {
    let (client, mut peer) = start();
    let scanning = client.scanning().expect("the I++ client scans");
    let plan = CurveScan {
        closed: false,
        nominals: vec![
            Nominal {
                point: Xyz::new(10.0, 0.0, 0.0),
                normal: Xyz::new(0.0, 0.0, 1.0),
            },
            Nominal {
                point: Xyz::new(22.0, 0.0, 0.0),
                normal: Xyz::new(0.0, 0.0, 1.0),
            },
        ],
        max_deviation: 0.01,
        min_radius: 0.5,
        density: Density::AtNominals,
    };
    let started = tokio::spawn(async move { scanning.scan_on_curve(plan).await });
    peer.expect("00001 OnScanReport(X(), Y(), Z(), IJK(), Q())")
        .await;
    peer.ack_and_complete("00001").await;
    peer.expect("00002 ScanOnCurveHint(0.01, 0.5)").await;
    peer.ack_and_complete("00002").await;
    peer.expect("00003 ScanOnCurveDensity(AtNominals(1))").await;
    peer.ack_and_complete("00003").await;
    peer.expect(
        "00004 ScanOnCurve(Closed(0), Format(X(), Y(), Z(), IJK(), tag), \
         Data(10, 0, 0, 0, 0, 1, 1, 22, 0, 0, 0, 0, 1, 1))",
    )
    .await;
    peer.reply(&["00004 &"]).await;
    let mut points = started.await.unwrap().unwrap();

    // Spec 11.2.8's reply: one point, then the scan goes on.
    peer.reply(&["00004 # 10.0,0.0,1.5,0.001,0.002,0.999,0.01"])
        .await;
    let first = points.next().await.unwrap().unwrap();
    assert_eq!(first.centre, Xyz::new(10.0, 0.0, 1.5));
    assert_eq!(first.normal, Xyz::new(0.001, 0.002, 0.999));
    assert_eq!(first.quality, 0.01);

    peer.reply(&["00004 # 22.0,0.0,1.501,0,0,1,0", "00004 %"])
        .await;
    let second = points.next().await.unwrap().unwrap();
    assert_eq!(second.centre, Xyz::new(22.0, 0.0, 1.501));
    assert!(points.next().await.is_none());
}

#[tokio::test(start_paused = true)]
async fn a_disconnect_mid_scan_ends_the_stream_with_a_transport_error() {
    let (client, mut peer) = start();
    let scanning = client.scanning().unwrap();
    let started = tokio::spawn(async move { scanning.scan_in_plane(in_plane_plan()).await });
    peer.expect("00001 OnScanReport(X(), Y(), Z(), IJK(), Q())")
        .await;
    peer.ack_and_complete("00001").await;
    peer.expect(
        "00002 ScanInPlaneEndIsSphere(0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 1, 0, 0.5, 0, 9, 0, 1.4, 1, 0, 0, 1)",
    )
    .await;
    // ScanInPlaneEndIsSphere_Client.log's shape, blocked two points a line, in our 7-value format.
    peer.reply(&[
        "00002 &",
        "00002 # 0.00000,0.49111,0.00000,0,0,1,3.00000,0.00000,0.99222,0.00000,0,0,1,3.00000",
    ])
    .await;
    let mut points = started.await.unwrap().unwrap();
    drop(peer);
    let got: Vec<_> = points.by_ref().collect().await;
    assert_eq!(got.len(), 3, "{got:?}");
    assert_eq!(got[0].as_ref().unwrap().centre, Xyz::new(0.0, 0.49111, 0.0));
    assert_eq!(got[1].as_ref().unwrap().quality, 3.0);
    let error = got[2].as_ref().unwrap_err();
    assert!(matches!(
        error.transport_error(),
        Some(TransportError::Disconnected)
    ));
    assert!(error.command().starts_with("ScanInPlaneEndIsSphere("));
}

#[tokio::test(start_paused = true)]
async fn a_scan_refused_before_its_ack_fails_to_start() {
    let (client, mut peer) = start();
    peer.reply(&["E0000 ! Error(3, 0500, \"HealthCheck\", \"Emergency stop\")"])
        .await;
    let scanning = client.scanning().unwrap();
    let started = tokio::spawn(async move { scanning.scan_in_plane(in_plane_plan()).await });
    // The report format is not motion, so it goes; the scan itself is refused.
    peer.expect("00001 OnScanReport(X(), Y(), Z(), IJK(), Q())")
        .await;
    peer.ack_and_complete("00001").await;
    let refused = started.await.unwrap().err().expect("refused");
    assert!(matches!(refused.kind(), ErrorKind::LockedOut { .. }));
    peer.expect_silence().await;
}

#[tokio::test(start_paused = true)]
async fn move_reports_stream_until_the_daemon_is_stopped() {
    let (client, mut peer) = start();
    let reporting = client
        .move_reporting()
        .expect("the I++ client reports moves");
    let rate = MoveReportRate {
        interval: Duration::from_millis(500),
        distance: 1.0,
    };
    let started = tokio::spawn({
        let reporting = reporting.clone();
        async move { reporting.start_move_reports(rate).await }
    });
    peer.expect("E0001 OnMoveReportE(Time(0.5), Dis(1), X(), Y(), Z())")
        .await;
    // OnMoveReportE_Client.log: & and % first, then the daemon's data under its tag.
    peer.ack_and_complete("E0001").await;
    let mut reports = started.await.unwrap().unwrap();
    assert_eq!(reports.daemon(), EventTag::new(1).unwrap());
    peer.reply(&["E0001 # X(0.35011), Y(0.70022), Z(1.05034)"])
        .await;
    let position = reports.next().await.unwrap().unwrap();
    assert_eq!(position, Xyz::new(0.35011, 0.70022, 1.05034));

    let daemon = reports.daemon();
    let stop = tokio::spawn(async move { reporting.stop_move_reports(daemon).await });
    peer.expect("00001 StopDaemon(E0001)").await;
    peer.reply(&["00001 &", "E0001 # X(50), Y(433), Z(530)", "00001 %"])
        .await;
    stop.await.unwrap().unwrap();
    assert_eq!(
        reports.next().await.unwrap().unwrap(),
        Xyz::new(50.0, 433.0, 530.0)
    );
    assert!(reports.next().await.is_none());
}

#[tokio::test(start_paused = true)]
async fn unwritable_arguments_are_refused_before_the_wire() {
    let (client, mut peer) = start();
    let error = client
        .go_to(Xyz::new(f64::NAN, 0.0, 0.0))
        .await
        .unwrap_err();
    assert!(matches!(error.kind(), ErrorKind::InvalidArgument(_)));
    peer.expect_silence().await;
}
