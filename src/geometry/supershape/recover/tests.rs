use std::f64::consts::PI;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal};

use super::*;
use crate::geometry::supershape::formula::Superformula;

/// A supershape placed by a rigid transform.
struct Truth {
    shape: Supershape,
    place: Isometry3<f64>,
}

impl Truth {
    fn node(&self) -> Node {
        Node::supershape(
            self.shape,
            Deformations(vec![Deformation::Rigid(self.place)]),
        )
    }

    fn surface(&self, count: usize) -> Vec<Point3<f64>> {
        self.shape
            .surface_points(count)
            .iter()
            .map(|p| self.place * p)
            .collect()
    }

    fn mean_size(&self) -> f64 {
        self.shape.scale.iter().sum::<f64>() / 3.0
    }
}

/// A superformula with m lobes and exponents drawn log-uniformly from [0.5, 20], kept only when its radius varies
/// by at most 3 : 1 round the turn (the stars and spikes beyond are not the mechanical parts this models).
fn formula(rng: &mut StdRng, m: u32) -> Superformula {
    loop {
        let mut n = || (rng.gen_range(0.5f64.ln()..20f64.ln())).exp();
        let f = Superformula::new(f64::from(m), n(), n(), n(), 1.0, 1.0).unwrap();
        let radii: Vec<f64> = (0..720)
            .map(|k| f.radius(-PI + PI * k as f64 / 360.0))
            .collect();
        let (low, high) = radii
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), r| (l.min(*r), h.max(*r)));
        if high / low <= 3.0 {
            return f;
        }
    }
}

/// A random supershape: m1 from 3 to 8, m2 even from 2 to 8, exponents as `formula`, sizes 10 to 30 mm, any
/// orientation, centred within 50 mm of the origin.
fn random_truth(rng: &mut StdRng) -> Truth {
    let m1 = rng.gen_range(3..=8);
    let m2 = 2 * rng.gen_range(1..=4);
    let shape = Supershape {
        r1: formula(rng, m1),
        r2: formula(rng, m2),
        scale: [
            rng.gen_range(10.0..30.0),
            rng.gen_range(10.0..30.0),
            rng.gen_range(10.0..30.0),
        ],
    };
    let axis = Vector3::new(
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
        rng.gen_range(-1.0..1.0),
    );
    let place = Isometry3::from_parts(
        Translation3::new(
            rng.gen_range(-50.0..50.0),
            rng.gen_range(-50.0..50.0),
            rng.gen_range(-50.0..50.0),
        ),
        UnitQuaternion::from_scaled_axis(axis.normalize() * rng.gen_range(0.0..PI)),
    );
    Truth { shape, place }
}

fn noisy(points: &[Point3<f64>], sigma: f64, rng: &mut StdRng) -> Vec<Point3<f64>> {
    let noise = Normal::new(0.0, sigma).unwrap();
    points
        .iter()
        .map(|p| p + Vector3::from_fn(|_, _| noise.sample(rng)))
        .collect()
}

/// The RMS gap between the recovered and the true surfaces, both ways, mm.
fn surface_distance(truth: &Truth, recovered: &(Supershape, Deformations)) -> f64 {
    let truth_place = Deformations(vec![Deformation::Rigid(truth.place)]);
    surface_gap_rms(
        (&truth.shape, &truth_place),
        (&recovered.0, &recovered.1),
        1000,
    )
}

/// The acceptance test: 100 seeded supershapes (m1 from 3 to 8, m2 from 2 to 8, exponents from 0.5 to
/// 20, random poses), 1000 points each with Gaussian noise of 0.5% of the mean size, symmetry read from the
/// points. A recovery succeeds when the RMS distance between the recovered and the true surfaces (both ways, from
/// 1000 parametric points of each to the other, `surface_distance_bound`) is within 1% of the mean size, twice the noise; it is near when within 3%. The
/// rates and the median distance are printed (`cargo test recovery_of_seeded -- --nocapture`) and asserted at
/// what this recovery reaches (BENCHMARKS.md): a drop means a regression. Of the 31 misses, 13 end with the true
/// symmetry numbers in a local minimum of the exponents; the rest with a number still wrong, where no other
/// number's brief fit came nearer the points (`best_switch`).
/// Measured: 69% within 1% and 93% within 3% of the size (median 0.36%), BENCHMARKS.md.
const RATE_WITHIN_1: f64 = 0.66;
const RATE_WITHIN_3: f64 = 0.90;

