//! Writes the example data in config/:
//! - from the quartic that seed 003 publishes for profile 3 of blade A (the only one of the three printed quartics
//!   whose zero set is a closed curve; those of profiles 1 and 5 open out beyond the measured arcs): the model as a
//!   model file, and simulated scans of profile 3 of blades A, B and C (B 0.8 mm inside A along the normal, C as
//!   far outside, as the paper reports);
//! - a twisted, tapering blade of NACA 2412 sections (the simulator's ground truth) scanned in five parallel
//!   planes x = 100 ... 500 mm, for blades A, B and C (B below A by 0.4 mm at the root growing to 1.0 mm at the
//!   tip, C above by as much), to fit a profile stack. "Below" is a shift along -z: an offset along the normal
//!   cannot exceed half the thickness of a trailing edge without passing through it.
//!
//! Every scan has 2 um of seeded Gaussian probe noise along the normal.
//!
//!     cargo run --release --example seed003_profiles
//!
//! The files are committed; this program documents and reproduces them.

use std::path::Path;

use nalgebra::Vector2;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset::geometry::implicit::{Implicit, IpModel};
use zeroset::geometry::published::seed_003_profile;
use zeroset::geometry::sampling::{Aabb, ZeroSetSamples};
use zeroset::geometry::trace::{resample_closed, trace_closed_curve};
use zeroset::model_file::{FittedIp, ModelFile, ReferenceModel};
use zeroset_sim::naca::Naca4;

const POINTS_PER_PROFILE: usize = 400;
const NOISE_MM: f64 = 0.002;
/// Profile k lies at x = 100 k mm: the paper's profiles are 10 cm apart.
const PROFILE_SPACING_MM: f64 = 100.0;

/// The longest closed curve of the model's zero set near the origin: the blade section (the published quartics
/// also have small spurious branches nearby).
fn main_section(model: &IpModel<2>) -> Vec<Vector2<f64>> {
    let bounds = Aabb {
        min: Vector2::new(-600.0, -600.0),
        max: Vector2::new(600.0, 600.0),
    };
    let samples = ZeroSetSamples::new(model, &bounds, 600);
    samples
        .points()
        .iter()
        .step_by(25)
        .filter_map(|start| trace_closed_curve(model, start, 0.05, 200_000).ok())
        .max_by_key(|curve| curve.len())
        .expect("the published quartics have a closed section")
}

fn scan(model: &IpModel<2>, section: &[Vector2<f64>], offset: f64, seed: u64) -> Vec<Vector2<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, NOISE_MM).expect("valid sigma");
    resample_closed(section, POINTS_PER_PROFILE)
        .into_iter()
        .map(|p| p + model.value_gradient(&p).1.normalize() * (offset + noise.sample(&mut rng)))
        .collect()
}

fn write_csv(path: &Path, header: &str, rows: impl Iterator<Item = String>) {
    let mut text = format!("{header}\n");
    for row in rows {
        text.push_str(&row);
        text.push('\n');
    }
    std::fs::write(path, text).unwrap_or_else(|e| panic!("cannot write {}: {e}", path.display()));
    println!("wrote {}", path.display());
}

/// The blade section at profile plane `k` (0..5): chord 120 mm at the root tapering to 80 mm, twisted from 30
/// to 15 degrees, pitched about the quarter chord; `count` points with their outward normals.
fn naca_section(k: usize, count: usize) -> Vec<(Vector2<f64>, Vector2<f64>)> {
    let t = k as f64 / 4.0;
    let chord = 120.0 - 40.0 * t;
    let twist = (30.0 - 15.0 * t).to_radians();
    let foil = Naca4::from_digits("2412", chord, true).expect("valid digits");
    let (sin, cos) = twist.sin_cos();
    let place = |p: [f64; 2]| {
        let (y, z) = (p[0] - 0.25 * chord, p[1]);
        Vector2::new(cos * y - sin * z, sin * y + cos * z)
    };
    (0..count)
        .map(|i| {
            let s = i as f64 / count as f64;
            let ds = 1e-6;
            let p = place(foil.point(s));
            // The section runs counter-clockwise (trailing edge, upper surface, leading edge, lower surface): the
            // outward normal is the tangent turned clockwise.
            let tangent = place(foil.point(s + ds)) - place(foil.point((s - ds).rem_euclid(1.0)));
            (p, Vector2::new(tangent.y, -tangent.x).normalize())
        })
        .collect()
}

fn main() {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
    std::fs::create_dir_all(config.join("profiles")).expect("config/profiles");
    std::fs::create_dir_all(config.join("models")).expect("config/models");
    let model = seed_003_profile(3).expect("published profile");
    let section = main_section(&model);
    for (blade, offset) in [("a", 0.0), ("b", -0.8), ("c", 0.8)] {
        let points = scan(&model, &section, offset, blade.as_bytes()[0] as u64);
        write_csv(
            &config.join(format!("profiles/seed003-profile3-blade-{blade}.csv")),
            "y,z",
            points.iter().map(|p| format!("{:.5},{:.5}", p.x, p.y)),
        );
    }
    let file = ModelFile::new(
        "published in seed 003 (Wolovich, Albakri, Yalcin), profile 3 of blade A, converted from cm",
        ReferenceModel::Profile(FittedIp {
            ip: model.clone(),
            domain: Aabb::of_points(&section).expect("points"),
            fit: None,
        }),
    );
    let path = config.join("models/seed003-profile3.json");
    file.save(&path).expect("model file");
    println!("wrote {}", path.display());

    for (blade, sign) in [("a", 0.0), ("b", -1.0), ("c", 1.0)] {
        let mut rng = rand::rngs::StdRng::seed_from_u64(blade.as_bytes()[0] as u64 + 100);
        let noise = Normal::new(0.0, NOISE_MM).expect("valid sigma");
        let mut rows = Vec::new();
        for k in 0..5 {
            let x = PROFILE_SPACING_MM * (k + 1) as f64;
            let shift = Vector2::new(0.0, sign * (0.4 + 0.6 * k as f64 / 4.0));
            for (p, n) in naca_section(k, POINTS_PER_PROFILE) {
                let q = p + shift + n * noise.sample(&mut rng);
                rows.push(format!("{x:.1},{:.5},{:.5}", q.x, q.y));
            }
        }
        write_csv(
            &config.join(format!("profiles/naca-blade-{blade}-5-profiles.csv")),
            "x,y,z",
            rows.into_iter(),
        );
    }
}
