//! The worker's motion logic against mocked machines: it sends a scan's planned motion exactly, refuses to move
//! when the probe is not where the plan has it, gets clear of the part only by a checked way out, and reopens a
//! link or a session it lost.

use std::sync::{Arc, Mutex};

use futures::stream;
use nalgebra::Point3;
use tokio::sync::{broadcast, mpsc};
use zeroset_drivers::machine::{
    CurveScan, Density, InPlaneScan, InPlaneSpacing, MockMachine, MockMoveReporting, MockScanning,
    MoveReporting, MoveReports, Nominal, ScanPoint, ScanStream, Scanning, Xyz,
};

use super::*;
use crate::config::{ProbeSettings, Safety};
use crate::plan::ProfileKey;
use crate::station::clearance::{swept_moves, MoveKind};
use crate::station::escape::KnownPath;
use zeroset_drivers::machine::TransportError;

const CLEARANCE_MM: f64 = 150.0;
const MARGIN_MM: f64 = 2.0;

fn probe() -> ProbeSettings {
    ProbeSettings {
        tool: "Probe1".into(),
        travel_mm_s: 100.0,
        probing_mm_s: 5.0,
        scanning_mm_s: 20.0,
        shank_radius_mm: 0.6,
        shank_length_mm: 30.0,
    }
}

fn safety() -> Safety {
    Safety {
        clearance_z_mm: CLEARANCE_MM,
        max_ball_radius_mm: 1.5,
        move_margin_mm: 0.5,
    }
}

/// A circular profile of radius 20 mm in the plane x = 100, its top first (the entry), 72 points.
fn circle() -> KnownPath {
    crate::station::escape::tests::circle(72)
}

fn curve_scan(path: &KnownPath) -> CurveScan {
    CurveScan {
        closed: true,
        nominals: path
            .surface
            .iter()
            .zip(&path.normals)
            .map(|(p, n)| Nominal {
                point: Xyz::new(p.x, p.y, p.z),
                normal: Xyz::new(n.x, n.y, n.z),
            })
            .collect(),
        max_deviation: 1.0,
        min_radius: 1.0,
        density: Density::AtNominals,
    }
}

/// A machine that is homed and set up, reports `positions` one after another, and records its moves.
fn machine(positions: Vec<Xyz>, moves: Arc<Mutex<Vec<Xyz>>>, scan: Vec<ScanPoint>) -> MockMachine {
    let mut machine = bare_machine(positions, Some(moves), scan);
    machine.expect_start_session().returning(|| Ok(()));
    machine.expect_clear_all_errors().returning(|| Ok(()));
    machine
}

/// Like [`machine`], without its session's expectations; every move fails with a lost link without `moves`.
fn bare_machine(
    positions: Vec<Xyz>,
    moves: Option<Arc<Mutex<Vec<Xyz>>>>,
    scan: Vec<ScanPoint>,
) -> MockMachine {
    scanning_machine(positions, moves, scan, None, None)
}

/// Like [`bare_machine`], its scans ending with `stopped_by` after their points, its move reports `reporting`.
fn scanning_machine(
    positions: Vec<Xyz>,
    moves: Option<Arc<Mutex<Vec<Xyz>>>>,
    scan: Vec<ScanPoint>,
    stopped_by: Option<MachineError>,
    reporting: Option<Arc<dyn MoveReporting>>,
) -> MockMachine {
    let mut machine = MockMachine::new();
    machine
        .expect_move_reporting()
        .returning(move || reporting.clone());
    machine
        .expect_events()
        .returning(|| broadcast::channel(1).1);
    machine.expect_is_homed().returning(|| Ok(true));
    machine.expect_change_tool().returning(|_| Ok(()));
    machine.expect_set_speeds().returning(|_| Ok(()));
    machine.expect_tool_radius().returning(|| Ok(1.0));
    let positions = Mutex::new(positions.into_iter());
    machine.expect_position().returning(move || {
        Ok(positions
            .lock()
            .unwrap()
            .next()
            .expect("no more positions were expected"))
    });
    machine
        .expect_go_to()
        .returning(move |target| match &moves {
            Some(moves) => {
                moves.lock().unwrap().push(target);
                Ok(())
            }
            None => Err(lost("GoTo")),
        });
    let mut scanning = MockScanning::new();
    let in_plane = scan.clone();
    scanning
        .expect_scan_on_curve()
        .times(0..=1)
        .returning(move |_| {
            Ok(ScanStream::new(stream::iter(
                scan.clone().into_iter().map(Ok),
            )))
        });
    scanning
        .expect_scan_in_plane()
        .times(0..=1)
        .returning(move |_| {
            let ending = stopped_by.clone().map(Err);
            Ok(ScanStream::new(stream::iter(
                in_plane.clone().into_iter().map(Ok).chain(ending),
            )))
        });
    let scanning: Arc<dyn Scanning> = Arc::new(scanning);
    machine
        .expect_scanning()
        .returning(move || Some(scanning.clone()));
    machine
}

