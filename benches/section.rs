//! Evaluation time per section, as the station spends it at each profile's end: the best fits of a 2 000-point
//! section against the master's taught profile (least squares and minimum zone, in one call as the station makes
//! them), and its parameters (chord, thicknesses, camber, chord angle, pitch) beside the nominal's.
//!
//!     cargo bench --bench section
//!
//! The reference is taught once from the demo propeller's master scan (5 profiles of blade A, degree 8 odr); the
//! section is blade A's r300 scanned at 2 000 points with 2 um noise and moved 0.4 mm along z, as blade B lies.

mod demo_propeller;

use criterion::{criterion_group, criterion_main, Criterion, SamplingMode};
use nalgebra::Vector3;
use rand::rngs::StdRng;
use rand::SeedableRng;
use zeroset::analysis::deviation::ProfileGauge;
use zeroset::analysis::reference::{teach, ReferenceSettings};
use zeroset::analysis::section::{best_fits, parameters, BestFitSettings, ScannedSection};
use zeroset::geometry::fit3l::FitMethod;

const POINTS: usize = 2000;
const X_MM: f64 = 300.0;

fn section_evaluation(c: &mut Criterion) {
    let settings = ReferenceSettings::ImplicitPolynomial {
        degree: 8,
        method: FitMethod::Orthogonal,
        nominal_spacing_mm: 2.0,
    };
    let reference =
        teach("propeller", &demo_propeller::master_profiles(), &settings).expect("teach");
    let gauge = ProfileGauge::all(&reference)
        .into_iter()
        .find(|g| g.x_mm() == X_MM)
        .expect("the r300 profile");
    let nominal = gauge
        .nominal_parameters()
        .expect("nominal parameters")
        .clone();
    let mut rng = StdRng::seed_from_u64(300);
    let points: Vec<_> = demo_propeller::section_scan(X_MM, Some(POINTS), &mut rng)
        .points
        .into_iter()
        .map(|p| p + Vector3::new(0.0, 0.0, 0.4))
        .collect();
    // A check that the bench times real work: the fit finds the 0.4 mm move.
    let fits = best_fits(&gauge, &points, &BestFitSettings::default())
        .expect("best fits")
        .fits;
    eprintln!(
        "r300, {POINTS} points moved 0.4 mm along z: l2 shift ({:+.4}, {:+.4}) mm, minzone zone {:.4} mm",
        fits[0].shift_mm[0], fits[0].shift_mm[1], fits[1].form.zone_mm
    );
    // Sampled from the section itself, not rolled round its edge: no sharp-edge contacts.
    let section = ScannedSection {
        points: points.clone(),
        sharp_edge_contacts: Vec::new(),
    };
    let mut group = c.benchmark_group(format!("section r300, {POINTS} points"));
    group.sample_size(20).sampling_mode(SamplingMode::Flat);
    group.bench_function("best fits, l2 and minzone", |b| {
        b.iter(|| best_fits(&gauge, &points, &BestFitSettings::default()).expect("best fits"))
    });
    group.bench_function("parameters", |b| {
        b.iter(|| parameters(&nominal, &section, Some(X_MM)).expect("parameters"))
    });
    group.finish();
}

criterion_group!(benches, section_evaluation);
criterion_main!(benches);
