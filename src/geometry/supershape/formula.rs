//! The 2-D superformula r(theta) of seed 000 eq. 4 (seed 001 eq. 1), its derivative, and the rational
//! superformula of seed 001 eqs. 8-9 that replaces the powers by Blanc-Schlick rational fractions.

use serde::{Deserialize, Serialize};

/// A parameter of the superformula that must be strictly positive was not.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "superformula parameter {name} = {value} must be a finite number > 0; fix it in the model's \
     supershape parameters"
)]
pub struct SuperformulaError {
    /// The parameter's name as in seed 000 eq. 4 (m, n1, n2, n3, a, b).
    pub name: &'static str,
    /// The rejected value.
    pub value: f64,
}

/// The superpolygon of seed 000 eq. 4:
/// r(theta) = ( |cos(m theta / 4) / a|^n2 + |sin(m theta / 4) / b|^n3 )^(-1/n1).
///
/// `m` is the symmetry number (an integer for the closed, non-self-intersecting solids the implicit
/// functions need, seed 000 section 3), `n1..n3` the shape coefficients and `a`, `b` the sizes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Superformula {
    pub m: f64,
    pub n1: f64,
    pub n2: f64,
    pub n3: f64,
    pub a: f64,
    pub b: f64,
}

impl Superformula {
    /// Checks that every parameter is finite and strictly positive, as seed 000 eq. 4 requires.
    pub fn new(
        m: f64,
        n1: f64,
        n2: f64,
        n3: f64,
        a: f64,
        b: f64,
    ) -> Result<Self, SuperformulaError> {
        for (name, value) in [
            ("m", m),
            ("n1", n1),
            ("n2", n2),
            ("n3", n3),
            ("a", a),
            ("b", b),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SuperformulaError { name, value });
            }
        }
        Ok(Self {
            m,
            n1,
            n2,
            n3,
            a,
            b,
        })
    }

    /// The unit circle: m = 4, n1 = n2 = n3 = 2, a = b = 1 gives r = (cos^2 + sin^2)^(-1/2) = 1.
    pub fn circle() -> Self {
        Self {
            m: 4.0,
            n1: 2.0,
            n2: 2.0,
            n3: 2.0,
            a: 1.0,
            b: 1.0,
        }
    }

    /// The radius r(theta) of eq. 4.
    pub fn radius(&self, theta: f64) -> f64 {
        let (sin, cos) = self.turned(theta);
        self.radius_at(cos, sin)
    }

    /// The radius and its derivative dr/dtheta. The derivative is not defined where cos or sin of
    /// m theta / 4 vanishes with an exponent n2 or n3 at most 1 (the sharp corners of the polygon).
    pub fn radius_and_derivative(&self, theta: f64) -> (f64, f64) {
        let (sin, cos) = self.turned(theta);
        self.radius_and_derivative_at(cos, sin)
    }

    /// sin and cos of m theta / 4, the angle at which eq. 4 reads its powers.
    fn turned(&self, theta: f64) -> (f64, f64) {
        (self.m * theta / 4.0).sin_cos()
    }

    /// sin and cos of m theta / 4 for the direction whose cos and sin are given (theta itself is only asked of
    /// `theta()` when m is not 4). A part's cylinders and boxes have m = 4 in both formulas, and a mesh or a
    /// distance evaluates them millions of times: this spares them atan2 and sin_cos.
    pub(crate) fn turned_direction(
        &self,
        theta: impl FnOnce() -> f64,
        cos_theta: f64,
        sin_theta: f64,
    ) -> (f64, f64) {
        if self.m == 4.0 {
            (sin_theta, cos_theta)
        } else {
            self.turned(theta())
        }
    }

    /// r of eq. 4 from cos and sin of m theta / 4.
    pub(crate) fn radius_at(&self, cos: f64, sin: f64) -> f64 {
        let (u, v) = (cos / self.a, sin / self.b);
        let n = self.n1;
        if n > 2.0 && self.n2 == n && self.n3 == n {
            return equal_exponents_radius(u.abs(), v.abs(), n);
        }
        inverse_root(abs_pow(u, self.n2) + abs_pow(v, self.n3), n)
    }

    /// r of eq. 4 and dr/dtheta from cos and sin of m theta / 4.
    pub(crate) fn radius_and_derivative_at(&self, cos: f64, sin: f64) -> (f64, f64) {
        let k = self.m / 4.0;
        let u = cos / self.a;
        let v = sin / self.b;
        let sum = abs_pow(u, self.n2) + abs_pow(v, self.n3);
        // d|u|^n2/dtheta = n2 |u|^(n2-1) sign(u) du/dtheta, du/dtheta = -k sin / a; same for v.
        let d_sum = self.n2 * abs_pow(u, self.n2 - 1.0) * u.signum() * (-k * sin / self.a)
            + self.n3 * abs_pow(v, self.n3 - 1.0) * v.signum() * (k * cos / self.b);
        let radius = inverse_root(sum, self.n1);
        (radius, -radius / (self.n1 * sum) * d_sum)
    }
}