fn worker_on(machine: MockMachine) -> (WorkerHandle, mpsc::Receiver<DaemonMsg>) {
    let machine: Link = Arc::new(machine);
    worker_with(Box::new(move || Ok(machine.clone())))
}

fn worker_with(connector: Connector) -> (WorkerHandle, mpsc::Receiver<DaemonMsg>) {
    let (daemon, reports) = mpsc::channel(8);
    let handle = spawn_on("cmm1".into(), connector, probe(), safety(), None, daemon);
    (handle, reports)
}

const KEY: ProfileKey = ProfileKey {
    instance: 1,
    profile: 2,
};

/// The circle's scan as the station plans it: entered over its top, for the largest ball the station accepts.
fn motion() -> ScanMotion {
    let path = circle();
    ScanMotion::plan(
        KEY,
        "instance B, profile r300".into(),
        Scan::Curve(curve_scan(&path)),
        path,
        MARGIN_MM,
        &safety(),
    )
    .expect("a plan")
}

async fn send_scan(worker: &WorkerHandle, motion: ScanMotion, pipeline: mpsc::Sender<PipelineMsg>) {
    send_scan_by(worker, motion, None, pipeline).await;
}

/// Sends a scan order with the taught part model `part`.
async fn send_scan_by(
    worker: &WorkerHandle,
    motion: ScanMotion,
    part: Option<Arc<MeshPart>>,
    pipeline: mpsc::Sender<PipelineMsg>,
) {
    let order = Order::Scan {
        motion: Box::new(motion),
        part,
        pipeline,
    };
    worker.orders.send(order).await.unwrap();
}

fn close(a: &Xyz, b: &Xyz) -> bool {
    (a.x - b.x).abs() < 1e-9 && (a.y - b.y).abs() < 1e-9 && (a.z - b.z).abs() < 1e-9
}

fn xyz_of(p: &Point3<f64>) -> Xyz {
    Xyz::new(p.x, p.y, p.z)
}

/// A whole scan round the circle: the 1 mm ball on it at every nominal, the top first.
fn whole_circle() -> Vec<ScanPoint> {
    let path = circle();
    path.surface
        .iter()
        .zip(&path.normals)
        .map(|(p, n)| ScanPoint {
            centre: Xyz::new(p.x + n.x, p.y + n.y, p.z + n.z),
            normal: Xyz::new(n.x, n.y, n.z),
            quality: 0.0,
        })
        .collect()
}

fn point(z: f64) -> ScanPoint {
    ScanPoint {
        centre: Xyz::new(100.0, 0.0, z),
        normal: Xyz::new(0.0, 0.0, 1.0),
        quality: 0.0,
    }
}

async fn clear(worker: &WorkerHandle, escape: EscapeModel) -> Result<(), WorkerError> {
    let (reply, answer) = tokio::sync::oneshot::channel();
    worker
        .orders
        .send(Order::Clear { escape, reply })
        .await
        .unwrap();
    answer.await.unwrap()
}

async fn scan_result(reports: &mut mpsc::Receiver<DaemonMsg>) -> ScanResult {
    let DaemonMsg::Input(Input::ScanEnded {
        machine,
        key,
        result,
    }) = reports.recv().await.unwrap()
    else {
        panic!("expected the end of the scan");
    };
    assert_eq!((machine.as_str(), key), ("cmm1", KEY));
    result
}

