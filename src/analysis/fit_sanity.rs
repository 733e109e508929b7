//! Whether a fitted model is a model of its data: what the fit's statistics say against the points' own scatter,
//! the part's tolerance and the spurious branches beside the data, each doubt with its reason and what to try.
//! A fit that passes none of these silently is the point: a plainly wrong model (RMS 18.8 mm on a 100 mm part)
//! must not be saved with a clean bill.

use nalgebra::{DMatrix, SMatrix, SVector};

use crate::geometry::fit3l::{FitStats, BESIDE_DATA};
use crate::geometry::nearest::PointIndex;
use crate::geometry::sampling::Aabb;

/// Neighbours (the point included) of the local line or plane that measures the points' scatter.
const SCATTER_NEIGHBOURS: usize = 8;
/// An RMS distance this many times the points' scatter is not the scatter: the model misses the shape.
const RMS_OVER_SCATTER: f64 = 10.0;
/// ... provided it is also this fraction of the data's size (0.1 mm on a 100 mm section): a fit to nearly noise-
/// free points is not doubted for a few microns of form error.
const RMS_OVER_SIZE: f64 = 1e-3;
/// A point whose nearest neighbour is this many times farther than the typical nearest neighbour stands alone:
/// an export or unit error, or a touch of something else.
const ISOLATION: f64 = 50.0;

/// The points' own scatter, mm: the median over points of the RMS distance of a point's nearest neighbours from
/// their best-fit line (plane, in 3-D). On a smooth scanned section this is the probe's noise plus a little
/// curvature; it does not depend on any model.
pub(crate) fn scatter_mm<const N: usize>(points: &[SVector<f64, N>]) -> f64 {
    if points.len() <= N {
        return 0.0;
    }
    let index = PointIndex::new(points);
    let mut scatter: Vec<f64> = points
        .iter()
        .map(|p| {
            let near: Vec<SVector<f64, N>> = index
                .nearest_iter(p)
                .take(SCATTER_NEIGHBOURS)
                .map(|i| points[i])
                .collect();
            let centre = near.iter().sum::<SVector<f64, N>>() / near.len() as f64;
            let covariance = near
                .iter()
                .map(|q| (q - centre) * (q - centre).transpose())
                .sum::<SMatrix<f64, N, N>>()
                / near.len() as f64;
            // Dynamic storage: nalgebra's symmetric eigen solver is not generic over a const dimension.
            let smallest = DMatrix::from_iterator(N, N, covariance.iter().copied())
                .symmetric_eigenvalues()
                .min();
            smallest.max(0.0).sqrt()
        })
        .collect();
    scatter.sort_by(f64::total_cmp);
    scatter[scatter.len() / 2]
}

/// The indices of points that stand alone, far from every other point (see [`ISOLATION`]).
pub(crate) fn isolated_points<const N: usize>(points: &[SVector<f64, N>]) -> Vec<usize> {
    if points.len() < 3 {
        return Vec::new();
    }
    let index = PointIndex::new(points);
    let gaps: Vec<f64> = points
        .iter()
        .map(|p| {
            index
                .nearest_iter(p)
                .nth(1)
                .map_or(0.0, |j| (points[j] - p).norm())
        })
        .collect();
    let mut sorted = gaps.clone();
    sorted.sort_by(f64::total_cmp);
    let typical = sorted[sorted.len() / 2];
    if typical <= 0.0 {
        return Vec::new();
    }
    (0..points.len())
        .filter(|&i| gaps[i] > ISOLATION * typical)
        .collect()
}

/// What the fit's statistics say against the data: each doubt a sentence with its reason and what to try.
/// `tolerance_mm`: the half width of the part's tolerance band, when known.
pub(crate) fn doubts<const N: usize>(
    stats: &FitStats,
    scatter_mm: f64,
    domain: &Aabb<N>,
    tolerance_mm: Option<f64>,
) -> Vec<String> {
    let mut doubts = Vec::new();
    let size = domain.diagonal();
    if stats.rms_distance_mm > RMS_OVER_SCATTER * scatter_mm
        && stats.rms_distance_mm > RMS_OVER_SIZE * size
    {
        doubts.push(format!(
            "the fit's RMS distance {:.4} mm is {:.0} times the points' own scatter ({:.4} mm): the model does \
             not follow the data; check that the points are one profile (3-D profiles in planes of constant x \
             need --stack), or try a higher degree",
            stats.rms_distance_mm,
            stats.rms_distance_mm / scatter_mm.max(f64::MIN_POSITIVE),
            scatter_mm
        ));
    }
    if let Some(tolerance) = tolerance_mm {
        doubts.extend(beyond_tolerance(
            stats.max_distance_mm,
            &stats.max_distance_at,
            tolerance,
        ));
    }
    if stats.branches_beside_data > 0 {
        doubts.push(format!(
            "the model has {} spurious zero-set branch(es) within {:.2} mm of the data: a measured point off the \
             part may take its deviation from the wrong curve there; check the deviations near it, or try \
             another degree or method",
            stats.branches_beside_data,
            BESIDE_DATA * size
        ));
    }
    if stats.side_segments_crossed_again > 0 {
        doubts.push(format!(
            "the model's zero set crosses {} of {} short segments across the data more than once: a sliver of \
             spurious surface beside the data, where deviations may have the wrong sign",
            stats.side_segments_crossed_again, stats.side_segments
        ));
    }
    if stats.points_without_foot > 0 {
        doubts.push(format!(
            "{} fitted points have no foot point on the model: it has a defect near them",
            stats.points_without_foot
        ));
    }
    doubts
}

