//! A polynomial's degree chosen by points held out of its fit. A fit's own residual always falls as the degree
//! rises (a higher degree also follows the noise); the distance of points it was not fitted to stops falling once
//! the shape is followed, and that is the degree the data supports.

use nalgebra::SVector;

use crate::geometry::fit3l::{fit_ip, FitMethod, FitOptions};
use crate::geometry::implicit::Implicit;

/// The degrees chosen from when none is given.
pub(crate) const CANDIDATE_DEGREES: [usize; 3] = [4, 6, 8];
/// A higher degree replaces the one chosen so far only when its held-out RMS is below this fraction of that one's:
/// noise alone moves a held-out RMS by a few percent.
const HIGHER_DEGREE_GAIN: f64 = 0.9;

/// The degree by held-out RMS (`scores`: each degree tried with its held-out RMS, lowest degree first): from the
/// lowest up, each higher degree replaces the one chosen so far only if it beats it by more than noise does
/// ([`HIGHER_DEGREE_GAIN`]).
pub(crate) fn choose_degree(scores: &[(usize, f64)]) -> usize {
    let mut chosen = scores
        .first()
        .copied()
        .unwrap_or((CANDIDATE_DEGREES[0], 0.0));
    for &(degree, rms) in &scores[1.min(scores.len())..] {
        if rms < HIGHER_DEGREE_GAIN * chosen.1 {
            chosen = (degree, rms);
        }
    }
    chosen.0
}

/// The degrees to try in turn: `chosen` first, then the others of `scores` by their held-out RMS, best first (a
/// fit of the chosen degree can still fail a check the held-out RMS does not make).
pub(crate) fn degrees_to_try(chosen: usize, scores: &[(usize, f64)]) -> Vec<usize> {
    let mut others = scores.to_vec();
    others.sort_by(|a, b| a.1.total_cmp(&b.1));
    std::iter::once(chosen)
        .chain(others.into_iter().map(|(d, _)| d).filter(|d| *d != chosen))
        .collect()
}

/// The fit to keep once a degree is chosen: the chosen degree's where it is clean (`defects` finds none of the
/// defects a fit's statistics show), else the first clean one of the other degrees, best held-out first; where none
/// is, the chosen degree's own result (its fit, whose defects its statistics report, or its error). With it, why
/// the chosen degree's fit was passed over ("fails (...)" or what `defects` said), when another is kept.
pub(crate) fn clean_fit_or_chosen<T, E: std::fmt::Display>(
    chosen: usize,
    scores: &[(usize, f64)],
    mut fit: impl FnMut(usize) -> Result<T, E>,
    defects: impl Fn(&T) -> Option<String>,
) -> (Result<T, E>, Option<String>) {
    let first = fit(chosen);
    let passed_over = match &first {
        Ok(fitted) => defects(fitted),
        Err(e) => Some(format!("fails ({e})")),
    };
    if passed_over.is_none() {
        return (first, None);
    }
    let other = degrees_to_try(chosen, scores)[1..]
        .iter()
        .find_map(|&degree| fit(degree).ok().filter(|f| defects(f).is_none()));
    match other {
        Some(other) => (Ok(other), passed_over),
        None => (first, None),
    }
}

/// RMS first-order distance |F| / |grad F| of points to a model, mm: the held-out points lie within the noise of
/// the model, where the first-order distance is exact to second order.
pub(crate) fn rms_distance<const N: usize>(
    model: &impl Implicit<N>,
    points: &[SVector<f64, N>],
) -> f64 {
    let sum: f64 = points
        .iter()
        .map(|p| {
            let (v, g) = model.value_gradient(p);
            (v / g.norm()).powi(2)
        })
        .sum();
    (sum / points.len() as f64).sqrt()
}