#[tokio::test]
async fn a_scan_sends_exactly_its_planned_motion_which_is_what_the_clearance_check_sweeps() {
    let motion = motion();
    let moves = Arc::new(Mutex::new(Vec::new()));
    // Homed at z = 400 before; at the end of the closed scan back over the top, the 1 mm ball in contact.
    let positions = vec![Xyz::new(0.0, 0.0, 400.0), Xyz::new(100.0, 0.0, 21.0)];
    let scanned = whole_circle();
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), scanned.clone()));
    let (pipeline, mut analysis) = mpsc::channel(128);
    send_scan(&worker, motion.clone(), pipeline).await;
    scan_result(&mut reports).await.expect("scanned");

    let sent = moves.lock().unwrap().clone();
    let planned = planned_moves(&motion);
    assert_eq!(
        sent, planned,
        "the wire's GoTo targets are the plan's, bit for bit"
    );
    // Over the entry (the top at z = 20) by the planned 1.5 mm ball and the margin, at the clearance height first.
    assert!(
        close(&sent[0], &Xyz::new(100.0, 0.0, CLEARANCE_MM)),
        "{sent:?}"
    );
    assert!(close(&sent[1], &Xyz::new(100.0, 0.0, 23.5)), "{sent:?}");
    assert!(
        close(sent.last().unwrap(), &Xyz::new(100.0, 0.0, CLEARANCE_MM)),
        "{sent:?}"
    );
    // The clearance check sweeps the same positions: the descent between the approach's two, the lift-off from
    // the planned end and every leg of the way out between the retract's.
    let swept: Vec<(MoveKind, Xyz, Xyz)> = swept_moves(std::slice::from_ref(&motion))
        .unwrap()
        .into_iter()
        .filter(|m| m.kind != MoveKind::Scan)
        .map(|m| {
            (
                m.kind,
                xyz_of(&m.motion.centre(0.0)),
                xyz_of(&m.motion.centre(1.0)),
            )
        })
        .collect();
    assert_eq!(swept[0], (MoveKind::Descent, sent[0], sent[1]));
    assert_eq!(swept[1], (MoveKind::LiftOff, xyz_of(&motion.end), sent[2]));
    for (leg, (kind, from, to)) in swept[2..].iter().enumerate() {
        assert_eq!(
            (*kind, *from, *to),
            (MoveKind::WayOut, sent[2 + leg], sent[3 + leg])
        );
    }
    assert_eq!(swept.len(), sent.len() - 1);

    let PipelineMsg::Start {
        ball_radius_mm,
        entry,
        ..
    } = analysis.recv().await.unwrap()
    else {
        panic!("the scan starts first");
    };
    assert_eq!(ball_radius_mm, 1.0);
    assert!(
        (entry - Point3::new(100.0, 0.0, 20.0)).norm() < 1e-9,
        "{entry}"
    );
    for expected in &scanned {
        let PipelineMsg::Point { raw, .. } = analysis.recv().await.unwrap() else {
            panic!("every point, in order");
        };
        assert_eq!(
            raw.centre,
            [expected.centre.x, expected.centre.y, expected.centre.z]
        );
    }
    assert!(matches!(
        analysis.recv().await.unwrap(),
        PipelineMsg::End { .. }
    ));
}

#[tokio::test]
async fn below_the_clearance_height_before_a_scan_nothing_moves() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    // After a restart the probe is down at z = 10, below the clearance height.
    let positions = vec![Xyz::new(100.0, -25.0, 10.0)];
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), Vec::new()));
    let (pipeline, _analysis) = mpsc::channel(16);
    send_scan(&worker, motion(), pipeline).await;
    let error = scan_result(&mut reports).await.unwrap_err();
    assert_eq!(error.kind, FaultKind::Refused);
    assert!(
        error.message.contains("cmm1")
            && error
                .message
                .contains("below the clearance height z = 150 mm")
            && error.message.contains("zeroset clear"),
        "{}",
        error.message
    );
    assert!(moves.lock().unwrap().is_empty(), "no move at all");
}

#[tokio::test]
async fn a_scan_that_ends_away_from_its_planned_end_is_not_retracted_by_the_plan() {
    let motion = motion();
    let moves = Arc::new(Mutex::new(Vec::new()));
    // The scan ended under the circle, 42 mm from where the plan has it end.
    let positions = vec![Xyz::new(0.0, 0.0, 400.0), Xyz::new(100.0, 0.0, -21.0)];
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), vec![point(21.0)]));
    let (pipeline, _analysis) = mpsc::channel(16);
    send_scan(&worker, motion.clone(), pipeline).await;
    let error = scan_result(&mut reports).await.unwrap_err();
    assert_eq!(error.kind, FaultKind::Refused, "{}", error.message);
    assert!(
        error.message.contains("from its planned end"),
        "{}",
        error.message
    );
    let sent = moves.lock().unwrap().clone();
    assert_eq!(sent, motion.approach.iter().map(xyz_of).collect::<Vec<_>>());
}

/// A closed box, outward triangles, mm.
fn block(min: [f64; 3], max: [f64; 3]) -> MeshPart {
    let vertices: Vec<Point3<f64>> = (0..8)
        .map(|i| {
            let pick = |axis: usize| {
                if i >> axis & 1 == 1 {
                    max[axis]
                } else {
                    min[axis]
                }
            };
            Point3::new(pick(0), pick(1), pick(2))
        })
        .collect();
    // Faces x-, x+, y-, y+, z-, z+ as quads of the corner indices (bit 0: x, bit 1: y, bit 2: z), outward.
    let quads = [
        [0, 4, 6, 2],
        [1, 3, 7, 5],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 2, 3, 1],
        [4, 5, 7, 6],
    ];
    let triangles = quads
        .iter()
        .flat_map(|[a, b, c, d]| [[*a, *b, *c], [*a, *c, *d]])
        .collect();
    let part = MeshPart::new(vertices, triangles, 0.0).unwrap();
    assert!(part.is_signed(), "the block is closed and outward");
    part
}