#[test]
fn recovery_of_seeded_supershapes_reaches_the_true_surface() {
    let mut rng = StdRng::seed_from_u64(2026);
    let options = RecoveryOptions {
        truncate: false,
        holes: false,
        ..RecoveryOptions::default()
    };
    let cases = 100;
    // The cases are drawn in order from one seed, then recovered on two threads (the machine's two cores).
    let drawn: Vec<(Truth, Vec<Point3<f64>>)> = (0..cases)
        .map(|_| {
            let truth = random_truth(&mut rng);
            let points = noisy(&truth.surface(1000), 0.005 * truth.mean_size(), &mut rng);
            (truth, points)
        })
        .collect();
    let judge = |case: usize| {
        let (truth, points) = &drawn[case];
        let (distance, found) = match recover(points, &options) {
            Ok(recovered) => (
                surface_distance(truth, &recovered.envelope) / truth.mean_size(),
                recovered.symmetry,
            ),
            Err(_) => (f64::INFINITY, [0, 0]),
        };
        let failure = (distance > 0.01).then(|| {
            let (r1, r2) = (truth.shape.r1, truth.shape.r2);
            format!(
                "case {case}: m {}/{} found {found:?}, n {:.2} {:.2} {:.2} / {:.2} {:.2} {:.2}: {distance:.4}",
                r1.m, r2.m, r1.n1, r1.n2, r1.n3, r2.n1, r2.n2, r2.n3
            )
        });
        (distance, failure)
    };
    let judged: Vec<(f64, Option<String>)> = std::thread::scope(|scope| {
        let halves: Vec<_> = [0..cases / 2, cases / 2..cases]
            .into_iter()
            .map(|range| scope.spawn(|| range.map(judge).collect::<Vec<_>>()))
            .collect();
        halves
            .into_iter()
            .flat_map(|h| h.join().expect("a half of the cases"))
            .collect()
    });
    let mut relative: Vec<f64> = judged.iter().map(|(d, _)| *d).collect();
    let failures: Vec<String> = judged.into_iter().filter_map(|(_, f)| f).collect();
    relative.sort_by(f64::total_cmp);
    let rate = (cases - failures.len()) as f64 / cases as f64;
    let near = relative.iter().filter(|d| **d <= 0.03).count() as f64 / cases as f64;
    println!(
        "recovered {:.0}% of {cases} supershapes within 1% of their size, {:.0}% within 3%; median RMS distance \
         {:.4}% of the size",
        100.0 * rate,
        100.0 * near,
        100.0 * relative[cases / 2]
    );
    for failure in &failures {
        println!("  {failure}");
    }
    assert!(
        rate >= RATE_WITHIN_1 && near >= RATE_WITHIN_3,
        "{failures:?}"
    );
}

/// A rounded block 60 x 40 x 30 mm (a superquadric, m = 4) with a round bore of radius 8 mm through it along z:
/// its scan (the block's surface outside the bore, the bore's wall inside the block) recovers as the block minus
/// one through hole whose radius and axis are the bore's, and the solid is the part: every point of the scan is
/// within 0.05 mm of the recovered solid's surface by the exact distance, the bore's axis is inside the hole, and
/// the block's material between bore and wall is inside the solid; as a supershape and as a superquadric.
#[test]
fn a_block_with_a_bore_recovers_as_an_envelope_minus_a_through_hole() {
    let squarish = Superformula::new(4.0, 8.0, 8.0, 8.0, 1.0, 1.0).unwrap();
    let block = Supershape {
        r1: squarish,
        r2: squarish,
        scale: [30.0, 20.0, 15.0],
    };
    let bore_radius = 8.0;
    let mut points: Vec<Point3<f64>> = block
        .surface_points(3000)
        .into_iter()
        .filter(|p| p.x.hypot(p.y) > bore_radius)
        .collect();
    for i in 0..40 {
        for j in 0..25 {
            let angle = 2.0 * PI * (i as f64 + 0.5) / 40.0;
            let z = -14.0 + 28.0 * j as f64 / 24.0;
            let wall = Point3::new(bore_radius * angle.cos(), bore_radius * angle.sin(), z);
            if block.radial(&wall) > 0.0 {
                points.push(wall);
            }
        }
    }
    // The block is a superquadric: recovered as a supershape and as a superquadric, whose refits without the
    // bore's points stay superquadrics.
    for family in [Family::Supershape, Family::Superquadric] {
        let options = RecoveryOptions {
            family,
            ..RecoveryOptions::default()
        };
        let recovered = recover(&points, &options).unwrap();
        assert_eq!(recovered.holes.len(), 1, "{:?}", recovered.holes);
        let hole = &recovered.holes[0];
        assert!(hole.through);
        let solid = &recovered.solid;
        assert!(
            !solid.contains(&Point3::new(0.0, 0.0, 0.0)),
            "the bore is open at its middle"
        );
        assert!(
            !solid.contains(&Point3::new(0.0, 0.0, 14.5)),
            "and at its ends"
        );
        assert!(
            solid.contains(&Point3::new(15.0, 0.0, 0.0)),
            "the material beside it is kept"
        );
        let distance = crate::geometry::supershape::distance::SolidDistance::new(solid);
        let worst = points
            .iter()
            .map(|p| distance.foot(p).expect("a foot").distance_mm.abs())
            .fold(0.0f64, f64::max);
        assert!(
            worst < 0.05,
            "{family:?}: worst point {worst} mm off the recovered solid"
        );
        if family == Family::Superquadric {
            let r1 = recovered.envelope.0.r1;
            assert!(r1.n1 == r1.n2 && r1.n2 == r1.n3, "{r1:?}");
        }
    }
}

