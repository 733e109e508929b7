//! Per-point cost of probe-radius compensation (geometry::sweep::compensation): the live pipeline compensates each
//! point as its look-ahead arrives, within the station's 1 ms point-to-event budget.
//!
//! Run: `cargo bench --bench compensation`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{Point3, Vector3};
use zeroset::geometry::sweep::compensation::{CompensationSettings, Compensator};

/// A 1 mm ball's centres round a 20 x 10 mm ellipse, 700 points (0.1 to 0.2 mm apart), with the exact normals.
fn ellipse_scan() -> Vec<(Point3<f64>, Vector3<f64>)> {
    (0..700)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / 700.0;
            let normal = Vector3::new(10.0 * t.cos(), 20.0 * t.sin(), 0.0).normalize();
            (
                Point3::new(20.0 * t.cos(), 10.0 * t.sin(), 0.0) + normal,
                normal,
            )
        })
        .collect()
}

fn per_point(c: &mut Criterion) {
    let scan = ellipse_scan();
    let mut group = c.benchmark_group("compensation");
    group.throughput(Throughput::Elements(scan.len() as u64));
    group.bench_function("stream 700 points", |b| {
        b.iter(|| {
            let mut compensator = Compensator::new(CompensationSettings::new(1.0), Vector3::z());
            let mut fitted = 0;
            for (centre, normal) in &scan {
                for point in compensator.push(black_box(*centre), black_box(*normal)) {
                    fitted += usize::from(!point.is_flagged());
                }
            }
            fitted + compensator.finish().len()
        })
    });
    group.finish();
}

criterion_group!(benches, per_point);
criterion_main!(benches);