/// After a scan that ended within its tolerance of the planned end, the worker sends what was sent before it
/// and the verdict; the planned retract is `motion.retract`.
async fn retract_after_an_end_at(
    end: Xyz,
    part: Option<Arc<MeshPart>>,
) -> (ScanMotion, Vec<Xyz>, WorkerError) {
    let motion = motion();
    assert!((Point3::new(end.x, end.y, end.z) - motion.end).norm() < motion.end_tolerance_mm);
    let moves = Arc::new(Mutex::new(Vec::new()));
    let positions = vec![Xyz::new(0.0, 0.0, 400.0), end];
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), whole_circle()));
    let (pipeline, _analysis) = mpsc::channel(128);
    send_scan_by(&worker, motion.clone(), part, pipeline).await;
    let error = scan_result(&mut reports).await.unwrap_err();
    let sent = moves.lock().unwrap().clone();
    (motion, sent, error)
}

#[tokio::test]
async fn a_lift_off_from_where_the_scan_really_ended_is_checked_against_the_part_model() {
    // A block beside the entry, 2 mm from the planned lift-off (the sweep's), which keeps the 1 mm ball 1 mm off
    // it; the scan really ended 3 mm along x and 3 mm up, 0.5 mm over the block, and from there the straight
    // lift-off to the entry's offset grazes its edge.
    let part = Arc::new(block([102.0, -5.0, 0.0], [110.0, 5.0, 23.0]));
    let (motion, sent, error) =
        retract_after_an_end_at(Xyz::new(103.0, 0.0, 24.5), Some(part)).await;
    assert_eq!(error.kind, FaultKind::Refused, "{}", error.message);
    assert!(
        error.message.contains("the taught part model")
            && error.message.contains("instance B, profile r300")
            && error.message.contains("zeroset clear"),
        "{}",
        error.message
    );
    assert_eq!(
        sent,
        motion.approach.iter().map(xyz_of).collect::<Vec<_>>(),
        "nothing moves after the scan"
    );
}

#[tokio::test]
async fn a_lift_off_through_the_known_surface_is_refused() {
    // The machine reports the ball 3 mm inside the circle's top (4.5 mm from the planned end, within tolerance):
    // the lift-off to the entry's offset would pass through the surface the scan just followed.
    let (motion, sent, error) = retract_after_an_end_at(Xyz::new(100.0, 0.0, 17.0), None).await;
    assert_eq!(error.kind, FaultKind::Refused, "{}", error.message);
    assert!(
        error.message.contains("the known surface"),
        "{}",
        error.message
    );
    assert_eq!(sent, motion.approach.iter().map(xyz_of).collect::<Vec<_>>());
}

/// Every point of every straight move from `position` through `moves` keeps the ball (radius 1) out of the circle
/// (radius 20); returns the least clearance after the first leg.
fn clearance_round_the_circle(position: Xyz, moves: &[Xyz]) -> f64 {
    let mut from = Point3::new(position.x, position.y, position.z);
    let mut least_after_first = f64::INFINITY;
    for (leg, to) in moves.iter().enumerate() {
        let to = Point3::new(to.x, to.y, to.z);
        for k in 0..=200 {
            let p = from + (to - from) * (k as f64 / 200.0);
            let clearance = (p.y.powi(2) + p.z.powi(2)).sqrt() - 20.0 - 1.0;
            assert!(
                clearance > -1e-9,
                "the move {from} -> {to} cuts the part at {p}"
            );
            if leg > 0 {
                least_after_first = least_after_first.min(clearance);
            }
        }
        from = to;
    }
    least_after_first
}

#[tokio::test]
async fn a_cleared_machine_leaves_the_part_along_the_path_of_the_cut_scan() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    // A daemon was killed with the ball under the circle (z = -21); the new daemon knows the cut scan's path.
    let position = Xyz::new(100.0, 0.0, -21.0);
    let (worker, _reports) = worker_on(machine(vec![position], moves.clone(), Vec::new()));
    // It also knows an older cut scan 300 mm away, listed first: the ball leaves by the scan it is on.
    let escape = restarted_escape();
    // What the escape planner gives (and checks) for the same stop is what goes on the wire.
    let planned = plan_escape(
        Point3::new(position.x, position.y, position.z),
        Some((&circle(), MARGIN_MM)),
        1.0,
        &safety(),
        &escape,
    )
    .unwrap();
    clear(&worker, escape).await.expect("cleared");
    let moves = moves.lock().unwrap();
    assert_eq!(*moves, planned.iter().map(xyz_of).collect::<Vec<_>>());
    assert!(
        close(moves.last().unwrap(), &Xyz::new(100.0, 0.0, CLEARANCE_MM)),
        "{moves:?}"
    );
    // Round the circle, never through it, the margin kept once off the surface, less the sag of the chords
    // between waypoints 10 degrees apart on the offset circle (23 mm (1 - cos 5 deg) = 0.09 mm).
    let least = clearance_round_the_circle(position, &moves);
    assert!(least >= MARGIN_MM - 0.09, "{least} mm");
    assert!(moves.len() > 10, "{} moves", moves.len());
}

