//! Supershape recovery (issue 5, item 2): the time to recover a supershape from 2 000 and 5 000 noisy points with
//! its symmetry read from them; the superquadric special case (2 000 points, noise 1% of the size) against the EMS
//! yardstick of the issue, fitted as a superquadric (11 parameters) and as a supershape with symmetry 4,4 given
//! (15), with their relative errors printed; and evaluations per second of
//! the radial implicit function (seed 000 eq. 7).
//!
//!     cargo bench --bench supershape_recovery

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset::geometry::supershape::deform::{Deformation, Deformations};
use zeroset::geometry::supershape::formula::Superformula;
use zeroset::geometry::supershape::recover::{recover, surface_gap_rms, Family, RecoveryOptions};
use zeroset::geometry::supershape::shape::Supershape;

fn formula(m: f64, n: [f64; 3]) -> Superformula {
    Superformula::new(m, n[0], n[1], n[2], 1.0, 1.0).expect("valid superformula")
}

/// A placed shape's surface with Gaussian noise of `sigma` mm on every coordinate.
fn scan(
    shape: &Supershape,
    place: &Isometry3<f64>,
    count: usize,
    sigma: f64,
    seed: u64,
) -> Vec<Point3<f64>> {
    let mut rng = StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, sigma).expect("a normal");
    shape
        .surface_points(count)
        .iter()
        .map(|p| place * p + Vector3::from_fn(|_, _| noise.sample(&mut rng)))
        .collect()
}

fn pose() -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(12.0, -30.0, 5.0),
        UnitQuaternion::from_euler_angles(0.4, -0.3, 1.1),
    )
}

/// A hexagonal knob: m1 = 6 with rounded flats, a boxy meridian.
fn knob() -> Supershape {
    Supershape {
        r1: formula(6.0, [6.0, 5.0, 5.0]),
        r2: formula(4.0, [5.0, 6.0, 6.0]),
        scale: [25.0, 25.0, 15.0],
    }
}

/// Superquadrics (epsilon1, epsilon2) as supershapes: m = 4, r1 exponents 2 / epsilon2, r2 exponents 2 / epsilon1.
fn superquadrics() -> Vec<Supershape> {
    [(0.3, 0.5), (0.6, 1.0), (1.0, 0.4), (1.4, 0.8)]
        .iter()
        .enumerate()
        .map(|(k, (e1, e2))| Supershape {
            r1: formula(4.0, [2.0 / e2; 3]),
            r2: formula(4.0, [2.0 / e1; 3]),
            scale: [30.0 - 3.0 * k as f64, 20.0 + 2.0 * k as f64, 14.0],
        })
        .collect()
}

fn mean_size(shape: &Supershape) -> f64 {
    shape.scale.iter().sum::<f64>() / 3.0
}

fn bench_recovery(c: &mut Criterion) {
    let options = RecoveryOptions {
        truncate: false,
        holes: false,
        ..RecoveryOptions::default()
    };
    let place = pose();
    let placed = Deformations(vec![Deformation::Rigid(place)]);
    let mut group = c.benchmark_group("supershape_recovery");
    group.sample_size(10);
    for count in [2000, 5000] {
        let shape = knob();
        let points = scan(&shape, &place, count, 0.005 * mean_size(&shape), 7);
        let recovered = recover(&points, &options).expect("the knob recovers");
        eprintln!(
            "knob, {count} points: symmetry {:?}, relative surface gap {:.2e}",
            recovered.symmetry,
            surface_gap_rms(
                (&shape, &placed),
                (&recovered.envelope.0, &recovered.envelope.1),
                1000
            ) / mean_size(&shape)
        );
        group.bench_function(format!("knob_{count}_points"), |b| {
            b.iter(|| recover(&points, &options).expect("recovers"))
        });
    }
    let given = RecoveryOptions {
        symmetry: Some([4, 4]),
        ..options.clone()
    };
    let superquadric = RecoveryOptions {
        family: Family::Superquadric,
        ..options.clone()
    };
    let scans: Vec<(Supershape, Vec<Point3<f64>>)> = superquadrics()
        .into_iter()
        .enumerate()
        .map(|(k, shape)| {
            let points = scan(
                &shape,
                &place,
                2000,
                0.01 * mean_size(&shape),
                11 + k as u64,
            );
            (shape, points)
        })
        .collect();
    for (name, options) in [
        ("superquadric_family", &superquadric),
        ("supershape_4_4", &given),
    ] {
        for (shape, points) in &scans {
            let recovered = recover(points, options).expect("a superquadric recovers");
            eprintln!(
                "{name} fit of superquadric {:?}: relative surface gap {:.2e}",
                shape.scale,
                surface_gap_rms(
                    (shape, &placed),
                    (&recovered.envelope.0, &recovered.envelope.1),
                    1000
                ) / mean_size(shape)
            );
        }
        group.bench_function(format!("{name}_2000_points_1pct_noise"), |b| {
            let mut k = 0;
            b.iter(|| {
                k = (k + 1) % scans.len();
                recover(&scans[k].1, options).expect("recovers")
            })
        });
    }
    group.finish();
}

fn bench_evaluations(c: &mut Criterion) {
    let shape = knob();
    let points: Vec<Point3<f64>> = shape
        .surface_points(10_000)
        .iter()
        .map(|p| Point3::from(p.coords * 1.03))
        .collect();
    let mut group = c.benchmark_group("supershape_radial_function");
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("10k_evaluations", |b| {
        b.iter(|| points.iter().map(|p| shape.radial(p)).sum::<f64>())
    });
    group.finish();
}

criterion_group!(benches, bench_recovery, bench_evaluations);
criterion_main!(benches);
