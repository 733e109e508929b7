//! Fit time: a 2-D profile (seed 003 profile 3, 2 um noise) at degree 4 by each method at 1 000, 10 000 and
//! 100 000 points; a 3-D surface of 10 000 points at degree 6; teaching the demo propeller (5 profiles of blade A,
//! every candidate fit); and, in the same run, the peers of benches/peers/fit_peer.py timed as whole processes
//! (numpy's 3L least squares and scipy's orthogonal-distance fit, 100 000 points of the same profile).
//!
//!     cargo bench --bench fit
//!
//! The peers need python3 with numpy and scipy; without them their entries are skipped with a message.

mod data;
mod demo_propeller;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode};
use nalgebra::{Vector2, Vector3};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset::analysis::reference::{teach, ReferenceSettings};
use zeroset::geometry::fit3l::{fit_ip, FitMethod, FitOptions};
use zeroset::geometry::normals::{ordered_profile_normals, pca_normals};

/// `count` points on r(theta, phi) = 50 (1 + 0.1 sin 3 theta cos 2 phi) mm, with 2 um noise along the radius.
fn blob(count: usize) -> Vec<Vector3<f64>> {
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

/// Writes y,z,ny,nz rows for the peers.
fn write_peer_input(path: &Path, points: &[Vector2<f64>], normals: &[Vector2<f64>]) {
    let mut file = std::io::BufWriter::new(std::fs::File::create(path).expect("peer input"));
    for (p, n) in points.iter().zip(normals) {
        writeln!(file, "{:.17e},{:.17e},{:.17e},{:.17e}", p.x, p.y, n.x, n.y).expect("write");
    }
}

fn peer(kind: &str, input: &Path) -> Option<Command> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/peers/fit_peer.py");
    let probe = Command::new("python3")
        .args(["-c", "import numpy, scipy"])
        .output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!("python3 with numpy and scipy not found: the {kind} peer is skipped");
        return None;
    }
    let mut command = Command::new("python3");
    command.arg(script).arg(kind).arg(input);
    Some(command)
}

fn run_peer(command: &mut Command) -> String {
    let out = command.output().expect("python3 runs");
    assert!(
        out.status.success(),
        "peer failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).trim().to_string()
}

fn profile_fits(c: &mut Criterion) {
    let input = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("fit_peer_100000.csv");
    for method in [FitMethod::ThreeL, FitMethod::Ridge, FitMethod::Orthogonal] {
        let mut group = c.benchmark_group(format!("2-D degree 4, {method:?}"));
        group.sample_size(10).sampling_mode(SamplingMode::Flat);
        for count in [1_000, 10_000, 100_000] {
            let profile = data::profile_3_scan(count, 0.0);
            let normals = ordered_profile_normals(&profile);
            let options = FitOptions::new(4, method);
            let fitted = fit_ip(&profile, &normals, &options).expect("fit");
            eprintln!(
                "{method:?} {count}: RMS {:.6} mm, max {:.6} mm",
                fitted.stats.rms_distance_mm, fitted.stats.max_distance_mm
            );
            if count == 100_000 && method == FitMethod::ThreeL {
                write_peer_input(&input, &profile, &normals);
            }
            group.bench_with_input(BenchmarkId::from_parameter(count), &count, |b, _| {
                b.iter(|| fit_ip(&profile, &normals, &options).expect("fit"))
            });
        }
        group.finish();
    }
    let mut group = c.benchmark_group("peers, 100 000 points, whole process");
    group
        .sample_size(10)
        .sampling_mode(SamplingMode::Flat)
        .measurement_time(Duration::from_secs(1));
    for (kind, name) in [("3l", "numpy 3L lstsq"), ("odr", "scipy.odr implicit")] {
        let Some(mut command) = peer(kind, &input) else {
            continue;
        };
        eprintln!("{name}: {}", run_peer(&mut command));
        group.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let started = Instant::now();
                for _ in 0..iters {
                    run_peer(&mut command);
                }
                started.elapsed()
            })
        });
    }
    group.finish();
}

fn surface_fits(c: &mut Criterion) {
    let surface = blob(10_000);
    let normals = pca_normals(&surface);
    let mut group = c.benchmark_group("3-D degree 6, 10 000 points");
    group.sample_size(10).sampling_mode(SamplingMode::Flat);
    for method in [FitMethod::ThreeL, FitMethod::Ridge, FitMethod::Orthogonal] {
        let options = FitOptions::new(6, method);
        group.bench_function(format!("{method:?}"), |b| {
            b.iter(|| fit_ip(&surface, &normals, &options).expect("fit"))
        });
    }
    group.finish();
}

fn teach_fits(c: &mut Criterion) {
    let profiles = demo_propeller::master_profiles();
    let settings = ReferenceSettings::ImplicitPolynomial {
        degree: 8,
        method: FitMethod::Orthogonal,
        nominal_spacing_mm: 2.0,
    };
    let points: usize = profiles.iter().map(|p| p.points.len()).sum();
    let mut group = c.benchmark_group("teach");
    group.sample_size(10).sampling_mode(SamplingMode::Flat);
    group.bench_function(
        format!("demo propeller, 5 profiles, {points} points, degree 8 odr"),
        |b| b.iter(|| teach("propeller", &profiles, &settings).expect("teach")),
    );
    group.finish();
}

criterion_group!(benches, profile_fits, surface_fits, teach_fits);
criterion_main!(benches);
