//! The faced model on NACA 4-digit sections drawn at random (BENCHMARKS.md, issue 15, stop 53): camber 0-9 % at
//! 20-60 % of chord, thickness 6-24 %, chord 30-400 mm, 200-1000 points with 0.5-3 um of Gaussian noise along the
//! normal, a sharp trailing edge. Each is fitted face by face as `fit ip` does, and again with no face split where
//! its polynomial does not follow it; printed: the faces' degrees, the largest distance of the true section (20 000
//! points) to each model and where along the chord it lies, and the fit's time.
//!
//!     cargo run --release --example faces_sweep [-- CASES [SEED]]

use std::time::Instant;

use nalgebra::Vector2;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};
use zeroset::geometry::faces::{fit_faces, FacesFitOptions, FittedFaces};
use zeroset::geometry::fit3l::FitMethod;
use zeroset::geometry::normals::ordered_profile_normals;
use zeroset_sim::naca::Naca4;

/// The largest distance (mm) of the true section to the model, and where it lies as a fraction of chord.
fn worst(fitted: &FittedFaces, truth: &[Vector2<f64>], chord: f64) -> (f64, f64) {
    truth
        .iter()
        .map(|q| {
            let d = fitted
                .model
                .foot(q)
                .map_or(f64::INFINITY, |f| f.distance.abs());
            (d, q.x / chord)
        })
        .fold((0.0, 0.0), |w, d| if d.0 > w.0 { d } else { w })
}

fn main() {
    let cases: usize = std::env::args()
        .nth(1)
        .map_or(60, |a| a.parse().expect("a number of cases"));
    let seed: u64 = std::env::args()
        .nth(2)
        .map_or(77, |a| a.parse().expect("a seed"));
    let mut draw = rand::rngs::StdRng::seed_from_u64(seed);
    println!("| case | section | chord (mm) | points | sigma (um) | faces' degrees | max (um), at x/c | none split: max (um), at x/c | fit (s) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for case in 0..cases {
        let camber = draw.gen_range(0..=9);
        let position = if camber == 0 {
            0
        } else {
            draw.gen_range(2..=6)
        };
        let thickness = draw.gen_range(6..=24);
        let digits = format!("{camber}{position}{thickness:02}");
        let chord = [30.0, 60.0, 100.0, 180.0, 250.0, 400.0][draw.gen_range(0..6)];
        let count = [200, 300, 400, 600, 1000][draw.gen_range(0..5)];
        let sigma = [0.0005, 0.001, 0.002, 0.003][draw.gen_range(0..4)];
        let foil = Naca4::from_digits(&digits, chord, true).expect("digits");
        let truth: Vec<Vector2<f64>> = foil.points(20_000).into_iter().map(Vector2::from).collect();
        let clean: Vec<Vector2<f64>> = foil.points(count).into_iter().map(Vector2::from).collect();
        let normals = ordered_profile_normals(&clean);
        let mut rng = rand::rngs::StdRng::seed_from_u64(case as u64);
        let noise = Normal::new(0.0, sigma).expect("sigma");
        let measured: Vec<Vector2<f64>> = clean
            .iter()
            .zip(&normals)
            .map(|(p, n)| p + n * noise.sample(&mut rng))
            .collect();
        let options = FacesFitOptions {
            degree: None,
            method: FitMethod::Orthogonal,
            split_unfollowed: true,
        };
        let started = Instant::now();
        let fitted = fit_faces(&measured, &options);
        let seconds = started.elapsed().as_secs_f64();
        let unsplit = fit_faces(
            &measured,
            &FacesFitOptions {
                split_unfollowed: false,
                ..options
            },
        );
        let row = match (fitted, unsplit) {
            (Ok(Some(fitted)), Ok(Some(unsplit))) => {
                let degrees: Vec<String> = fitted
                    .faces
                    .iter()
                    .map(|f| f.model.degree().to_string())
                    .collect();
                let (split_mm, split_at) = worst(&fitted, &truth, chord);
                let (none_mm, none_at) = worst(&unsplit, &truth, chord);
                format!(
                    "{} | {:.2}, {:.3} | {:.2}, {:.3} | {seconds:.2}",
                    degrees.join("+"),
                    split_mm * 1000.0,
                    split_at,
                    none_mm * 1000.0,
                    none_at
                )
            }
            (fitted, unsplit) => format!(
                "fit: {:?} | none split: {:?} | | |",
                fitted.map(|f| f.map(|f| f.faces.len())),
                unsplit.map(|f| f.map(|f| f.faces.len()))
            ),
        };
        println!(
            "| {case} | NACA {digits} | {chord} | {count} | {} | {row} |",
            sigma * 1000.0
        );
    }
}
