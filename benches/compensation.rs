//! Per-point cost of probe-radius compensation (geometry::sweep::compensation): the live pipeline compensates each
//! point as its look-ahead arrives, within the station's 1 ms point-to-event budget. Two scans: a smooth one (every
//! point from the local quartic) and a blade's sharp trailing edge, where each point near the roll searches runs of
//! centres for the edge's circle.
//!
//! Run: `cargo bench --bench compensation`.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{Point3, Vector3};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
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

/// A 1 mm ball's centres along a 20-deg wedge's faces (30 points each, 0.5 mm apart), rolled round its sharp tip in
/// 10-deg steps, with 2 um of seeded noise on each centre: a blade's trailing edge as an inspection scans it.
fn sharp_edge_scan() -> Vec<(Point3<f64>, Vector3<f64>)> {
    // The material towards -x, each face 10 deg either side of it.
    let half = 10f64.to_radians();
    let lower = Vector3::new(half.sin(), -half.cos(), 0.0);
    let upper = Vector3::new(half.sin(), half.cos(), 0.0);
    let face = |normal: Vector3<f64>, k: usize| {
        let along = Vector3::new(-half.cos(), normal.y.signum() * half.sin(), 0.0);
        (
            Point3::from(along * (0.5 * (k as f64 + 0.5)) + normal),
            normal,
        )
    };
    let mut truth: Vec<_> = (0..30).rev().map(|k| face(lower, k)).collect();
    let (from, to) = (lower.y.atan2(lower.x), upper.y.atan2(upper.x));
    let steps = ((to - from) / 10f64.to_radians()).round() as usize;
    truth.extend((0..=steps).map(|i| {
        let angle = from + (to - from) * i as f64 / steps as f64;
        let normal = Vector3::new(angle.cos(), angle.sin(), 0.0);
        (Point3::from(normal), normal)
    }));
    truth.extend((0..30).map(|k| face(upper, k)));
    let noise = Normal::new(0.0, 0.002).expect("a positive sigma");
    let mut rng = StdRng::seed_from_u64(7);
    truth
        .into_iter()
        .map(|(centre, normal)| {
            let offset = Vector3::new(noise.sample(&mut rng), noise.sample(&mut rng), 0.0);
            (centre + offset, normal)
        })
        .collect()
}

/// Streams `scan` through a compensator, as the live pipeline does.
fn stream(scan: &[(Point3<f64>, Vector3<f64>)]) -> usize {
    let mut compensator = Compensator::new(CompensationSettings::new(1.0), Vector3::z());
    let mut fitted = 0;
    for (centre, normal) in scan {
        for point in compensator.push(black_box(*centre), black_box(*normal)) {
            fitted += usize::from(!point.is_flagged());
        }
    }
    fitted + compensator.finish().len()
}

fn per_point(c: &mut Criterion) {
    let mut group = c.benchmark_group("compensation");
    for (name, scan) in [
        ("stream 700 points", ellipse_scan()),
        ("stream a sharp edge rolled round", sharp_edge_scan()),
    ] {
        group.throughput(Throughput::Elements(scan.len() as u64));
        group.bench_function(name, |b| b.iter(|| stream(&scan)));
    }
    group.finish();
}

criterion_group!(benches, per_point);
criterion_main!(benches);