/// The held-out RMS (mm) of each of [`CANDIDATE_DEGREES`] for one polynomial through points with their normals (a
/// profile's, running along it, or a surface's): each degree fitted to every other point, judged by the points
/// between. A degree whose fit fails is left out.
pub(crate) fn held_out_scores<const N: usize>(
    points: &[SVector<f64, N>],
    normals: &[SVector<f64, N>],
    method: FitMethod,
) -> Vec<(usize, f64)> {
    let (trained, trained_normals): (Vec<_>, Vec<_>) =
        points.iter().zip(normals).step_by(2).unzip();
    let judged: Vec<SVector<f64, N>> = points.iter().skip(1).step_by(2).copied().collect();
    CANDIDATE_DEGREES
        .into_iter()
        .filter_map(|degree| {
            let fitted =
                fit_ip(&trained, &trained_normals, &FitOptions::new(degree, method)).ok()?;
            Some((degree, rms_distance(&fitted.model, &judged)))
        })
        .collect()
}

/// The held-out RMS (mm) of each degree over several profiles fitted at one degree (a stack's: its profiles blend
/// only at equal degrees), from each profile's points held out and [`held_out_scores`]: the root of the mean
/// square over every held-out point, so each profile weighs by its points. A degree that some profile could not
/// be fitted at is left out.
pub(crate) fn combined_scores(profiles: &[(usize, Vec<(usize, f64)>)]) -> Vec<(usize, f64)> {
    CANDIDATE_DEGREES
        .into_iter()
        .filter_map(|degree| {
            let (squares, points) =
                profiles
                    .iter()
                    .try_fold((0.0, 0usize), |(squares, points), (count, scores)| {
                        let rms = scores.iter().find(|s| s.0 == degree)?.1;
                        Some((squares + rms * rms * *count as f64, points + count))
                    })?;
            (points > 0).then(|| (degree, (squares / points as f64).sqrt()))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::normals::ordered_profile_normals;
    use crate::geometry::trace::{resample_closed, trace_closed_curve};
    use nalgebra::Vector2;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// `count` points along a closed curve, each moved along its normal by seeded Gaussian noise of 2 um.
    fn noisy(curve: &[Vector2<f64>], count: usize, seed: u64) -> Vec<Vector2<f64>> {
        let clean = resample_closed(curve, count);
        let normals = ordered_profile_normals(&clean);
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let noise = Normal::new(0.0, 0.002).unwrap();
        clean
            .iter()
            .zip(&normals)
            .map(|(p, n)| p + n * noise.sample(&mut rng))
            .collect()
    }

    #[test]
    fn the_chosen_degree_is_tried_first_and_then_the_others_best_held_out_first() {
        let scores = [(4, 0.005), (6, 0.0021), (8, 0.0020)];
        assert_eq!(choose_degree(&scores), 6);
        assert_eq!(degrees_to_try(6, &scores), vec![6, 8, 4]);
        assert_eq!(degrees_to_try(4, &[]), vec![4]);
    }

    #[test]
    fn the_chosen_degree_is_kept_where_clean_else_the_best_clean_other_else_its_own_result() {
        let scores = [(4, 0.005), (6, 0.002), (8, 0.003)];
        // A fit stands for its degree; `clean` and the errors are given per degree.
        let keep = |clean: &[usize], failing: &[usize]| {
            let mut tried = Vec::new();
            let (kept, passed_over) = clean_fit_or_chosen(
                6,
                &scores,
                |degree| {
                    tried.push(degree);
                    if failing.contains(&degree) {
                        Err(format!("degree {degree} failed"))
                    } else {
                        Ok(degree)
                    }
                },
                |degree| (!clean.contains(degree)).then(|| format!("fits degree {degree} badly")),
            );
            (kept, passed_over, tried)
        };
        let said = |text: &str| Some(text.to_string());
        assert_eq!(keep(&[4, 6, 8], &[]), (Ok(6), None, vec![6]));
        // Unclean: the others best held-out first (8 before 4), the first clean one kept, and why 6 was not.
        assert_eq!(
            keep(&[4, 8], &[]),
            (Ok(8), said("fits degree 6 badly"), vec![6, 8])
        );
        assert_eq!(
            keep(&[4], &[8]),
            (Ok(4), said("fits degree 6 badly"), vec![6, 8, 4])
        );
        // The chosen one failing does not end the search.
        assert_eq!(
            keep(&[4], &[6]),
            (Ok(4), said("fails (degree 6 failed)"), vec![6, 8, 4])
        );
        // No degree clean: the chosen one's fit, or its error, with nothing passed over.
        assert_eq!(keep(&[], &[]), (Ok(6), None, vec![6, 8, 4]));
        assert_eq!(
            keep(&[], &[6]),
            (Err("degree 6 failed".to_string()), None, vec![6, 8, 4])
        );
    }

    #[test]
    fn a_stack_s_scores_weigh_each_profile_by_its_points_and_drop_a_degree_one_profile_lacks() {
        // 100 held-out points at 3 um and 300 at 1 um: sqrt((100 * 9 + 300 * 1) / 400) = sqrt(3) um at degree 4.
        let profiles = [
            (100, vec![(4, 0.003), (6, 0.002), (8, 0.002)]),
            (300, vec![(4, 0.001), (6, 0.001)]),
        ];
        let combined = combined_scores(&profiles);
        assert_eq!(combined.len(), 2, "degree 8 is missing from one profile");
        assert_eq!(combined[0].0, 4);
        assert!((combined[0].1 - 3f64.sqrt() * 1e-3).abs() < 1e-15);
        assert_eq!(combined[1].0, 6);
        assert!((combined[1].1 - 1.75f64.sqrt() * 1e-3).abs() < 1e-15);
        assert!(combined_scores(&[]).is_empty());
    }

    #[test]
    fn a_quartic_profile_keeps_degree_4_and_a_shape_a_quartic_cannot_follow_takes_a_higher_one() {
        // Seed 003's profile 3 is a quartic: higher degrees only follow the noise, and do not beat it by 10% on
        // the points held out. A stadium (a 40 by 10 mm slot: straight sides between half circles) bends at its
        // tangent points in a way no quartic follows: its held-out RMS at degree 4 is many times the noise.
        let quartic = crate::geometry::published::seed_003_profile(3).unwrap();
        let start = crate::geometry::sampling::project_to_zero_set(
            &quartic,
            &Vector2::new(100.0, 320.0),
            50.0,
        )
        .unwrap();
        let curve = trace_closed_curve(&quartic, &start, 0.05, 1_000_000).unwrap();
        for seed in [1, 2, 3] {
            let points = noisy(&curve, 400, seed);
            let normals = ordered_profile_normals(&points);
            let scores = held_out_scores(&points, &normals, FitMethod::default());
            assert_eq!(choose_degree(&scores), 4, "seed {seed}: {scores:?}");
            assert!(scores[0].1 < 0.003, "seed {seed}: {scores:?}");
        }
        let stadium: Vec<Vector2<f64>> = (0..4_000)
            .map(|k| {
                let s = k as f64 / 4_000.0 * (2.0 * 30.0 + 2.0 * std::f64::consts::PI * 5.0);
                let half_circle = std::f64::consts::PI * 5.0;
                let (x, y) = if s < 30.0 {
                    (-15.0 + s, -5.0)
                } else if s < 30.0 + half_circle {
                    let a = (s - 30.0) / 5.0 - std::f64::consts::FRAC_PI_2;
                    (15.0 + 5.0 * a.cos(), 5.0 * a.sin())
                } else if s < 60.0 + half_circle {
                    (15.0 - (s - 30.0 - half_circle), 5.0)
                } else {
                    let a = (s - 60.0 - half_circle) / 5.0 + std::f64::consts::FRAC_PI_2;
                    (-15.0 + 5.0 * a.cos(), 5.0 * a.sin())
                };
                Vector2::new(x, y)
            })
            .collect();
        let points = noisy(&stadium, 400, 7);
        let normals = ordered_profile_normals(&points);
        let scores = held_out_scores(&points, &normals, FitMethod::default());
        let chosen = choose_degree(&scores);
        let rms_of = |degree: usize| scores.iter().find(|s| s.0 == degree).unwrap().1;
        assert!(chosen > 4, "{scores:?}");
        assert!(rms_of(4) > 5.0 * 0.002, "{scores:?}");
        assert!(rms_of(chosen) < 0.8 * rms_of(4), "{scores:?}");
    }
}
