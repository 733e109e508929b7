use super::*;
use rand::{Rng, SeedableRng};

fn at(k: usize) -> [f64; 3] {
    [k as f64, 2.0 * k as f64, -(k as f64)]
}

#[test]
fn known_values_give_their_mean_rms_spread_and_worst() {
    let mut stats = RunningStats::default();
    assert_eq!(stats.summary(), None);
    for (k, d) in [0.1, -0.3, 0.2, 0.05, 0.3].into_iter().enumerate() {
        stats.push(d, at(k));
    }
    let s = stats.summary().unwrap();
    assert_eq!(s.points, 5);
    assert_eq!(stats.count(), 5);
    assert!((s.mean_mm - 0.07).abs() < 1e-15, "{s:?}");
    let mean_square = (0.01 + 0.09 + 0.04 + 0.0025 + 0.09) / 5.0;
    assert!((s.rms_mm - f64::sqrt(mean_square)).abs() < 1e-15, "{s:?}");
    assert!((s.std_mm - f64::sqrt(mean_square - 0.07 * 0.07)).abs() < 1e-15);
    assert_eq!((s.min_mm, s.max_mm), (-0.3, 0.3));
    // -0.3 and +0.3 are equally bad: the first one stays the worst.
    assert_eq!((s.worst_mm, s.worst_at_mm), (-0.3, at(1)));
}

#[test]
fn merging_equals_pushing_everything() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(7);
    let values: Vec<f64> = (0..1000).map(|_| rng.gen_range(-0.2..0.25)).collect();
    let mut all = RunningStats::default();
    values
        .iter()
        .enumerate()
        .for_each(|(k, d)| all.push(*d, at(k)));
    for split in [0, 1, 377, 999, 1000] {
        let (mut first, mut second) = (RunningStats::default(), RunningStats::default());
        for (k, d) in values.iter().enumerate() {
            if k < split {
                first.push(*d, at(k));
            } else {
                second.push(*d, at(k));
            }
        }
        first.merge(&second);
        let (merged, pushed) = (first.summary().unwrap(), all.summary().unwrap());
        assert_eq!(merged.points, pushed.points);
        assert!(
            (merged.mean_mm - pushed.mean_mm).abs() < 1e-17,
            "split {split}"
        );
        assert!(
            (merged.rms_mm - pushed.rms_mm).abs() < 1e-15,
            "split {split}"
        );
        assert!(
            (merged.std_mm - pushed.std_mm).abs() < 1e-15,
            "split {split}"
        );
        assert_eq!(
            (
                merged.min_mm,
                merged.max_mm,
                merged.worst_mm,
                merged.worst_at_mm
            ),
            (
                pushed.min_mm,
                pushed.max_mm,
                pushed.worst_mm,
                pushed.worst_at_mm
            )
        );
    }
}

/// 10^5 deviations near 0.8 mm with micron noise, each a multiple of 2^-40 mm so that their exact sum is an
/// integer: the mean must be the exact mean to within 1e-12 mm (in fact to the last bit or two).
#[test]
fn the_mean_of_many_similar_deviations_is_exact() {
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let unit = (-40f64).exp2();
    let centre = (0.8 / unit).round() as i64;
    let ticks: Vec<i64> = (0..100_000)
        .map(|_| centre + rng.gen_range(-(1i64 << 20)..(1i64 << 20)))
        .collect();
    let mut stats = RunningStats::default();
    let mut halves = (RunningStats::default(), RunningStats::default());
    for (k, t) in ticks.iter().enumerate() {
        let d = *t as f64 * unit;
        stats.push(d, at(k));
        if k % 2 == 0 {
            &mut halves.0
        } else {
            &mut halves.1
        }
        .push(d, at(k));
    }
    let exact = ticks.iter().map(|&t| t as i128).sum::<i128>() as f64 * unit / ticks.len() as f64;
    let mean = stats.summary().unwrap().mean_mm;
    assert!((mean - exact).abs() < 1e-12, "mean {mean} vs exact {exact}");
    assert!(
        (mean - exact).abs() <= 2.0 * f64::EPSILON * exact,
        "mean {mean} vs exact {exact}"
    );
    halves.0.merge(&halves.1);
    assert!((halves.0.summary().unwrap().mean_mm - exact).abs() <= 2.0 * f64::EPSILON * exact);
}