/// Truncation (seed 001 eq. 14): a scan of only the top half of an ellipsoid recovers the ellipsoid cut by the
/// points' bounding box, so the recovered solid ends just below the scanned rim instead of closing the bottom.
#[test]
fn a_half_scan_is_truncated_by_its_bounding_box() {
    let ellipsoid = Supershape {
        r1: Superformula::circle(),
        r2: Superformula::circle(),
        scale: [30.0, 20.0, 15.0],
    };
    let points: Vec<Point3<f64>> = ellipsoid
        .surface_points(3000)
        .into_iter()
        .filter(|p| p.z > 0.0)
        .collect();
    let whole = recover(
        &points,
        &RecoveryOptions {
            truncate: false,
            holes: false,
            ..RecoveryOptions::default()
        },
    )
    .unwrap();
    let cut = recover(
        &points,
        &RecoveryOptions {
            holes: false,
            ..RecoveryOptions::default()
        },
    )
    .unwrap();
    assert!(
        whole.solid.contains(&Point3::new(0.0, 0.0, -10.0)),
        "the untruncated model closes below"
    );
    assert!(
        !cut.solid.contains(&Point3::new(0.0, 0.0, -1.0)),
        "the truncated one ends at the data"
    );
    assert!(cut.solid.contains(&Point3::new(0.0, 0.0, 1.0)));
    assert!(cut.rms_radial_mm < 1e-3, "{}", cut.rms_radial_mm);
}

/// The global error of fit (eq. 15) is zero on the model's surface and grows off it; a pose fit finds the turn,
/// shift and scale that moved a scan of the reference (12 degrees, 3 mm, 2%), back to 1e-6.
#[test]
fn a_pose_fit_undoes_a_known_similarity_against_the_reference() {
    let truth = Truth {
        shape: Supershape {
            r1: Superformula::new(6.0, 5.0, 4.0, 4.0, 1.0, 1.0).unwrap(),
            r2: Superformula::new(4.0, 3.0, 6.0, 6.0, 1.0, 1.0).unwrap(),
            scale: [20.0, 20.0, 12.0],
        },
        place: Isometry3::identity(),
    };
    let reference = Solid::new(truth.node());
    let on_surface = truth.surface(1500);
    assert!(global_error(&reference, &on_surface) < 1e-20);
    let moved = Pose {
        rotation: nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), 12f64.to_radians()),
        translation: Vector3::new(3.0, -1.0, 0.5),
        scale: 1.02,
    };
    let measured: Vec<Point3<f64>> = on_surface.iter().map(|p| moved.apply(p)).collect();
    let fit = fit_pose(&reference, &measured, Pose::identity());
    assert!(fit.error_before > 1.0, "{fit:?}");
    assert!(fit.error_after < 1e-12, "{fit:?}");
    for p in &on_surface {
        assert!((fit.pose.apply(&moved.apply(p)) - p).norm() < 1e-6);
    }
}

