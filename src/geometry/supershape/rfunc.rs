//! R-functions (seed 000 section 2, seed 001 section 5): real functions whose sign follows the Boolean
//! combination of their arguments' signs, so that implicit functions of primitives (positive inside)
//! combine into the implicit function of a union, intersection or difference.

use serde::{Deserialize, Serialize};

/// The branch of R-function, chosen by the differential properties wanted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum RFunction {
    /// Seed 000 eq. 1: (x + y +- sqrt(x^2 + y^2 - 2 alpha x y)) / (1 + alpha), -1 < alpha <= 1;
    /// alpha = 1 is max (union) and min (intersection). Not differentiable where x = y for alpha = 1.
    Alpha(f64),
    /// Seed 000 eq. 2: (x + y +- sqrt(x^2 + y^2)) (x^2 + y^2)^(m/2), m even: m times differentiable
    /// everywhere, including the corner x = y = 0, but not normalised.
    ZeroM(u32),
    /// Seed 000 eq. 3: x + y +- (x^p + y^p)^(1/p), p even: normalised (on the boundary it has the
    /// value and gradient of the argument that vanishes) and differentiable except at x = y = 0.
    P(u32),
}

/// The Boolean operation an R-function transcribes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Boolean {
    /// R-disjunction, the "+" branch: positive where either argument is.
    Union,
    /// R-conjunction, the "-" branch: positive where both arguments are.
    Intersection,
    /// Intersection of the first with the R-negation of the second: positive where the first
    /// argument is positive and the second negative.
    Difference,
}

/// (|x|^p + |y|^p)^(1/p); for p = 2 a square root, where `powf` costs several times as much.
fn p_norm(x: f64, y: f64, p: u32) -> f64 {
    if p == 2 {
        (x * x + y * y).sqrt()
    } else {
        let exponent = p as i32;
        (x.abs().powi(exponent) + y.abs().powi(exponent)).powf(1.0 / f64::from(p))
    }
}

/// R-negation, the opposite sign function of seed 000 section 2: the complement of a solid.
pub fn negation(f: f64) -> f64 {
    -f
}

impl RFunction {
    /// The value of the R-function for `op` at the arguments' values `f1`, `f2`.
    pub fn combine(self, op: Boolean, f1: f64, f2: f64) -> f64 {
        if let RFunction::P(p) = self {
            // The value alone, without the partials' powers: a mesh's check and the distance's tree evaluate it
            // at every node, and the hub's p = 2 needs only a square root.
            let (x, y) = match op {
                Boolean::Union | Boolean::Intersection => (f1, f2),
                Boolean::Difference => (f1, negation(f2)),
            };
            let branch = if op == Boolean::Union { 1.0 } else { -1.0 };
            return x + y + branch * p_norm(x, y, p);
        }
        self.combine_with_partials(op, f1, f2).0
    }

    /// The value and the partial derivatives with respect to `f1` and `f2`, for the chain rule
    /// through a CSG tree. At the corner f1 = f2 = 0 the partials of `Alpha` and `P` are not defined
    /// (NaN); those of `ZeroM` are 0 there, as Shapiro shows.
    pub fn combine_with_partials(self, op: Boolean, f1: f64, f2: f64) -> (f64, f64, f64) {
        let (x, y, sign_y) = match op {
            Boolean::Union | Boolean::Intersection => (f1, f2, 1.0),
            Boolean::Difference => (f1, negation(f2), -1.0),
        };
        let branch = if op == Boolean::Union { 1.0 } else { -1.0 };
        let (value, dx, dy) = match self {
            RFunction::Alpha(alpha) => {
                let root = (x * x + y * y - 2.0 * alpha * x * y).sqrt();
                let scale = 1.0 / (1.0 + alpha);
                (
                    scale * (x + y + branch * root),
                    scale * (1.0 + branch * (x - alpha * y) / root),
                    scale * (1.0 + branch * (y - alpha * x) / root),
                )
            }
            RFunction::ZeroM(m) => {
                let r2 = x * x + y * y;
                if r2 == 0.0 {
                    (0.0, 0.0, 0.0)
                } else {
                    let r = r2.sqrt();
                    let first = x + y + branch * r;
                    let weight = r2.powf(f64::from(m) / 2.0);
                    // d weight / dx = m r^(m-2) x.
                    let d_weight = f64::from(m) * weight / r2;
                    (
                        first * weight,
                        (1.0 + branch * x / r) * weight + first * d_weight * x,
                        (1.0 + branch * y / r) * weight + first * d_weight * y,
                    )
                }
            }
            RFunction::P(p) => {
                // |x|^p equals x^p for the even p the paper requires and keeps any p well defined.
                let exponent = p as i32;
                let norm = p_norm(x, y, p);
                // d norm / dx = sign(x) |x|^(p-1) / norm^(p-1).
                let slope = |t: f64| t.signum() * (t.abs() / norm).powi(exponent - 1);
                (
                    x + y + branch * norm,
                    1.0 + branch * slope(x),
                    1.0 + branch * slope(y),
                )
            }
        };
        (value, dx, sign_y * dy)
    }