#[test]
fn a_verdict_passes_inside_and_fails_with_the_count_outside() {
    let tolerance = Tolerance {
        lower_mm: -0.1,
        upper_mm: 0.1,
    };
    assert!(tolerance.contains(0.1) && tolerance.contains(-0.1) && tolerance.contains(0.0));
    assert!(!tolerance.contains(0.1000001) && !tolerance.contains(-0.12));
    let mut stats = RunningStats::default();
    let mut outside = 0;
    for (k, d) in [0.02, -0.05, 0.09].into_iter().enumerate() {
        stats.push(d, at(k));
        outside += usize::from(!tolerance.contains(d));
    }
    let inside = tolerance.verdict(&stats.summary().unwrap(), outside);
    assert_eq!(inside, Verdict::Pass);
    for (k, d) in [0.15, -0.13, 0.08].into_iter().enumerate() {
        stats.push(d, at(k + 3));
        outside += usize::from(!tolerance.contains(d));
    }
    let failed = tolerance.verdict(&stats.summary().unwrap(), outside);
    assert_eq!(
        failed,
        Verdict::Fail {
            points_outside: 2,
            worst_mm: 0.15,
            parameters_outside: 0,
        }
    );
    let json = serde_json::to_string(&failed).unwrap();
    assert_eq!(
        json,
        r#"{"verdict":"fail","points_outside":2,"worst_mm":0.15}"#
    );
    let other = Verdict::Fail {
        points_outside: 1,
        worst_mm: -0.4,
        parameters_outside: 0,
    };
    assert_eq!(
        Verdict::combine([&inside, &failed, &Verdict::Pass, &other]),
        Verdict::Fail {
            points_outside: 3,
            worst_mm: -0.4,
            parameters_outside: 0,
        }
    );
    assert!(Verdict::combine([&inside, &Verdict::Pass]).passed());
    assert!(Verdict::combine([]).passed());
}

#[test]
fn parameters_out_of_tolerance_fail_a_verdict_and_are_counted_apart_from_points() {
    let failed = Verdict::Pass.with_parameters_outside(2, -0.03);
    assert_eq!(
        failed,
        Verdict::Fail {
            points_outside: 0,
            worst_mm: -0.03,
            parameters_outside: 2,
        }
    );
    assert_eq!(
        failed.what_failed().unwrap(),
        "2 parameters out of tolerance (every point within, worst -0.0300 mm)"
    );
    assert_eq!(failed.cell_text(), "FAIL (0 outside, 2 parameters)");
    let points = Verdict::Fail {
        points_outside: 1,
        worst_mm: 0.2,
        parameters_outside: 0,
    };
    // Older reports have no count of parameters; a verdict without one writes none.
    let json = serde_json::to_string(&points).unwrap();
    assert!(!json.contains("parameters_outside"), "{json}");
    assert_eq!(serde_json::from_str::<Verdict>(&json).unwrap(), points);
    assert_eq!(
        points.what_failed().unwrap(),
        "1 point outside the tolerance, worst +0.2000 mm"
    );
    assert_eq!(
        points
            .clone()
            .with_parameters_outside(1, 0.2)
            .what_failed()
            .unwrap(),
        "1 point outside the tolerance, worst +0.2000 mm, 1 parameter out of tolerance"
    );
    let both = points.clone().with_parameters_outside(1, 0.2);
    assert_eq!(
        both,
        Verdict::Fail {
            points_outside: 1,
            worst_mm: 0.2,
            parameters_outside: 1,
        }
    );
    assert_eq!(
        Verdict::combine([&both, &failed]).cell_text(),
        "FAIL (1 outside, 3 parameters)"
    );
    assert_eq!(points.clone().with_parameters_outside(0, 0.2), points);
    assert_eq!(Verdict::Pass.with_parameters_outside(0, 0.0), Verdict::Pass);
}
