//! Distance throughput to a 2-D quartic (seed 003's profile 3): points per second on one core for the exact
//! distance (seeded along the scan, and point by point), the paper's approximation and Taubin's estimate.
//!
//!     cargo bench --bench distance

mod data;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use zeroset::geometry::distance::{paper_distance, taubin_distance, ExactDistance};
use zeroset::geometry::sampling::{Aabb, ZeroSetSamples};

fn distances(c: &mut Criterion) {
    let model = data::profile_3();
    // Blade B: 0.8 mm inside, in scan order.
    let scan = data::profile_3_scan(4_000, -0.8);
    let bounds = Aabb::of_points(&scan).expect("points").scaled(2.0);
    let samples = ZeroSetSamples::new(&model, &bounds, 512);
    let exact = ExactDistance::new(&model, &samples);
    let mut group = c.benchmark_group("distance to a 2-D quartic");
    group.throughput(Throughput::Elements(scan.len() as u64));
    group.bench_function("taubin", |b| {
        b.iter(|| {
            scan.iter()
                .map(|p| taubin_distance(&model, p).unwrap_or(0.0))
                .sum::<f64>()
        })
    });
    group.bench_function("paper", |b| {
        b.iter(|| {
            scan.iter()
                .map(|p| paper_distance(&model, p, 1000.0).map_or(0.0, |f| f.distance))
                .sum::<f64>()
        })
    });
    group.bench_function("exact, seeded along the scan", |b| {
        b.iter(|| {
            exact
                .feet_along_scan(&scan)
                .iter()
                .map(|f| f.map_or(0.0, |f| f.distance))
                .sum::<f64>()
        })
    });
    group.bench_function("exact, point by point", |b| {
        b.iter(|| {
            scan.iter()
                .map(|p| exact.foot(p, None).map_or(0.0, |f| f.distance))
                .sum::<f64>()
        })
    });
    group.finish();
    c.bench_function("sample the zero set (512 cells)", |b| {
        b.iter_batched(
            || (),
            |_| ZeroSetSamples::new(&model, &bounds, 512),
            BatchSize::SmallInput,
        )
    });
}

criterion_group!(benches, distances);
criterion_main!(benches);
