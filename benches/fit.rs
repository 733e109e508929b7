//! Fit time for 10 000 points: a 2-D profile at degree 4 and a 3-D surface at degree 6, by each method.
//!
//!     cargo bench --bench fit

mod data;

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::Vector3;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::time::Duration;
use zeroset::geometry::fit3l::{fit_ip, FitMethod, FitOptions};
use zeroset::geometry::normals::{ordered_profile_normals, pca_normals};

/// `count` points on r(theta, phi) = 50 (1 + 0.1 sin 3 theta cos 2 phi) mm, with 2 um noise along the radius.
pub fn blob(count: usize) -> Vec<Vector3<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(6);
    let noise = Normal::new(0.0, 0.002).expect("sigma");
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let theta = z.acos();
            let phi = golden * i as f64;
            let r = 50.0 * (1.0 + 0.1 * (3.0 * theta).sin() * (2.0 * phi).cos())
                + noise.sample(&mut rng);
            Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), z) * r
        })
        .collect()
}

fn fits(c: &mut Criterion) {
    let profile = data::profile_3_scan(10_000, 0.0);
    let profile_normals = ordered_profile_normals(&profile);
    let surface = blob(10_000);
    let surface_normals = pca_normals(&surface);
    let mut group = c.benchmark_group("fit 10 000 points");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(20));
    for method in [FitMethod::ThreeL, FitMethod::Ridge, FitMethod::Orthogonal] {
        let options = FitOptions::new(4, method);
        group.bench_function(format!("2-D degree 4, {method:?}"), |b| {
            b.iter(|| fit_ip(&profile, &profile_normals, &options).expect("fit"))
        });
    }
    for method in [FitMethod::Ridge, FitMethod::Orthogonal] {
        let options = FitOptions::new(6, method);
        group.bench_function(format!("3-D degree 6, {method:?}"), |b| {
            b.iter(|| fit_ip(&surface, &surface_normals, &options).expect("fit"))
        });
    }
    group.finish();
}

criterion_group!(benches, fits);
criterion_main!(benches);
