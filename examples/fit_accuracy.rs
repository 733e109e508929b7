//! The accuracy figures of BENCHMARKS.md: how far the true curve lies from the fitted model, in mm.
//! - profile 3 of seed 003 (its published quartic), 400 points with 2 um noise, refitted at degree 4;
//! - a NACA 2412 section (100 mm chord, sharp trailing edge), 400 points with 2 um noise, at degrees 4 to 10.
//!
//! For each method: the largest and RMS exact distance of the true curve's points to the model, where the
//! largest is, the largest away from the edges (5% to 95% of chord), and the zero-set components near the data.
//!
//!     cargo run --release --example fit_accuracy

use nalgebra::Vector2;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset::geometry::distance::ExactDistance;
use zeroset::geometry::fit3l::{fit_ip, FitMethod, FitOptions, Fitted};
use zeroset::geometry::implicit::Implicit;
use zeroset::geometry::normals::ordered_profile_normals;
use zeroset::geometry::published::seed_003_profile;
use zeroset::geometry::sampling::{project_to_zero_set, ZeroSetSamples};
use zeroset::geometry::trace::{resample_closed, trace_closed_curve};
use zeroset_sim::naca::Naca4;

const METHODS: [FitMethod; 3] = [FitMethod::ThreeL, FitMethod::Ridge, FitMethod::Orthogonal];

/// Points moved along the given normals by seeded Gaussian noise of 2 um.
fn with_noise(points: &[Vector2<f64>], normals: &[Vector2<f64>], seed: u64) -> Vec<Vector2<f64>> {
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, 0.002).expect("sigma");
    points
        .iter()
        .zip(normals)
        .map(|(p, n)| p + n * noise.sample(&mut rng))
        .collect()
}

/// Largest and RMS distance of `truth` to the model, where the largest is, and the largest among `inner`.
fn compare(
    fitted: &Fitted<2>,
    truth: &[Vector2<f64>],
    inner: impl Fn(&Vector2<f64>) -> bool,
) -> String {
    let samples = ZeroSetSamples::new(&fitted.model, &fitted.domain.scaled(2.0), 1024);
    let exact = ExactDistance::new(&fitted.model, &samples);
    let distances: Vec<f64> = exact
        .feet_along_scan(truth)
        .into_iter()
        .map(|f| f.expect("a foot").distance.abs())
        .collect();
    let (worst, at) =
        distances.iter().zip(truth).fold(
            (0.0, truth[0]),
            |w, (d, p)| if *d > w.0 { (*d, *p) } else { w },
        );
    let rms = (distances.iter().map(|d| d * d).sum::<f64>() / distances.len() as f64).sqrt();
    let inner_max = distances
        .iter()
        .zip(truth)
        .filter(|(_, p)| inner(p))
        .map(|(d, _)| *d)
        .fold(0.0, f64::max);
    format!(
        "{:>9.4} | {:>9.4} | ({:7.2}, {:6.2}) | {:>9.4} | {:>2}",
        worst, rms, at.x, at.y, inner_max, fitted.stats.zero_set_components
    )
}

fn main() {
    println!("| section | degree | method | max (mm) | RMS (mm) | max at (mm) | max away from edges (mm) | components |");
    println!("|---|---|---|---|---|---|---|---|");
    let published = seed_003_profile(3).expect("published");
    let start =
        project_to_zero_set(&published, &Vector2::new(100.0, 320.0), 50.0).expect("on the section");
    let truth = trace_closed_curve(&published, &start, 0.05, 1_000_000).expect("closed");
    let clean = resample_closed(&truth, 400);
    let normals: Vec<_> = clean
        .iter()
        .map(|p| published.value_gradient(p).1.normalize())
        .collect();
    let measured = with_noise(&clean, &normals, 3);
    for method in METHODS {
        let fitted = fit_ip(
            &measured,
            &ordered_profile_normals(&measured),
            &FitOptions::new(4, method),
        )
        .expect("fit");
        println!(
            "| seed 003 profile 3 | 4 | {method:?} | {} |",
            compare(&fitted, &truth, |_| true)
        );
    }
    let foil = Naca4::from_digits("2412", 100.0, true).expect("digits");
    let to_vector = |p: &[f64; 2]| Vector2::new(p[0], p[1]);
    let truth: Vec<Vector2<f64>> = foil.points(20_000).iter().map(to_vector).collect();
    let clean: Vec<Vector2<f64>> = foil.points(400).iter().map(to_vector).collect();
    let measured = with_noise(&clean, &ordered_profile_normals(&clean), 2412);
    for degree in [4, 6, 8, 10] {
        for method in METHODS {
            let options = FitOptions::new(degree, method);
            let fitted =
                fit_ip(&measured, &ordered_profile_normals(&measured), &options).expect("fit");
            println!(
                "| NACA 2412 | {degree} | {method:?} | {} |",
                compare(&fitted, &truth, |p| p.x > 5.0 && p.x < 95.0)
            );
        }
    }
}