/// Points that all lie at one place (a probe that never moved) are refused with what to check, and so are too few
/// points and a coordinate that is not a number.
#[test]
fn points_that_show_no_surface_are_refused() {
    let same = vec![Point3::new(1.0, 2.0, 3.0); 100];
    assert!(matches!(
        recover(&same, &RecoveryOptions::default()),
        Err(RecoveryError::Coincident { .. })
    ));
    let few = vec![Point3::new(1.0, 2.0, 3.0); 10];
    assert_eq!(
        recover(&few, &RecoveryOptions::default()),
        Err(RecoveryError::TooFewPoints { got: 10 })
    );
    let mut broken: Vec<Point3<f64>> = (0..100).map(|k| Point3::new(k as f64, 0.0, 1.0)).collect();
    broken[7].y = f64::NAN;
    assert_eq!(
        recover(&broken, &RecoveryOptions::default()),
        Err(RecoveryError::NotFinite { index: 7 })
    );
}

/// A random superquadric: epsilon1 and epsilon2 uniform in [0.1, 1.9] (n = 2 / epsilon from 1.05 to 20: boxes to
/// near-octahedra, the range superquadric fitters are tried on), sizes 10 to 30 mm, any orientation.
fn random_superquadric(rng: &mut StdRng) -> Truth {
    let mut superellipse = || {
        let n = 2.0 / rng.gen_range(0.1..1.9);
        Superformula::new(4.0, n, n, n, 1.0, 1.0).unwrap()
    };
    let (r1, r2) = (superellipse(), superellipse());
    let place = random_truth(rng).place;
    Truth {
        shape: Supershape {
            r1,
            r2,
            scale: [
                rng.gen_range(10.0..30.0),
                rng.gen_range(10.0..30.0),
                rng.gen_range(10.0..30.0),
            ],
        },
        place,
    }
}

/// The superquadric special case against the yardstick (EMS: about 1e-3 relative error at 1% noise, no
/// local-minimum failures): 100 seeded superquadrics, 2000 points each with Gaussian noise of 1% of the mean
/// size on every coordinate. Every case must come within `SUPERQUADRIC_GAP` of its size (RMS distance between
/// the recovered and the true surfaces, both ways); a start in the wrong basin lands at 1e-2 and beyond.
/// The median is asserted too, so that a biased fit that stays out of local minima still fails. Measured: median
/// 0.99e-3, worst 1.88e-3 (`cargo test superquadrics_ -- --nocapture`, BENCHMARKS.md).
const SUPERQUADRIC_GAP: f64 = 2.5e-3;
const SUPERQUADRIC_MEDIAN_GAP: f64 = 1.2e-3;

#[test]
fn superquadrics_are_recovered_from_every_seeded_case() {
    let mut rng = StdRng::seed_from_u64(2022);
    let options = RecoveryOptions {
        family: Family::Superquadric,
        truncate: false,
        holes: false,
        ..RecoveryOptions::default()
    };
    let cases = 100;
    let mut relative: Vec<(f64, usize)> = (0..cases)
        .map(|case| {
            let truth = random_superquadric(&mut rng);
            let points = noisy(&truth.surface(2000), 0.01 * truth.mean_size(), &mut rng);
            let recovered = recover(&points, &options).expect("a superquadric recovers");
            (
                surface_distance(&truth, &recovered.envelope) / truth.mean_size(),
                case,
            )
        })
        .collect();
    relative.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (worst, case) = relative[cases - 1];
    println!(
        "superquadrics: median relative surface gap {:.2e}, worst {worst:.2e} (case {case})",
        relative[cases / 2].0
    );
    let failures: Vec<_> = relative
        .iter()
        .filter(|(d, _)| *d > SUPERQUADRIC_GAP)
        .collect();
    assert!(
        failures.is_empty(),
        "{} cases miss: {failures:?}",
        failures.len()
    );
    assert!(relative[cases / 2].0 <= SUPERQUADRIC_MEDIAN_GAP);
}

/// A superquadric's symmetry numbers are 4,4: others are refused, not silently replaced.
#[test]
fn a_superquadric_with_other_symmetry_numbers_is_refused() {
    let truth = random_superquadric(&mut StdRng::seed_from_u64(5));
    let options = RecoveryOptions {
        family: Family::Superquadric,
        symmetry: Some([6, 4]),
        ..RecoveryOptions::default()
    };
    assert_eq!(
        recover(&truth.surface(500), &options),
        Err(RecoveryError::SuperquadricSymmetry { given: [6, 4] })
    );
}
