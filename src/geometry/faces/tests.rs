use nalgebra::Vector2;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset_sim::naca::Naca4;

use super::*;
use crate::geometry::fit3l::FitMethod;

/// A NACA 4-digit section with a sharp trailing edge: `count` points round it with seeded noise of `sigma` mm
/// along the normal, and the noise-free section densely (to 0.1 um) for the truth.
pub(super) fn naca(
    digits: &str,
    chord: f64,
    count: usize,
    sigma: f64,
    seed: u64,
) -> Vec<Vector2<f64>> {
    let foil = Naca4::from_digits(digits, chord, true).unwrap();
    let clean: Vec<Vector2<f64>> = foil.points(count).into_iter().map(Vector2::from).collect();
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, sigma).unwrap();
    let n = clean.len();
    (0..n)
        .map(|i| {
            let tangent = clean[(i + 1) % n] - clean[(i + n - 1) % n];
            let normal = Vector2::new(tangent.y, -tangent.x).normalize();
            clean[i] + normal * noise.sample(&mut rng)
        })
        .collect()
}

/// The true section densely: points 1e-5 of the parameter apart round it (0.1 um and less near the edges).
pub(super) fn truth(digits: &str, chord: f64, count: usize) -> Vec<Vector2<f64>> {
    let foil = Naca4::from_digits(digits, chord, true).unwrap();
    foil.points(count).into_iter().map(Vector2::from).collect()
}

#[test]
fn a_naca_2412_with_a_sharp_trailing_edge_is_followed_to_its_edge() {
    let points = naca("2412", 100.0, 400, 0.002, 1);
    let fitted = fit_faces(
        &points,
        &FacesFitOptions {
            degree: None,
            method: FitMethod::Orthogonal,
        },
    )
    .unwrap()
    .expect("a sharp trailing edge");
    let (worst, at) = truth("2412", 100.0, 20_000)
        .iter()
        .map(|p| (fitted.model.foot(p).unwrap().distance.abs(), *p))
        .fold(
            (0.0, Vector2::zeros()),
            |a, b| if b.0 > a.0 { b } else { a },
        );
    eprintln!("at {at:?} joins {:?}", fitted.model.joins());
    let edge = Vector2::from(fitted.model.joins()[1].point);
    eprintln!("worst {worst} edge {edge:?} held out {:?}", fitted.held_out);
    assert!(worst < 0.005, "{worst}");
}