    /// Bounds of the R-function's value when each argument is only known to lie in a range [lo, hi], either end
    /// possibly infinite (a primitive whose box does not hold the point is known only to be outside: (-inf, 0]).
    /// `Alpha` and an even `P` are non-decreasing in each argument of a union or intersection (their partials,
    /// 1 +- (x - alpha y) / root and 1 +- (x / norm)^(p-1), lie in [0, 2]), so the bounds are their values at the
    /// ranges' ends; and they are normalised, so that an argument going to the side that does not decide leaves
    /// the other: union(x, -inf) = x. `ZeroM` is not monotone (its weight grows with both arguments): `None`.
    pub fn combine_bounds(self, op: Boolean, x: (f64, f64), y: (f64, f64)) -> Option<(f64, f64)> {
        let monotone = match self {
            RFunction::Alpha(alpha) => alpha > -1.0 && alpha <= 1.0,
            RFunction::P(p) => p >= 2 && p % 2 == 0,
            RFunction::ZeroM(_) => false,
        };
        if !monotone {
            return None;
        }
        let (op, y) = match op {
            Boolean::Difference => (Boolean::Intersection, (negation(y.1), negation(y.0))),
            _ => (op, y),
        };
        Some((
            self.combine_to_limit(op, x.0, y.0),
            self.combine_to_limit(op, x.1, y.1),
        ))
    }

