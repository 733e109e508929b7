//! How closely a stack model follows its part between its profiles (issue 15, BENCHMARKS.md): the true blade of
//! config/profiles/naca-blade-a-5-profiles.csv (examples/seed003_profiles.rs: NACA 2412 sections with sharp
//! trailing edges, chord 120 mm tapering to 80 mm and twist 30 deg to 15 deg about the quarter chord, linearly
//! from x = 100 to 500 mm) sampled in its five profile planes and in the four planes midway between, 4000
//! cosine-spaced points each, and each model's exact distance to them: the largest and the RMS, in the profiles'
//! planes and midway, and the largest within 1% of chord of the trailing edge.
//!
//!     cargo run --release --example stack_accuracy -- MODEL.json...
//!
//! The models are files `zeroset fit ip --stack` wrote (a polynomial stack, `ip-stack`, or a stack of faces,
//! `ip-faces-stack`).

use std::path::PathBuf;
use std::time::Instant;

use nalgebra::{Vector2, Vector3};
use rayon::prelude::*;
use zeroset::geometry::distance::StackDistance;
use zeroset::geometry::faces::FacedLoft;
use zeroset::geometry::sampling::Aabb;
use zeroset::model_file::{faced_sections, stack_of, ModelFile, ReferenceModel};
use zeroset_sim::naca::Naca4;

const POINTS_PER_SECTION: usize = 4000;

/// The true section at x (mm): its points, and whether each lies within 1% of chord of the trailing edge.
fn true_section(x: f64) -> Vec<(Vector3<f64>, bool)> {
    let t = (x - 100.0) / 400.0;
    let chord = 120.0 - 40.0 * t;
    let (sin, cos) = (30.0 - 15.0 * t).to_radians().sin_cos();
    Naca4::from_digits("2412", chord, true)
        .expect("valid digits")
        .points(POINTS_PER_SECTION)
        .into_iter()
        .map(|p| {
            let (y, z) = (p[0] - 0.25 * chord, p[1]);
            let placed = Vector2::new(cos * y - sin * z, sin * y + cos * z);
            (Vector3::new(x, placed.x, placed.y), p[0] > 0.99 * chord)
        })
        .collect()
}

fn main() {
    let paths: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if paths.is_empty() {
        eprintln!("usage: stack_accuracy MODEL.json...");
        std::process::exit(2);
    }
    let planes: Vec<(f64, bool)> = (0..9)
        .map(|k| (100.0 + 50.0 * k as f64, k % 2 == 0))
        .collect();
    let truth: Vec<(Vector3<f64>, bool, bool)> = planes
        .iter()
        .flat_map(|&(x, in_plane)| {
            true_section(x)
                .into_iter()
                .map(move |(p, at_edge)| (p, at_edge, in_plane))
        })
        .collect();
    println!(
        "{:<40} {:>14} {:>14} {:>14} {:>14} {:>14} {:>8}",
        "model",
        "planes max um",
        "planes RMS um",
        "midway max um",
        "midway RMS um",
        "TE max um",
        "time s"
    );
    for path in paths {
        let file = ModelFile::load(&path).unwrap_or_else(|e| panic!("{e}"));
        let started = Instant::now();
        let distances: Vec<f64> = match &file.model {
            ReferenceModel::Stack { profiles } => {
                let stack = stack_of(profiles).expect("a valid stack");
                let mut sorted = profiles.clone();
                sorted.sort_by(|a, b| a.x.total_cmp(&b.x));
                let domains: Vec<Aabb<2>> = sorted.iter().map(|p| p.fitted.domain).collect();
                let exact = StackDistance::new(&stack, &domains);
                truth
                    .par_iter()
                    .map(|(p, ..)| exact.foot(p).map_or(f64::NAN, |f| f.distance))
                    .collect()
            }
            ReferenceModel::FacesStack { profiles } => {
                let loft = FacedLoft::new(faced_sections(profiles)).expect("a valid loft");
                truth
                    .par_iter()
                    .map(|(p, ..)| loft.foot(p).map_or(f64::NAN, |f| f.distance))
                    .collect()
            }
            _ => panic!("{}: not a stack", path.display()),
        };
        let seconds = started.elapsed().as_secs_f64();
        let summary = |keep: &dyn Fn(bool, bool) -> bool| {
            let chosen: Vec<f64> = truth
                .iter()
                .zip(&distances)
                .filter(|((_, at_edge, in_plane), _)| keep(*at_edge, *in_plane))
                .map(|(_, d)| *d)
                .collect();
            let max = chosen.iter().fold(0.0f64, |m, d| m.max(d.abs()));
            let rms = (chosen.iter().map(|d| d * d).sum::<f64>() / chosen.len() as f64).sqrt();
            (max * 1000.0, rms * 1000.0)
        };
        let (planes_max, planes_rms) = summary(&|_, in_plane| in_plane);
        let (midway_max, midway_rms) = summary(&|_, in_plane| !in_plane);
        let (edge_max, _) = summary(&|at_edge, _| at_edge);
        println!(
            "{:<40} {planes_max:>14.1} {planes_rms:>14.2} {midway_max:>14.1} {midway_rms:>14.2} {edge_max:>14.1} \
             {seconds:>8.2}",
            path.file_name().unwrap().to_string_lossy()
        );
    }
}
