//! A root of a function of one variable that changes sign on [0, 1], by regula falsi in its Illinois variant
//! (the end that stays put has its value halved, so the bracket closes superlinearly where plain regula falsi
//! would crawl). The mesher's edge roots and sharp-edge starts both need it, on functions that are smooth near
//! the root but may have a kink elsewhere on the segment, where Newton without a bracket could leave it.

const MAX_STEPS: u32 = 100;

/// A t in [0, 1] with |f(t)| < `tolerance` or f(t) = 0 (or the bracket closed to rounding), and f(t), given f's values at the
/// ends, of opposite signs (or one of them 0). None if they have the same sign or it does not converge.
pub(super) fn root(f: impl Fn(f64) -> f64, ends: (f64, f64), tolerance: f64) -> Option<(f64, f64)> {
    let ((mut t0, mut f0), (mut t1, mut f1)) = ((0.0, ends.0), (1.0, ends.1));
    if f0 * f1 > 0.0 || f0.is_nan() || f1.is_nan() {
        return None;
    }
    if f0.abs() < tolerance || f0 == 0.0 {
        return Some((t0, f0));
    }
    if f1.abs() < tolerance || f1 == 0.0 {
        return Some((t1, f1));
    }
    // Which end moved last: -1 the low one, 1 the high one.
    let mut side = 0;
    for _ in 0..MAX_STEPS {
        let t = if f0 == f1 {
            0.5 * (t0 + t1)
        } else {
            (t0 * f1 - t1 * f0) / (f1 - f0)
        };
        let ft = f(t);
        if ft.abs() < tolerance || ft == 0.0 || t1 - t0 < 1e-15 {
            return Some((t, ft));
        }
        if (ft > 0.0) == (f0 > 0.0) {
            (t0, f0) = (t, ft);
            if side == -1 {
                f1 *= 0.5;
            }
            side = -1;
        } else {
            (t1, f1) = (t, ft);
            if side == 1 {
                f0 *= 0.5;
            }
            side = 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_root_within_tolerance_in_few_steps() {
        // A smooth function with its root at t = 0.3, and one whose root sits beside a kink.
        let calls = std::cell::Cell::new(0);
        let smooth = |t: f64| {
            calls.set(calls.get() + 1);
            (t - 0.3) * (1.0 + t * t)
        };
        let (t, value) = root(smooth, (smooth(0.0), smooth(1.0)), 1e-12).unwrap();
        assert!((t - 0.3).abs() < 1e-11, "{t}");
        assert_eq!(value, smooth(t));
        assert!(calls.get() < 12, "{} evaluations", calls.get());
        let kinked = |t: f64| (t - 0.7).abs().max(0.05) * (t - 0.65).signum();
        let (t, _) = root(kinked, (kinked(0.0), kinked(1.0)), 1e-12).unwrap();
        assert!((t - 0.65).abs() < 1e-12, "{t}");
    }

    #[test]
    fn ends_of_one_sign_have_no_root_and_a_zero_end_is_one() {
        assert_eq!(root(|t| t + 1.0, (1.0, 2.0), 1e-9), None);
        assert_eq!(root(|t| t, (0.0, 1.0), 1e-9), Some((0.0, 0.0)));
        assert_eq!(root(|t| t - 1.0, (-1.0, 0.0), 1e-9), Some((1.0, 0.0)));
        assert_eq!(root(|t| t, (f64::NAN, 1.0), 1e-9), None);
    }
}