#[tokio::test]
async fn a_probe_near_the_part_with_no_known_way_out_is_not_moved_by_a_clear() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    let (worker, _reports) = worker_on(machine(
        vec![Xyz::new(100.0, -25.0, 10.0)],
        moves.clone(),
        Vec::new(),
    ));
    let error = clear(&worker, EscapeModel::default()).await.unwrap_err();
    assert_eq!(error.kind, FaultKind::Refused);
    assert!(
        error.message.contains("jog the probe above z = 150 mm"),
        "{}",
        error.message
    );
    assert!(moves.lock().unwrap().is_empty());
}

fn lost(command: &str) -> MachineError {
    MachineError::new(
        "cmm1".into(),
        command.into(),
        ErrorKind::Transport(TransportError::Disconnected),
    )
}

/// I++ 0008 for `command`: what a controller answers on a session it does not (or already) hold.
fn protocol_error(command: &str) -> MachineError {
    device_error(command, 3, PROTOCOL_ERROR, "Protocol error")
}

/// The device error `code` (`text`, of `severity`) on `command`.
fn device_error(command: &str, severity: u8, code: u16, text: &str) -> MachineError {
    let error = zeroset_drivers::wire::DeviceError::new(
        severity,
        code,
        zeroset_drivers::wire::WireString::new(command).unwrap(),
        zeroset_drivers::wire::WireString::new(text).unwrap(),
    )
    .unwrap();
    MachineError::new(
        "cmm1".into(),
        format!("{command}()"),
        ErrorKind::Device(error),
    )
}

#[tokio::test]
async fn a_lost_link_is_opened_again_by_the_next_order_not_reused() {
    let opened = Arc::new(Mutex::new(0usize));
    let moves = Arc::new(Mutex::new(Vec::new()));
    let connector: Connector = {
        let (opened, moves) = (opened.clone(), moves.clone());
        Box::new(move || {
            let mut count = opened.lock().unwrap();
            *count += 1;
            let positions = vec![Xyz::new(0.0, 0.0, 400.0); 2];
            // The first link dies under the approach (through `?`, not a named failure path).
            let moves = (*count > 1).then(|| moves.clone());
            let mut machine = bare_machine(positions, moves, Vec::new());
            machine.expect_start_session().returning(|| Ok(()));
            machine.expect_clear_all_errors().returning(|| Ok(()));
            Ok(Arc::new(machine) as Link)
        })
    };
    let (worker, mut reports) = worker_with(connector);
    let (pipeline, _analysis) = mpsc::channel(16);
    send_scan(&worker, motion(), pipeline).await;
    let error = scan_result(&mut reports).await.unwrap_err();
    assert_eq!(error.kind, FaultKind::Transport, "{}", error.message);
    clear(&worker, EscapeModel::default())
        .await
        .expect("cleared on a new link");
    assert_eq!(
        *opened.lock().unwrap(),
        2,
        "the dead link was dropped and a new one opened"
    );
}

#[tokio::test]
async fn a_clear_on_a_session_the_machine_lost_starts_it_again() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    let mut machine = bare_machine(vec![Xyz::new(0.0, 0.0, 400.0); 3], Some(moves), Vec::new());
    let sessions = Arc::new(Mutex::new(0usize));
    {
        let sessions = sessions.clone();
        machine.expect_start_session().returning(move || {
            *sessions.lock().unwrap() += 1;
            Ok(())
        });
    }
    // The first clear's, on the session it has just opened; then the machine has lost the session.
    machine
        .expect_clear_all_errors()
        .times(1)
        .returning(|| Ok(()));
    machine
        .expect_clear_all_errors()
        .returning(|| Err(protocol_error("ClearAllErrors")));
    machine.expect_end_session().returning(|| Ok(()));
    let (worker, _reports) = worker_on(machine);
    for _ in 0..2 {
        clear(&worker, EscapeModel::default())
            .await
            .expect("cleared");
    }
    // The first clear opens the session; the second finds it lost (0008) and opens it again.
    assert_eq!(*sessions.lock().unwrap(), 2);
}

#[tokio::test]
async fn a_scan_with_a_hole_is_cut_not_counted_and_the_probe_still_leaves_as_planned() {
    let motion = motion();
    let moves = Arc::new(Mutex::new(Vec::new()));
    let positions = vec![Xyz::new(0.0, 0.0, 400.0), Xyz::new(100.0, 0.0, 21.0)];
    let mut scanned = whole_circle();
    scanned.drain(20..30);
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), scanned));
    let (pipeline, mut analysis) = mpsc::channel(128);
    send_scan(&worker, motion.clone(), pipeline).await;
    let error = scan_result(&mut reports).await.unwrap_err();
    assert_eq!(error.kind, FaultKind::Gap, "{}", error.message);
    assert!(
        error.message.contains("after point 19"),
        "{}",
        error.message
    );
    let planned = planned_moves(&motion);
    assert_eq!(
        *moves.lock().unwrap(),
        planned,
        "the machine did its part: it leaves as planned"
    );
    let mut last = None;
    while let Ok(message) = analysis.try_recv() {
        last = Some(message);
    }
    assert!(matches!(last, Some(PipelineMsg::Cut { .. })), "{last:?}");
}

