//! A section with a sharp trailing edge fitted face by face (issue 15): the fit's time for a NACA 2412 scan of 400
//! points (100 mm chord), and the exact distance's throughput to the faces, beside one degree-8 polynomial's
//! exact distance (seeded along the scan) and Taubin's estimate in the same run.
//!
//!     cargo bench --bench faces

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::Vector2;
use zeroset::geometry::distance::{taubin_distance, ExactDistance};
use zeroset::geometry::faces::{fit_faces, FacesFitOptions};
use zeroset::geometry::fit3l::{fit_ip, FitMethod, FitOptions};
use zeroset::geometry::normals::ordered_profile_normals;
use zeroset::geometry::sampling::ZeroSetSamples;
use zeroset_sim::naca::Naca4;

fn faces(c: &mut Criterion) {
    let foil = Naca4::from_digits("2412", 100.0, true).expect("digits");
    let section: Vec<Vector2<f64>> = foil.points(400).into_iter().map(Vector2::from).collect();
    let options = FacesFitOptions {
        degree: None,
        method: FitMethod::Orthogonal,
        split_unfollowed: true,
    };
    c.bench_function(
        "fit a NACA 2412 face by face (400 points, degrees by held-out points)",
        |b| {
            b.iter(|| {
                fit_faces(&section, &options)
                    .expect("fit")
                    .expect("an edge")
            })
        },
    );
    let fitted = fit_faces(&section, &options)
        .expect("fit")
        .expect("an edge");
    let single = fit_ip(
        &section,
        &ordered_profile_normals(&section),
        &FitOptions::new(8, FitMethod::Orthogonal),
    )
    .expect("fit");
    // A part 0.1 mm oversize, in scan order: 4 000 points round it.
    let dense: Vec<Vector2<f64>> = foil.points(4_000).into_iter().map(Vector2::from).collect();
    let normals = ordered_profile_normals(&dense);
    let scan: Vec<Vector2<f64>> = dense
        .iter()
        .zip(&normals)
        .map(|(p, n)| p + n * 0.1)
        .collect();
    let samples = ZeroSetSamples::new(&single.model, &single.domain.scaled(2.0), 512);
    let exact = ExactDistance::new(&single.model, &samples);
    let mut group = c.benchmark_group("distance to a NACA 2412 section");
    group.throughput(Throughput::Elements(scan.len() as u64));
    group.bench_function("faces, exact, point by point", |b| {
        b.iter(|| {
            scan.iter()
                .map(|p| fitted.model.foot(p).map_or(0.0, |f| f.distance))
                .sum::<f64>()
        })
    });
    group.bench_function(
        "one degree-8 polynomial, exact, seeded along the scan",
        |b| {
            b.iter(|| {
                exact
                    .feet_along_scan(&scan)
                    .iter()
                    .map(|f| f.map_or(0.0, |f| f.distance))
                    .sum::<f64>()
            })
        },
    );
    group.bench_function("one degree-8 polynomial, taubin", |b| {
        b.iter(|| {
            scan.iter()
                .map(|p| taubin_distance(&single.model, p).unwrap_or(0.0))
                .sum::<f64>()
        })
    });
    group.finish();
}

criterion_group!(benches, faces);
criterion_main!(benches);