    /// The union or intersection with either argument possibly infinite, as the limit of a normalised
    /// R-function: what decides wins (a union with +inf is +inf), what does not leaves the other argument.
    fn combine_to_limit(self, op: Boolean, x: f64, y: f64) -> f64 {
        let deciding = if op == Boolean::Union {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
        if x == deciding || y == deciding {
            deciding
        } else if x.is_infinite() {
            y
        } else if y.is_infinite() {
            x
        } else {
            self.combine(op, x, y)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn bounds_over_ranges_hold_every_value_in_them_and_their_limits_at_infinity() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let ops = [Boolean::Union, Boolean::Intersection, Boolean::Difference];
        for rfunction in [
            RFunction::Alpha(1.0),
            RFunction::Alpha(0.0),
            RFunction::Alpha(-0.5),
            RFunction::P(2),
            RFunction::P(4),
        ] {
            for op in ops {
                for _ in 0..200 {
                    let range = |rng: &mut rand::rngs::StdRng| {
                        let (a, b): (f64, f64) =
                            (rng.gen_range(-2.0..2.0), rng.gen_range(-2.0..2.0));
                        (a.min(b), a.max(b))
                    };
                    let (x, y) = (range(&mut rng), range(&mut rng));
                    let (lo, hi) = rfunction.combine_bounds(op, x, y).unwrap();
                    for _ in 0..20 {
                        let value = rfunction.combine(
                            op,
                            rng.gen_range(x.0..=x.1),
                            rng.gen_range(y.0..=y.1),
                        );
                        assert!(
                            value >= lo - 1e-12 && value <= hi + 1e-12,
                            "{rfunction:?} {op:?} {x:?} {y:?}: {value} not in [{lo}, {hi}]"
                        );
                    }
                }
                // A primitive known only to be outside, (-inf, 0], beside a value x: the union lies
                // between x (the primitive far away) and its value at 0, and every far value comes near x.
                let x = 0.3;
                let (lo, hi) = rfunction
                    .combine_bounds(op, (x, x), (f64::NEG_INFINITY, 0.0))
                    .unwrap();
                let far = rfunction.combine(op, x, -1e3);
                let near = rfunction.combine(op, x, 0.0);
                assert!(
                    lo <= far.min(near) + 1e-12 && hi >= far.max(near) - 1e-12,
                    "{rfunction:?} {op:?}"
                );
                match op {
                    Boolean::Union => assert_eq!((lo, hi), (x, near)),
                    Boolean::Intersection => assert_eq!((lo, hi), (f64::NEG_INFINITY, near)),
                    Boolean::Difference => assert_eq!((lo, hi), (near, x)),
                }
            }
        }
        assert_eq!(
            RFunction::ZeroM(2).combine_bounds(Boolean::Union, (0.0, 1.0), (0.0, 1.0)),
            None
        );
    }

    const BRANCHES: [RFunction; 6] = [
        RFunction::Alpha(1.0),
        RFunction::Alpha(0.0),
        RFunction::Alpha(-0.5),
        RFunction::ZeroM(2),
        RFunction::ZeroM(4),
        RFunction::P(2),
    ];

    /// Two overlapping unit spheres, centred at x = -0.5 and x = +0.5, positive inside.
    fn spheres(x: f64, y: f64, z: f64) -> (f64, f64) {
        let sphere = |cx: f64| 1.0 - ((x - cx).powi(2) + y * y + z * z);
        (sphere(-0.5), sphere(0.5))
    }

    #[test]
    fn signs_give_the_boolean_results_on_a_grid_of_two_spheres() {
        let grid = (0..31).map(|i| -1.7 + i as f64 * 0.113);
        let mut counted = [0usize; 3];
        for x in grid.clone() {
            for y in grid.clone() {
                for z in grid.clone() {
                    let (f1, f2) = spheres(x, y, z);
                    let (in1, in2) = (f1 > 0.0, f2 > 0.0);
                    for (k, (op, expected)) in [
                        (Boolean::Union, in1 || in2),
                        (Boolean::Intersection, in1 && in2),
                        (Boolean::Difference, in1 && !in2),
                    ]
                    .into_iter()
                    .enumerate()
                    {
                        counted[k] += usize::from(expected);
                        for rf in BRANCHES
                            .into_iter()
                            .chain([RFunction::P(4), RFunction::P(6)])
                        {
                            let value = rf.combine(op, f1, f2);
                            assert_eq!(value > 0.0, expected, "{rf:?} {op:?} at ({x}, {y}, {z})");
                        }
                    }
                }
            }
        }
        // The grid really samples every region: union > intersection > 0 and difference > 0.
        assert!(
            counted[0] > counted[1] && counted[1] > 0 && counted[2] > 0,
            "{counted:?}"
        );
    }

    #[test]
    fn alpha_one_is_max_and_min() {
        let rf = RFunction::Alpha(1.0);
        let close = |value: f64, expected: f64| (value - expected).abs() < 1e-15;
        assert!(close(rf.combine(Boolean::Union, 0.3, -2.0), 0.3));
        assert!(close(rf.combine(Boolean::Intersection, 0.3, -2.0), -2.0));
        assert!(close(rf.combine(Boolean::Difference, 0.3, -2.0), 0.3));
    }

    #[test]
    fn r_p_is_normalised_and_r_0_m_is_not() {
        // Normalised (Shapiro): where one argument vanishes and the combination's boundary follows it,
        // the R-function equals that argument to first order: value 0, partial 1 for it and 0 for the
        // other, so distances measured by the primitive carry over to the solid.
        for p in [2, 4, 6] {
            let rp = RFunction::P(p);
            for other in [0.1, 0.7, 3.0] {
                // Intersection boundary where f2 = 0 and f1 > 0; union boundary where f2 = 0, f1 < 0.
                for (op, f1) in [(Boolean::Intersection, other), (Boolean::Union, -other)] {
                    let (value, d1, d2) = rp.combine_with_partials(op, f1, 0.0);
                    let error = value.abs().max(d1.abs()).max((d2 - 1.0).abs());
                    assert!(error < 1e-15, "p {p} {op:?} f1 {f1}: {value} {d1} {d2}");
                }
            }
        }
        let (_, _, d2) = RFunction::ZeroM(2).combine_with_partials(Boolean::Intersection, 0.7, 0.0);
        assert!(
            (d2 - 0.49).abs() < 1e-15,
            "R_0^m has the partial f1^m, not 1: {d2}"
        );
    }

    #[test]
    fn partials_match_central_differences() {
        let h = 1e-6;
        for rf in BRANCHES.into_iter().chain([RFunction::P(4)]) {
            for op in [Boolean::Union, Boolean::Intersection, Boolean::Difference] {
                for (f1, f2) in [(0.3, -0.8), (-1.2, -0.4), (0.9, 0.2), (-0.1, 0.6)] {
                    let (_, d1, d2) = rf.combine_with_partials(op, f1, f2);
                    let n1 = (rf.combine(op, f1 + h, f2) - rf.combine(op, f1 - h, f2)) / (2.0 * h);
                    let n2 = (rf.combine(op, f1, f2 + h) - rf.combine(op, f1, f2 - h)) / (2.0 * h);
                    assert!(
                        (d1 - n1).abs() < 1e-8 && (d2 - n2).abs() < 1e-8,
                        "{rf:?} {op:?}"
                    );
                }
            }
        }
    }
}