#[tokio::test]
async fn a_teach_scan_sends_exactly_its_planned_motion() {
    let motion = teach_motion(1.0);
    let moves = Arc::new(Mutex::new(Vec::new()));
    let positions = vec![Xyz::new(0.0, 0.0, 400.0), Xyz::new(100.0, 0.0, 21.0)];
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), whole_circle()));
    let (pipeline, _analysis) = mpsc::channel(128);
    send_scan(&worker, motion.clone(), pipeline).await;
    scan_result(&mut reports).await.expect("taught");
    let planned = planned_moves(&motion);
    assert_eq!(*moves.lock().unwrap(), planned);
    // Straight down over the start by the planned ball and the teach margin, and back up the same way.
    assert!(
        close(&planned[1], &Xyz::new(100.0, 0.0, 26.5)),
        "{planned:?}"
    );
    assert_eq!(planned.len(), 4);
}

/// The GoTo targets a scan's motion plans: its approach, then its retract.
fn planned_moves(motion: &ScanMotion) -> Vec<Xyz> {
    motion
        .approach
        .iter()
        .chain(&motion.retract)
        .map(xyz_of)
        .collect()
}

/// The teach scan of the circle from its top, towards y = `towards_y` (+1 or -1), for a 1 mm ball.
fn teach_motion(towards_y: f64) -> ScanMotion {
    let xyz = |x, y, z| Xyz::new(x, y, z);
    let scan = Scan::InPlane(InPlaneScan {
        start: xyz(100.0, 0.0, 20.0),
        start_normal: xyz(0.0, 0.0, 1.0),
        plane_normal: xyz(1.0, 0.0, 0.0),
        direction: xyz(100.0, towards_y, 20.0),
        spacing: InPlaneSpacing::Step(2.0),
        end: xyz(100.0, 0.0, 20.0),
        stop_diameter: 3.0,
        passes: 1,
        end_normal: xyz(0.0, 0.0, 1.0),
    });
    let start = KnownPath {
        surface: vec![Point3::new(100.0, 0.0, 20.0)],
        normals: vec![nalgebra::Vector3::new(0.0, 0.0, 1.0)],
        closed: false,
        entry: 0,
    };
    ScanMotion::plan(KEY, "A r100".into(), scan, start, 5.0, &safety()).unwrap()
}

/// A teach scan of the circle stopped by an emergency stop at its 30th point (150 degrees round, under it) with
/// only its first 20 points sent; the machine's move reports (`reported`) every second point up to the stop.
/// Returns what the clear answered and the moves it made.
async fn clear_after_a_stop_in_a_teach_scan(reported: bool) -> (ScanResult, Vec<Xyz>) {
    let round = whole_circle();
    let stopped = round[30];
    let positions = vec![Xyz::new(0.0, 0.0, 400.0), stopped.centre];
    // What the scan's own transaction ends with on an emergency stop: 0006, transaction aborted.
    let estop = device_error("ScanInPlaneEndIsSphere", 2, 6, "Transaction aborted");
    let reporting: Option<Arc<dyn MoveReporting>> = reported.then(|| {
        let mut reporting = MockMoveReporting::new();
        let trail: Vec<Xyz> = round[..=30].iter().step_by(2).map(|p| p.centre).collect();
        reporting
            .expect_start_move_reports()
            .times(1)
            .returning(move |rate| {
                assert_eq!(rate.interval, Duration::from_millis(100));
                let tag = zeroset_drivers::wire::EventTag::new(1).unwrap();
                Ok(MoveReports::new(
                    tag,
                    stream::iter(trail.clone().into_iter().map(Ok)),
                ))
            });
        reporting
            .expect_stop_move_reports()
            .times(1)
            .returning(|_| Ok(()));
        Arc::new(reporting) as Arc<dyn MoveReporting>
    });
    let moves = Arc::new(Mutex::new(Vec::new()));
    let mut machine = scanning_machine(
        positions,
        Some(moves.clone()),
        round[..20].to_vec(),
        Some(estop),
        reporting,
    );
    machine.expect_start_session().returning(|| Ok(()));
    machine.expect_clear_all_errors().returning(|| Ok(()));
    let (worker, mut reports) = worker_on(machine);
    let (pipeline, _analysis) = mpsc::channel(128);
    let motion = teach_motion(-1.0);
    let approach = motion.approach.len();
    send_scan(&worker, motion, pipeline).await;
    scan_result(&mut reports).await.unwrap_err();
    let cleared = clear(&worker, EscapeModel::default()).await;
    let moves = moves.lock().unwrap()[approach..].to_vec();
    (cleared, moves)
}