/// |x|^n. The exponents of real parts are mostly small integers (a cylinder's 2, a box's 40): those are taken by
/// multiplication (`powi`, within a few ulps of `powf`), several times faster than `powf`, which the meshing of a
/// part of 54 primitives spent a third of its time in.
fn abs_pow(x: f64, n: f64) -> f64 {
    let x = x.abs();
    if n == 2.0 {
        x * x
    } else if n == 1.0 {
        x
    } else if n.fract() == 0.0 && (0.0..=64.0).contains(&n) {
        x.powi(n as i32)
    } else {
        x.powf(n)
    }
}

/// (u^n + v^n)^(-1/n) for u, v >= 0 and n > 2, the profile of a part's cylinders and prisms (n = 40: near-square
/// edges). Written as (1 / big) (1 + t)^(-1/n) with t = (small / big)^n <= 1: over most of the turn t is below
/// 1e-8, where 1 - t/n is (1 + t)^(-1/n) to within t^2 (its next term's coefficient (1/n)(1/n + 1)/2 is below 1),
/// under an ulp, and no powf is needed; it takes one power of the ratio where the sum took two.
fn equal_exponents_radius(u: f64, v: f64, n: f64) -> f64 {
    let (big, small) = if u >= v { (u, v) } else { (v, u) };
    if big == 0.0 {
        return f64::INFINITY;
    }
    let t = abs_pow(small / big, n);
    let root = if t < 1e-8 {
        1.0 - t / n
    } else {
        (1.0 + t).powf(-1.0 / n)
    };
    root / big
}

/// sum^(-1/n1), with the common n1 = 2 (a circle's) and 1 by a square root and a division.
fn inverse_root(sum: f64, n1: f64) -> f64 {
    if n1 == 2.0 {
        1.0 / sum.sqrt()
    } else if n1 == 1.0 {
        1.0 / sum
    } else {
        sum.powf(-1.0 / n1)
    }
}

/// The rational superformula of seed 001 eqs. 8-9: each power |t|^p of eq. 7 is replaced by the
/// Blanc-Schlick fraction |t| / (p + (1 - p)|t|) (exact at |t| = 0 and 1), so the recovery's early
/// iterations avoid powers of sines and cosines.
///
/// With U = |cos(m theta/4)/a| and V = |sin(m theta/4)/b|:
/// W = ( U/(n2 + (1-n2)U) + V/(n3 + (1-n3)V) ) / 2 and r = 2^(-1/n1) (1/(n1 W) + 1 - 1/n1).
///
/// The factor 1/2 in W is the "factor 2 extracted to keep the argument of the root below 1" of the
/// text; eq. 9 as printed omits it, but only with it does the rational radius equal eq. 4 exactly for
/// n1 = n2 = n3 = 1, where every Blanc-Schlick fraction is exact. (Eq. 7 also misprints V as
/// |cos(n theta/4)|; the sine of eq. 1 is meant.) The fractions approximate powers only for
/// |t| <= 1, i.e. a, b >= 1 in the normalised frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RationalSuperformula(pub Superformula);

impl RationalSuperformula {
    /// The rational radius of seed 001 eq. 8.
    pub fn radius(&self, theta: f64) -> f64 {
        let p = &self.0;
        let (sin, cos) = (p.m * theta / 4.0).sin_cos();
        let u = (cos / p.a).abs();
        let v = (sin / p.b).abs();
        let half_sum = 0.5 * (blanc_schlick(u, p.n2) + blanc_schlick(v, p.n3));
        2f64.powf(-1.0 / p.n1) * (1.0 / (p.n1 * half_sum) + 1.0 - 1.0 / p.n1)
    }
}

