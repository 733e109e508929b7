//! The worker's motion logic against mocked machines: where it moves before and after a scan, and that it will not
//! move a probe it cannot get clear safely.

use std::sync::{Arc, Mutex};

use futures::stream;
use nalgebra::{Point3, Vector3};
use tokio::sync::{broadcast, mpsc};
use zeroset_drivers::machine::{
    CurveScan, Density, MockMachine, MockScanning, Nominal, ScanPoint, ScanStream, Scanning, Xyz,
};

use super::*;
use crate::config::{ProbeSettings, Safety};
use crate::plan::ProfileKey;

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

/// A circular profile of radius 20 mm in the plane x = 100, its top first (the entry).
fn circle() -> KnownPath {
    let (surface, normals) = (0..72)
        .map(|k| {
            let t = std::f64::consts::FRAC_PI_2 + std::f64::consts::TAU * k as f64 / 72.0;
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
    let mut machine = MockMachine::new();
    machine
        .expect_events()
        .returning(|| broadcast::channel(1).1);
    machine.expect_start_session().returning(|| Ok(()));
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
    machine.expect_go_to().returning(move |target| {
        moves.lock().unwrap().push(target);
        Ok(())
    });
    let mut scanning = MockScanning::new();
    scanning
        .expect_scan_on_curve()
        .times(0..=1)
        .returning(move |_| {
            Ok(ScanStream::new(stream::iter(
                scan.clone().into_iter().map(Ok),
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
    let (daemon, reports) = mpsc::channel(8);
    let handle = spawn_on(
        "cmm1".into(),
        Box::new(move || Ok(machine.clone())),
        probe(),
        safety(),
        daemon,
    );
    (handle, reports)
}

fn order(path: KnownPath, pipeline: mpsc::Sender<PipelineMsg>) -> Order {
    Order::Scan(ScanOrder {
        key: ProfileKey {
            instance: 1,
            profile: 2,
        },
        scan: Scan::Curve(curve_scan(&path)),
        path,
        margin_mm: MARGIN_MM,
        pipeline,
    })
}

fn close(a: &Xyz, b: &Xyz) -> bool {
    (a.x - b.x).abs() < 1e-9 && (a.y - b.y).abs() < 1e-9 && (a.z - b.z).abs() < 1e-9
}

fn point(z: f64) -> ScanPoint {
    ScanPoint {
        centre: Xyz::new(100.0, 0.0, z),
        normal: Xyz::new(0.0, 0.0, 1.0),
        quality: 0.0,
    }
}

#[tokio::test]
async fn a_scan_is_entered_from_above_streamed_in_order_and_left_the_way_it_came() {
    let path = circle();
    // Over the entry (the top at z = 20) by the ball and the margin: z = 23.
    let entry = Xyz::new(100.0, 0.0, 23.0);
    let moves = Arc::new(Mutex::new(Vec::new()));
    // Homed at z = 400 before; at the end of the closed scan, back over the top, the ball 2 mm off the surface.
    let positions = vec![Xyz::new(0.0, 0.0, 400.0), Xyz::new(100.0, 0.0, 23.0)];
    let scanned = vec![point(21.0), point(21.001), point(20.999)];
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), scanned.clone()));
    let (pipeline, mut analysis) = mpsc::channel(16);
    worker.orders.send(order(path, pipeline)).await.unwrap();

    let DaemonMsg::ScanEnded {
        machine,
        key,
        result,
    } = reports.recv().await.unwrap()
    else {
        panic!("expected the end of the scan");
    };
    assert_eq!(
        (machine.as_str(), key.instance, key.profile),
        ("cmm1", 1, 2)
    );
    assert!(result.is_ok(), "{:?}", result.err());
    let expected = [
        Xyz::new(100.0, 0.0, CLEARANCE_MM),
        entry,
        entry,
        Xyz::new(100.0, 0.0, CLEARANCE_MM),
    ];
    let moves = moves.lock().unwrap().clone();
    assert!(
        moves.len() == expected.len() && moves.iter().zip(&expected).all(|(a, b)| close(a, b)),
        "over the entry at the clearance height, down to it; after the scan back to it, then up: {moves:?}"
    );
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
async fn a_probe_near_the_part_with_no_known_way_out_is_not_moved() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    // After a restart the probe is down at z = 10, below the clearance height, and no scan path is known.
    let positions = vec![Xyz::new(100.0, -25.0, 10.0)];
    let (worker, mut reports) = worker_on(machine(positions, moves.clone(), Vec::new()));
    let (pipeline, _analysis) = mpsc::channel(16);
    worker.orders.send(order(circle(), pipeline)).await.unwrap();
    let DaemonMsg::ScanEnded { result, .. } = reports.recv().await.unwrap() else {
        panic!("expected the end of the scan");
    };
    let message = result.unwrap_err().message;
    assert!(
        message.contains("cmm1") && message.contains("jog the probe above z = 150 mm"),
        "{message}"
    );
    assert!(moves.lock().unwrap().is_empty(), "no move at all");
}

#[tokio::test]
async fn a_cleared_machine_leaves_the_part_along_the_path_of_the_cut_scan() {
    let moves = Arc::new(Mutex::new(Vec::new()));
    // A daemon was killed with the ball under the circle (z = -21); the new daemon knows the cut scan's path.
    let positions = vec![Xyz::new(100.0, 0.0, -21.0)];
    let (worker, _reports) = worker_on(machine(positions, moves.clone(), Vec::new()));
    let (reply, answer) = tokio::sync::oneshot::channel();
    worker
        .orders
        .send(Order::Clear {
            path: Some((circle(), MARGIN_MM)),
            reply,
        })
        .await
        .unwrap();
    answer.await.unwrap().expect("cleared");
    let moves = moves.lock().unwrap();
    assert!(
        close(moves.last().unwrap(), &Xyz::new(100.0, 0.0, CLEARANCE_MM)),
        "{moves:?}"
    );
    // Round the circle, never through it: every waypoint at least the ball and the margin off the surface.
    for target in moves.iter() {
        let off = (target.y.powi(2) + target.z.powi(2)).sqrt() - 20.0;
        assert!(
            off >= 1.0 + MARGIN_MM - 1e-9,
            "{target:?} is {off} mm off the circle"
        );
    }
    assert!(moves.len() > 10, "{} moves", moves.len());
}