/// The doubt when the farthest fitted point (`max_mm` from the model, at `at` when known) is beyond the part's
/// tolerance (the half width of its band).
pub(crate) fn beyond_tolerance(max_mm: f64, at: &[f64], tolerance_mm: f64) -> Option<String> {
    if max_mm <= tolerance_mm {
        return None;
    }
    let at = if at.is_empty() {
        String::new()
    } else {
        let coordinates: Vec<String> = at.iter().map(|c| format!("{c:.3}")).collect();
        format!(" at ({}) mm", coordinates.join(", "))
    };
    Some(format!(
        "a fitted point lies {max_mm:.4} mm from the model{at}, beyond the part's tolerance of {tolerance_mm} \
         mm: deviations measured against this model are not good to that tolerance there; try a higher degree \
         or the other normals, or more points where the part turns sharply"
    ))
}

#[cfg(test)]
mod tests {
    use nalgebra::Vector2;
    use rand::{Rng, SeedableRng};

    use super::*;

    fn circle(n: usize, radius: f64, noise: f64, seed: u64) -> Vec<Vector2<f64>> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        (0..n)
            .map(|i| {
                let t = i as f64 / n as f64 * std::f64::consts::TAU;
                let r = radius + rng.gen_range(-1.0..1.0) * noise * 3f64.sqrt();
                Vector2::new(r * t.cos(), r * t.sin())
            })
            .collect()
    }

    fn stats(rms: f64, max: f64) -> FitStats {
        FitStats {
            points: 400,
            rms_distance_mm: rms,
            max_distance_mm: max,
            max_distance_at: vec![12.0, -3.5],
            condition_number: 1.0,
            zero_set_components: 1,
            branches_beside_data: 0,
            offset_min_mm: 0.0,
            offset_max_mm: 0.0,
            refinement_iterations: 0,
            points_without_foot: 0,
            side_segments: 0,
            side_segments_crossed_again: 0,
        }
    }

    #[test]
    fn the_scatter_is_the_probe_s_noise_not_the_shape() {
        // A 50 mm circle of 2000 points (0.16 mm apart) with uniform radial noise of RMS 5 um, then 20 um.
        for noise in [0.005, 0.020] {
            let scatter = scatter_mm(&circle(2000, 50.0, noise, 3));
            assert!(
                scatter > 0.4 * noise && scatter < 1.2 * noise,
                "noise {noise} mm, scatter {scatter} mm"
            );
        }
        let clean = scatter_mm(&circle(2000, 50.0, 0.0, 3));
        assert!(
            clean < 0.0015,
            "a clean circle scatters by its curvature only: {clean}"
        );
    }

    #[test]
    fn a_point_far_from_the_rest_is_named_and_no_other() {
        let mut points = circle(400, 50.0, 0.005, 4);
        points[50] = Vector2::new(1e30, 0.0);
        points[123] = Vector2::new(400.0, 20.0);
        assert_eq!(isolated_points(&points), vec![50, 123]);
        assert!(isolated_points(&circle(400, 50.0, 0.005, 4)).is_empty());
    }

    #[test]
    fn a_fit_is_doubted_for_its_rms_its_max_and_near_branches_each_with_what_to_try() {
        let domain = Aabb {
            min: Vector2::new(-50.0, -50.0),
            max: Vector2::new(50.0, 50.0),
        };
        // A good fit: RMS twice the scatter, within a 0.1 mm tolerance.
        assert!(doubts(&stats(0.004, 0.02), 0.002, &domain, Some(0.1)).is_empty());
        // 18.8 mm RMS over 5 um of scatter: plainly not a model of the data.
        let wrong = doubts(&stats(18.8, 61.0), 0.005, &domain, None);
        assert_eq!(wrong.len(), 1, "{wrong:?}");
        assert!(
            wrong[0].contains("18.8000 mm") && wrong[0].contains("--stack"),
            "{}",
            wrong[0]
        );
        // Many times the scatter but a few microns: not doubted for its RMS.
        assert!(doubts(&stats(0.01, 0.05), 0.0001, &domain, None).is_empty());
        // A max beyond the tolerance, named with where it is.
        let beyond = doubts(&stats(0.01, 0.153), 0.005, &domain, Some(0.1));
        assert_eq!(beyond.len(), 1, "{beyond:?}");
        assert!(beyond[0].contains("0.1530 mm") && beyond[0].contains("(12.000, -3.500) mm"));
        // A branch beside the data.
        let mut branched = stats(0.004, 0.02);
        branched.zero_set_components = 3;
        assert!(
            doubts(&branched, 0.002, &domain, None).is_empty(),
            "far branches change nothing"
        );
        branched.branches_beside_data = 1;
        let near = doubts(&branched, 0.002, &domain, None);
        assert!(
            near.len() == 1 && near[0].contains("within 2.83 mm"),
            "{near:?}"
        );
    }
}