#[tokio::test]
async fn a_teach_scan_stopped_past_its_last_sent_point_leaves_by_the_positions_the_machine_reported(
) {
    // Without the reports the probe is 10 points (17 mm of travel) past the last point known: no way out is known.
    let (blind, moves) = clear_after_a_stop_in_a_teach_scan(false).await;
    let refusal = blind.unwrap_err();
    assert_eq!(refusal.kind, FaultKind::Refused, "{}", refusal.message);
    assert!(
        refusal.message.contains("from the path it was scanning"),
        "{}",
        refusal.message
    );
    assert!(moves.is_empty(), "{moves:?}");
    // With them, the clear lifts off the circle's side and follows the reported travel back over the top.
    let (cleared, moves) = clear_after_a_stop_in_a_teach_scan(true).await;
    cleared.expect("cleared");
    let (first, last) = (moves[0], moves[moves.len() - 1]);
    let stop = whole_circle()[30].centre;
    let out = (Point3::new(first.x, first.y, first.z) - Point3::new(100.0, 0.0, 0.0)).norm()
        - (Point3::new(stop.x, stop.y, stop.z) - Point3::new(100.0, 0.0, 0.0)).norm();
    assert!(out > 4.0, "lifts off outwards by the margin: {first:?}");
    assert!(
        close(&last, &Xyz::new(100.0, 0.0, CLEARANCE_MM)),
        "{last:?}"
    );
    for target in &moves {
        let radial = (target.y.powi(2) + target.z.powi(2)).sqrt();
        assert!(
            radial > 20.0 + 1.0 + 4.5 || target.z > 26.0,
            "a waypoint inside the margin round the circle: {target:?}"
        );
    }
}

#[tokio::test]
async fn an_abort_before_the_first_connection_still_stops_the_order_until_a_clear() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    let positions = vec![Xyz::new(0.0, 0.0, 400.0); 3];
    let mut machine = machine(positions, moves.clone(), whole_circle());
    machine.expect_clear_all_errors().returning(|| Ok(()));
    let (worker, mut reports) = worker_on(machine);
    // No link is open yet: the AbortE cannot be sent, but the order that follows sends no motion.
    worker.abort().await;
    let (pipeline, _analysis) = mpsc::channel(128);
    send_scan(&worker, motion(), pipeline).await;
    let error = scan_result(&mut reports).await.unwrap_err();
    assert_eq!(error.kind, FaultKind::Aborted, "{}", error.message);
    assert!(
        moves.lock().unwrap().is_empty(),
        "{:?}",
        moves.lock().unwrap()
    );
    // The operator's clear lifts it (at the clearance height: nothing to move).
    clear(&worker, EscapeModel::default())
        .await
        .expect("cleared");
}

fn observed(message: Option<DaemonMsg>) -> WorkerError {
    match message {
        Some(DaemonMsg::Input(Input::Observed { machine, fault })) => {
            assert_eq!(machine, "cmm1");
            fault
        }
        _ => panic!("expected what the watch saw"),
    }
}

fn seen(message: Option<DaemonMsg>) {
    assert!(
        matches!(&message, Some(DaemonMsg::Input(Input::Seen { machine })) if machine == "cmm1"),
        "expected the first look's 'ready'"
    );
}

#[tokio::test]
async fn a_machine_holding_a_killed_daemon_s_session_is_still_looked_at() {
    let (alarms, _) = broadcast::channel(8);
    // StartSession: 0008, the session of the daemon that was killed is still open; GetErrStatusE answers on it.
    let (_worker, mut reports) =
        watched_with_session(&alarms, || Err(protocol_error("StartSession")), || Ok(true));
    let fault = observed(
        tokio::time::timeout(Duration::from_secs(2), reports.recv())
            .await
            .unwrap(),
    );
    assert_eq!(fault.kind, FaultKind::LockedOut, "{}", fault.message);
    assert!(
        fault.message.contains("error state while idle"),
        "{}",
        fault.message
    );
}

/// An idle machine under a fast watch, its alarms sent through `alarms`, GetErrStatusE answered by `in_error`.
fn watched(
    alarms: &broadcast::Sender<Event>,
    in_error: impl Fn() -> Result<bool, MachineError> + Send + 'static,
) -> (WorkerHandle, mpsc::Receiver<DaemonMsg>) {
    watched_with_session(alarms, || Ok(()), in_error)
}

/// Like [`watched`], StartSession answered by `start_session`.
fn watched_with_session(
    alarms: &broadcast::Sender<Event>,
    start_session: impl Fn() -> Result<(), MachineError> + Send + 'static,
    in_error: impl Fn() -> Result<bool, MachineError> + Send + 'static,
) -> (WorkerHandle, mpsc::Receiver<DaemonMsg>) {
    let mut machine = MockMachine::new();
    let alarms = alarms.clone();
    machine
        .expect_events()
        .returning(move || alarms.subscribe());
    machine.expect_start_session().returning(start_session);
    machine.expect_in_error().returning(in_error);
    machine.expect_go_to().never();
    let machine: Link = Arc::new(machine);
    let (daemon, reports) = mpsc::channel(8);
    let watch = Some(Duration::from_millis(20));
    let handle = spawn_on(
        "cmm1".into(),
        Box::new(move || Ok(machine.clone())),
        probe(),
        safety(),
        watch,
        daemon,
    );
    (handle, reports)
}