/// The rational stand-in for t^p on [0, 1] (seed 001 eq. 6 in Blanc and Schlick's form).
fn blanc_schlick(t: f64, p: f64) -> f64 {
    t / (p + (1.0 - p) * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn formula(m: f64, n1: f64, n2: f64, n3: f64) -> Superformula {
        Superformula::new(m, n1, n2, n3, 1.0, 1.0).unwrap()
    }

    #[test]
    fn equal_exponents_give_the_printed_power_to_rounding_either_side_of_the_series_switch() {
        for n in [2.5, 3.0, 7.5, 40.0, 100.0] {
            // Ratios spread over [0, 1], and around the one where (small / big)^n crosses 1e-8.
            let switch = 1e-8f64.powf(1.0 / n);
            let ratios = (0..=200)
                .map(|k| k as f64 / 200.0)
                .chain((-50..=50).map(|k| switch * (1.0 + k as f64 * 1e-3)));
            for ratio in ratios {
                for big in [0.3, 1.0, 1.7] {
                    let (u, v) = (big, ratio * big);
                    let printed = (u.powf(n) + v.powf(n)).powf(-1.0 / n);
                    for (a, b) in [(u, v), (v, u)] {
                        let got = equal_exponents_radius(a, b, n);
                        assert!(
                            (got - printed).abs() <= 4.0 * f64::EPSILON * printed,
                            "n {n}, u {a}, v {b}: {got} vs {printed}"
                        );
                    }
                }
            }
        }
        assert_eq!(equal_exponents_radius(0.0, 0.0, 40.0), f64::INFINITY);
    }

    fn angles(count: usize) -> impl Iterator<Item = f64> {
        (0..count).map(move |i| -std::f64::consts::PI + 0.37 + i as f64 * 6.0 / count as f64)
    }

    #[test]
    fn the_circle_has_radius_one_everywhere() {
        for theta in angles(200) {
            let (r, dr) = Superformula::circle().radius_and_derivative(theta);
            assert!(
                (r - 1.0).abs() < 1e-15 && dr.abs() < 1e-14,
                "theta {theta}: r {r}, dr {dr}"
            );
        }
    }

    #[test]
    fn a_square_reaches_its_corners() {
        // m = 4, n1 = 1, n2 = n3 = 1 is the diamond |x| + |y| = 1: radius 1 on the axes and
        // 1 / (cos 45 + sin 45) = 1/sqrt 2 on the diagonals.
        let diamond = formula(4.0, 1.0, 1.0, 1.0);
        assert!((diamond.radius(0.0) - 1.0).abs() < 1e-15);
        let diagonal = diamond.radius(std::f64::consts::FRAC_PI_4);
        assert!((diagonal - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-15);
    }

    #[test]
    fn the_radius_has_period_eight_pi_over_m() {
        let star = formula(5.0, 0.7, 3.0, 8.0);
        for theta in angles(50) {
            let shifted = star.radius(theta + 8.0 * std::f64::consts::PI / 5.0);
            assert!((star.radius(theta) - shifted).abs() < 1e-12);
        }
    }

    #[test]
    fn the_derivative_matches_central_differences() {
        let h = 1e-6;
        for shape in [formula(3.0, 0.5, 2.5, 1.7), formula(6.0, 4.0, 20.0, 7.0)] {
            for theta in angles(97) {
                let (_, dr) = shape.radius_and_derivative(theta);
                let numeric = (shape.radius(theta + h) - shape.radius(theta - h)) / (2.0 * h);
                assert!(
                    (dr - numeric).abs() <= 1e-6 * dr.abs().max(1.0),
                    "{theta}: {dr} vs {numeric}"
                );
            }
        }
    }

    #[test]
    fn non_positive_parameters_are_rejected_by_name() {
        let err = Superformula::new(4.0, 1.0, 0.0, 1.0, 1.0, 1.0).unwrap_err();
        assert_eq!(err.name, "n2");
        assert!(Superformula::new(4.0, 1.0, 1.0, 1.0, f64::NAN, 1.0).is_err());
    }

    /// Largest relative difference between the rational and standard radii over a full turn.
    fn rational_gap(shape: Superformula) -> f64 {
        angles(720)
            .map(|theta| {
                let standard = shape.radius(theta);
                ((RationalSuperformula(shape).radius(theta) - standard) / standard).abs()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn rational_is_exact_when_every_exponent_is_one() {
        for m in [3.0, 4.0, 5.0, 8.0] {
            assert!(rational_gap(formula(m, 1.0, 1.0, 1.0)) < 1e-14);
        }
    }

    #[test]
    fn rational_agrees_for_small_coefficients() {
        // Seed 001 section 4 says only that the shapes are "similar" for n_i in [1, 4] (figure 3), a
        // visual claim. Measured here: at most 6.1 % relative radius difference for n in [1, 4], so the
        // tolerance is 6.5 %; with the factor 1/2 of eq. 9 left out the gap would be 50 % at n = 1.
        for m in [3.0, 4.0, 6.0, 8.0] {
            for n in [1.0, 1.5, 2.0, 3.0, 4.0] {
                let gap = rational_gap(formula(m, n, n, n));
                assert!(gap < 0.065, "m {m} n {n}: gap {gap}");
            }
        }
    }
}
