//! The mocks the `mock` feature provides, driven the way the station drives a machine.
#![cfg(feature = "mock")]

use std::sync::Arc;

use futures_util::{stream, StreamExt};
use zeroset_drivers::machine::{
    InPlaneScan, InPlaneSpacing, Machine, MockMachine, MockScanning, ScanPoint, ScanStream, Xyz,
};

/// What a station worker does first: home if needed, then scan, collecting the points.
async fn home_and_scan(machine: &dyn Machine, plan: InPlaneScan) -> Vec<ScanPoint> {
    if !machine.is_homed().await.unwrap() {
        machine.home().await.unwrap();
    }
    let scanning = machine.scanning().expect("a scanning machine");
    let points = scanning.scan_in_plane(plan).await.unwrap();
    points.map(Result::unwrap).collect().await
}

#[tokio::test]
async fn a_mock_machine_stands_in_for_the_client() {
    let point = ScanPoint {
        centre: Xyz::new(1.0, 2.0, 3.0),
        normal: Xyz::new(0.0, 0.0, 1.0),
        quality: 0.0,
    };
    let mut scanning = MockScanning::new();
    scanning
        .expect_scan_in_plane()
        .withf(|plan| plan.spacing == InPlaneSpacing::Step(0.25))
        .times(1)
        .returning(move |_| Ok(ScanStream::new(stream::iter([Ok(point), Ok(point)]))));
    let scanning = Arc::new(scanning);

    let mut machine = MockMachine::new();
    machine.expect_is_homed().times(1).returning(|| Ok(false));
    machine.expect_home().times(1).returning(|| Ok(()));
    machine
        .expect_scanning()
        .returning(move || Some(scanning.clone()));

    let plan = InPlaneScan {
        start: Xyz::new(0.0, 0.0, 0.0),
        start_normal: Xyz::new(0.0, 0.0, 1.0),
        plane_normal: Xyz::new(1.0, 0.0, 0.0),
        direction: Xyz::new(0.0, 1.0, 0.0),
        spacing: InPlaneSpacing::Step(0.25),
        end: Xyz::new(0.0, 0.0, 0.0),
        stop_diameter: 1.0,
        passes: 1,
        end_normal: Xyz::new(0.0, 0.0, 1.0),
    };
    assert_eq!(home_and_scan(&machine, plan).await, [point, point]);
}