#[tokio::test]
async fn an_emergency_stop_on_an_idle_machine_is_seen_at_once_and_the_next_scan_sends_nothing() {
    let (alarms, _) = broadcast::channel(8);
    let (worker, mut reports) = watched(&alarms, || Ok(false));
    // The first look at a healthy machine says it is ready; the next few report nothing.
    seen(reports.recv().await);
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert!(reports.try_recv().is_err());
    let estop = zeroset_drivers::wire::DeviceError::new(
        3,
        500,
        zeroset_drivers::wire::WireString::new("E0000").unwrap(),
        zeroset_drivers::wire::WireString::new("Emergency stop").unwrap(),
    )
    .unwrap();
    alarms.send(Event::Unsolicited(estop)).unwrap();
    let fault = observed(
        tokio::time::timeout(Duration::from_secs(2), reports.recv())
            .await
            .unwrap(),
    );
    assert_eq!(
        fault.kind,
        FaultKind::Device {
            severity: 3,
            code: 500
        }
    );
    assert!(fault.message.contains("while idle"), "{}", fault.message);
    // Seen once, not at every look.
    tokio::time::sleep(Duration::from_millis(100)).await;
    assert!(reports.try_recv().is_err());
    // An order that meets the stopped machine ends with its fault and sends nothing (the mock refuses any GoTo).
    let (pipeline, _analysis) = mpsc::channel(8);
    send_scan(&worker, motion(), pipeline).await;
    let error = scan_result(&mut reports).await.unwrap_err();
    assert_eq!(error.kind, fault.kind, "{}", error.message);
}

#[tokio::test]
async fn a_line_that_went_dead_while_idle_is_seen_by_the_look() {
    let (alarms, _) = broadcast::channel(8);
    let (_worker, mut reports) = watched(&alarms, || Err(lost("GetErrStatusE")));
    let fault = observed(
        tokio::time::timeout(Duration::from_secs(2), reports.recv())
            .await
            .unwrap(),
    );
    assert_eq!(fault.kind, FaultKind::Transport, "{}", fault.message);
    assert!(fault.message.contains("GetErrStatusE"), "{}", fault.message);
}

#[tokio::test]
async fn a_port_that_cannot_be_opened_is_seen_before_any_job() {
    let (daemon, mut reports) = mpsc::channel(8);
    let connector: Connector = Box::new(|| {
        Err(WorkerError {
            kind: FaultKind::PortMissing,
            message: "machine cmm1: cannot open its line /dev/ttyUSB7: No such file or directory"
                .into(),
        })
    });
    let _worker = spawn_on(
        "cmm1".into(),
        connector,
        probe(),
        safety(),
        Some(Duration::from_millis(20)),
        daemon,
    );
    let fault = observed(
        tokio::time::timeout(Duration::from_secs(2), reports.recv())
            .await
            .unwrap(),
    );
    assert_eq!(fault.kind, FaultKind::PortMissing);
    assert!(fault.message.contains("/dev/ttyUSB7"), "{}", fault.message);
}

/// What a restarted daemon gives a clear: an older cut scan 300 mm away, listed first, then the circle's scan.
fn restarted_escape() -> EscapeModel {
    EscapeModel {
        paths: vec![
            scan_path("instance A, profile r100", 300.0),
            scan_path("instance B, profile r300", 0.0),
        ],
        part: None,
        deviation_margin_mm: MARGIN_MM,
    }
}

fn scan_path(name: &str, shift_y_mm: f64) -> ScanPath {
    let mut path = circle();
    for p in &mut path.surface {
        p.y += shift_y_mm;
    }
    ScanPath {
        name: name.into(),
        path,
        margin_mm: MARGIN_MM,
    }
}

#[tokio::test]
async fn far_from_every_scan_it_knows_a_clear_moves_nothing_and_names_the_nearest() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    let (worker, _reports) = worker_on(machine(
        vec![Xyz::new(100.0, 150.0, 10.0)],
        moves.clone(),
        Vec::new(),
    ));
    let escape = restarted_escape();
    let error = clear(&worker, escape).await.unwrap_err();
    assert_eq!(error.kind, FaultKind::Refused);
    assert!(
        error
            .message
            .contains("the nearest scan known: instance B, profile r300")
            || error
                .message
                .contains("the nearest scan known: instance A, profile r100"),
        "{}",
        error.message
    );
    assert!(moves.lock().unwrap().is_empty());
}
