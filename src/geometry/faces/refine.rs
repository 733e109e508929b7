//! Whether a face's polynomial follows the face's points, and where to split the face when it does not: a
//! profile's curvature can change at once (a NACA 4-digit camber line's second derivative jumps at its maximum),
//! which no polynomial of the degrees tried follows over a whole face. Measured on NACA sections whose camber line
//! bends hard (BENCHMARKS.md, issue 15, stop 53): NACA 9322 at 250 mm missed by up to 23 um as three faces.

use nalgebra::Vector2;

use super::split::{own_span, FacePoints};
use crate::geometry::implicit::{Implicit, IpModel};

/// A face its polynomial follows leaves no run of [`MISS_WINDOW`] neighbouring points whose mean residual is more
/// than this many times what the noise alone gives such a mean. Where the polynomial follows, the largest such
/// mean on NACA sections under 2 um of noise was 3.1 times it (60 faces); 3.5 split faces that were followed
/// and made NACA 3211 and 8406 at 250 mm worse.
const MISS_SIGMAS: f64 = 4.5;
/// The run of neighbouring points whose mean residual shows a miss: long enough to average the noise down by 3,
/// short enough to stay within one lobe of the polynomial's miss round a change of curvature.
const MISS_WINDOW: usize = 9;
/// A mean miss smaller than this (mm) is not worth a joint, however small the noise.
const MISS_FLOOR_MM: f64 = 2.5e-4;
/// A point bending more than this many times its face's median curvature is on a nose, where no joint goes (the
/// faces either side of a joint there part by more than on a flat).
const NOSE_BENDING: f64 = 3.0;
/// A face is split only into halves of at least this many of its own points each.
const MIN_SPLIT_POINTS: usize = 25;

/// Where to split a face (of `points`) whose fitted polynomial `model` does not follow its points: the position
/// in `face.indices` nearest the middle of its own span, within its middle half and off any nose, both halves
/// keeping [`MIN_SPLIT_POINTS`] points. `None` when the polynomial follows the points, or the face is too short to
/// split.
///
/// Whether it follows is read from the points alone: a miss is smooth along the face, so the mean residual over
/// a run of neighbours keeps it while averaging the noise down; the noise is read from the differences of
/// neighbours' residuals, from which a smooth miss cancels.
pub(super) fn joint_for_unfollowed(
    points: &[Vector2<f64>],
    face: &FacePoints,
    model: &IpModel<2>,
) -> Option<usize> {
    let (first, last) = own_span(face);
    if last < first + 2 * MIN_SPLIT_POINTS {
        return None;
    }
    let residuals: Vec<f64> = face
        .indices
        .iter()
        .map(|&i| {
            let (value, gradient) = model.value_gradient(&points[i]);
            value / gradient.norm()
        })
        .collect();
    if largest_local_miss(&residuals) <= MISS_FLOOR_MM.max(MISS_SIGMAS * miss_noise(&residuals)) {
        return None;
    }
    let at = |k: usize| points[face.indices[k]];
    let mut along = vec![0.0; last + 1];
    for k in first + 1..=last {
        along[k] = along[k - 1] + (at(k) - at(k - 1)).norm();
    }
    let length = along[last];
    let bending: Vec<f64> = (first..=last).map(|k| curvature(model, &at(k))).collect();
    let mut sorted = bending.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let from_middle = |k: usize| (along[k] - 0.5 * length).abs();
    (first + MIN_SPLIT_POINTS..=last - MIN_SPLIT_POINTS)
        .filter(|&k| from_middle(k) <= 0.25 * length)
        .filter(|&k| bending[k - first] <= NOSE_BENDING * median)
        .min_by(|&a, &b| from_middle(a).total_cmp(&from_middle(b)))
}

/// The largest mean of [`MISS_WINDOW`] neighbouring residuals, mm.
fn largest_local_miss(residuals: &[f64]) -> f64 {
    residuals
        .windows(MISS_WINDOW)
        .map(|run| (run.iter().sum::<f64>() / MISS_WINDOW as f64).abs())
        .fold(0.0, f64::max)
}

/// The standard deviation (mm) the noise alone gives a mean of [`MISS_WINDOW`] residuals: the noise's, read from
/// neighbours' differences (each holds two draws of it), over the root of the window.
fn miss_noise(residuals: &[f64]) -> f64 {
    let differences: f64 = residuals.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
    let noise = (differences / (2.0 * (residuals.len() as f64 - 1.0))).sqrt();
    noise / (MISS_WINDOW as f64).sqrt()
}

/// The unsigned curvature (1/mm) of a model's level curve through `p`.
fn curvature(model: &IpModel<2>, p: &Vector2<f64>) -> f64 {
    let (_, gradient, hessian) = model.value_gradient_hessian(p);
    let tangent = Vector2::new(-gradient.y, gradient.x);
    tangent.dot(&(hessian * tangent)).abs() / gradient.norm().powi(3)
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    use super::*;

    #[test]
    fn a_smooth_miss_shows_through_noise_that_hides_it_point_by_point() {
        // A bump of 4 um over 40 points (the polynomial's miss) under 2 um of noise: no point stands out, the runs'
        // means do, at about 4 / (2 / 3) = 6 times their noise.
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        let noise = Normal::new(0.0, 0.002).unwrap();
        let bump = |k: usize| {
            let t = (k as f64 - 100.0) / 20.0;
            if t.abs() < 1.0 {
                0.004 * (1.0 - t * t)
            } else {
                0.0
            }
        };
        let noisy: Vec<f64> = (0..200).map(|_| noise.sample(&mut rng)).collect();
        let missed: Vec<f64> = noisy.iter().enumerate().map(|(k, r)| r + bump(k)).collect();
        for residuals in [&noisy, &missed] {
            let noise = miss_noise(residuals) * (MISS_WINDOW as f64).sqrt();
            assert!((noise - 0.002).abs() < 3e-4, "noise read {noise} mm");
        }
        let z = |r: &[f64]| largest_local_miss(r) / miss_noise(r);
        assert!(z(&noisy) < MISS_SIGMAS, "noise alone: {}", z(&noisy));
        assert!(z(&missed) > MISS_SIGMAS + 0.5, "the miss: {}", z(&missed));
    }

    #[test]
    fn noise_alone_rarely_reads_as_a_miss() {
        // 200 seeded runs of 200 residuals of pure noise: the runs' means stay below the limit in nearly all.
        let noise = Normal::new(0.0, 0.002).unwrap();
        let over = (0..200u64)
            .filter(|&seed| {
                let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
                let r: Vec<f64> = (0..200).map(|_| noise.sample(&mut rng)).collect();
                largest_local_miss(&r) > MISS_SIGMAS * miss_noise(&r)
            })
            .count();
        assert!(over <= 4, "{over} of 200 noise runs read as a miss");
    }
}
