//! The 3-D supershape: the spherical product of two superformulas (seed 000 eq. 5), its two implicit
//! functions (eq. 6 and the radial eq. 7) with the angles of eq. 8, and their analytic gradients.
//! Both implicit functions are positive inside, zero on the surface and negative outside.

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use super::formula::Superformula;

/// A supershape in its canonical frame: `r1` runs over the longitude theta in [-pi, pi), `r2` over the
/// latitude phi in [-pi/2, pi/2], and `scale` holds the semi-axes a1, a2, a3 that stretch the unit
/// shape along x, y and z (the sizes whose product the recovery cost of seed 001 eq. 4 weighs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Supershape {
    pub r1: Superformula,
    pub r2: Superformula,
    pub scale: [f64; 3],
}

/// The latitude phi of seed 000 eq. 8 for a point of the unscaled shape (as its cos and sin), with the radii
/// r1(theta), r2(phi) and, when asked for, their derivatives (else 0).
struct Angles {
    cos_phi: f64,
    sin_phi: f64,
    r1: f64,
    dr1: f64,
    r2: f64,
    dr2: f64,
}

impl Supershape {
    /// The unit sphere: both superformulas are the unit circle and the scale is 1.
    pub fn sphere() -> Self {
        Self {
            r1: Superformula::circle(),
            r2: Superformula::circle(),
            scale: [1.0; 3],
        }
    }

    /// The surface point of seed 000 eq. 5 at longitude `theta` and latitude `phi`, scaled.
    pub fn point(&self, theta: f64, phi: f64) -> Point3<f64> {
        let (sin_theta, cos_theta) = theta.sin_cos();
        let (sin_phi, cos_phi) = phi.sin_cos();
        let (sin1, cos1) = self.r1.turned_direction(|| theta, cos_theta, sin_theta);
        let (sin2, cos2) = self.r2.turned_direction(|| phi, cos_phi, sin_phi);
        let r1 = self.r1.radius_at(cos1, sin1);
        let r2 = self.r2.radius_at(cos2, sin2);
        Point3::new(
            self.scale[0] * r1 * r2 * cos_theta * cos_phi,
            self.scale[1] * r1 * r2 * sin_theta * cos_phi,
            self.scale[2] * r2 * sin_phi,
        )
    }

    /// `count` surface points of eq. 5 spread over the parameters: latitudes evenly in sin(phi) (so that bands
    /// of the unit sphere get points by their area), longitudes turned by the golden angle from one to the next.
    /// For tests, benches and examples that need a scan of a known shape.
    pub fn surface_points(&self, count: usize) -> Vec<Point3<f64>> {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..count)
            .map(|k| {
                let sin_phi = -1.0 + (2 * k + 1) as f64 / count as f64;
                let theta =
                    (golden * k as f64).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
                self.point(theta, sin_phi.asin())
            })
            .collect()
    }

    /// The implicit function of seed 000 eq. 6 (seed 001 eq. 2),
    /// F1 = 1 - (x^2 + y^2 + r1^2 z^2) / (r1^2 r2^2), evaluated on the unscaled point. For P = t I with
    /// I on the surface it equals 1 - t^2.
    pub fn implicit(&self, p: &Point3<f64>) -> f64 {
        let q = self.unscaled(p);
        let a = self.angles(&q, false);
        let rho2 = q.x * q.x + q.y * q.y;
        1.0 - (rho2 + a.r1 * a.r1 * q.z * q.z) / (a.r1 * a.r1 * a.r2 * a.r2)
    }

    /// The radial implicit function of seed 000 eq. 7 (seed 001 eq. 3), F2 = 1 - OP/OI with I the
    /// surface point on the half-line [OP): 1 - |P| / (r2 sqrt(cos^2 phi (r1^2 - 1) + 1)).
    pub fn radial(&self, p: &Point3<f64>) -> f64 {
        let q = self.unscaled(p);
        let a = self.angles(&q, false);
        let spread = a.cos_phi * a.cos_phi * (a.r1 * a.r1 - 1.0) + 1.0;
        1.0 - q.coords.norm() / (a.r2 * spread.sqrt())
    }

    /// The gradient of [`Self::implicit`] with respect to the (scaled) point, by the chain rule
    /// through the angles of eq. 8. Not defined on the z axis, where theta is not.
    pub fn implicit_gradient(&self, p: &Point3<f64>) -> Vector3<f64> {
        let q = self.unscaled(p);
        let a = self.angles(&q, true);
        let (d_theta, d_phi) = self.angle_gradients(&q, &a);
        let rho2 = q.x * q.x + q.y * q.y;
        let (r1s, r2s) = (a.r1 * a.r1, a.r2 * a.r2);
        // F1 = 1 - rho^2 / (r1^2 r2^2) - z^2 / r2^2.
        let direct = Vector3::new(
            2.0 * q.x / (r1s * r2s),
            2.0 * q.y / (r1s * r2s),
            2.0 * q.z / r2s,
        );
        let by_theta = -2.0 * rho2 * a.dr1 / (r1s * a.r1 * r2s);
        let by_phi = -2.0 * (rho2 / r1s + q.z * q.z) * a.dr2 / (r2s * a.r2);
        self.rescaled(-(direct + by_theta * d_theta + by_phi * d_phi))
    }

    /// The gradient of [`Self::radial`] with respect to the (scaled) point. Not defined on the z axis.
    pub fn radial_gradient(&self, p: &Point3<f64>) -> Vector3<f64> {
        self.radial_and_gradient(p).1
    }

    /// [`Self::radial`] and [`Self::radial_gradient`] together, computing the angles of eq. 8 once
    /// (the distance search evaluates both at every Newton step).
    pub fn radial_and_gradient(&self, p: &Point3<f64>) -> (f64, Vector3<f64>) {
        let q = self.unscaled(p);
        let a = self.angles(&q, true);
        let (d_theta, d_phi) = self.angle_gradients(&q, &a);
        let (sin_phi, cos_phi) = (a.sin_phi, a.cos_phi);
        let spread = cos_phi * cos_phi * (a.r1 * a.r1 - 1.0) + 1.0;
        let norm2 = q.coords.norm_squared();
        let t = norm2.sqrt() / (a.r2 * spread.sqrt());
        // ln t = ln|q| - ln r2(phi) - ln(spread) / 2, spread = cos^2 phi (r1^2 - 1) + 1.
        let d_spread_d_theta = cos_phi * cos_phi * 2.0 * a.r1 * a.dr1;
        let d_spread_d_phi = -2.0 * cos_phi * sin_phi * (a.r1 * a.r1 - 1.0);
        let d_ln_t = q.coords / norm2
            - d_theta * (0.5 * d_spread_d_theta / spread)
            - d_phi * (a.dr2 / a.r2 + 0.5 * d_spread_d_phi / spread);
        (1.0 - t, self.rescaled(-t * d_ln_t))
    }

    fn unscaled(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::new(
            p.x / self.scale[0],
            p.y / self.scale[1],
            p.z / self.scale[2],
        )
    }

    /// Chain rule through q = p / scale.
    fn rescaled(&self, gradient_in_q: Vector3<f64>) -> Vector3<f64> {
        gradient_in_q.component_div(&Vector3::from(self.scale))
    }

    /// Seed 000 eq. 8: theta = atan(y / x) and tan phi = z r1(theta) cos(theta) / x. Since
    /// x = rho cos(theta) with rho = sqrt(x^2 + y^2), the latter is tan phi = z r1 / rho, in every quadrant and at
    /// x = 0. The angles are taken as their cos and sin (of atan2's angle: (1, 0) at the origin); a formula with
    /// m = 4 needs no more, the others turn them by m/4 from the angle itself.
    fn angles(&self, q: &Point3<f64>, derivatives: bool) -> Angles {
        let rho = (q.x * q.x + q.y * q.y).sqrt();
        let (cos_theta, sin_theta) = direction(q.x, q.y, rho);
        let (sin1, cos1) = self
            .r1
            .turned_direction(|| q.y.atan2(q.x), cos_theta, sin_theta);
        let (r1, dr1) = if derivatives {
            self.r1.radius_and_derivative_at(cos1, sin1)
        } else {
            (self.r1.radius_at(cos1, sin1), 0.0)
        };
        let u = q.z * r1;
        let (cos_phi, sin_phi) = direction(rho, u, (u * u + rho * rho).sqrt());
        let (sin2, cos2) = self.r2.turned_direction(|| u.atan2(rho), cos_phi, sin_phi);
        let (r2, dr2) = if derivatives {
            self.r2.radius_and_derivative_at(cos2, sin2)
        } else {
            (self.r2.radius_at(cos2, sin2), 0.0)
        };
        Angles {
            cos_phi,
            sin_phi,
            r1,
            dr1,
            r2,
            dr2,
        }
    }

    /// The gradients of theta and phi (eq. 8) with respect to the unscaled point.
    fn angle_gradients(&self, q: &Point3<f64>, a: &Angles) -> (Vector3<f64>, Vector3<f64>) {
        let rho2 = q.x * q.x + q.y * q.y;
        let rho = rho2.sqrt();
        let d_theta = Vector3::new(-q.y / rho2, q.x / rho2, 0.0);
        // phi = atan2(u, rho) with u = z r1(theta).
        let u = q.z * a.r1;
        let d_u = Vector3::new(0.0, 0.0, a.r1) + d_theta * (q.z * a.dr1);
        let d_rho = Vector3::new(q.x / rho, q.y / rho, 0.0);
        let d_phi = (d_u * rho - d_rho * u) / (u * u + rho2);
        (d_theta, d_phi)
    }
}

/// cos and sin of atan2(y, x), given the length of (x, y): (1, 0) at the origin, as atan2(0, 0) = 0.
fn direction(x: f64, y: f64, length: f64) -> (f64, f64) {
    if length > 0.0 {
        (x / length, y / length)
    } else {
        (1.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn formula(m: f64, n1: f64, n2: f64, n3: f64) -> Superformula {
        Superformula::new(m, n1, n2, n3, 1.0, 1.0).unwrap()
    }

    /// Shapes with m from 3 to 8 and coefficients from 0.5 to 20, some stretched.
    fn shapes() -> Vec<Supershape> {
        vec![
            Supershape {
                r1: formula(3.0, 0.5, 1.0, 1.5),
                r2: formula(4.0, 2.0, 2.0, 2.0),
                scale: [1.0; 3],
            },
            Supershape {
                r1: formula(5.0, 2.0, 7.0, 7.0),
                r2: formula(6.0, 20.0, 20.0, 20.0),
                scale: [3.0, 2.0, 5.0],
            },
            Supershape {
                r1: formula(8.0, 1.0, 0.5, 4.0),
                r2: formula(4.0, 4.0, 1.0, 3.0),
                scale: [10.0; 3],
            },
            Supershape {
                r1: Superformula::new(6.0, 20.0, 15.0, 0.5, 1.5, 0.8).unwrap(),
                r2: formula(7.0, 3.0, 10.0, 2.0),
                scale: [0.5, 0.7, 1.2],
            },
        ]
    }

    /// Parameters off the poles and the z axis, where theta is undefined.
    fn parameters() -> impl Iterator<Item = (f64, f64)> {
        (0..40).flat_map(|i| {
            (0..19).map(move |j| {
                (
                    -PI + (i as f64 + 0.31) * 2.0 * PI / 40.0,
                    -FRAC_PI_2 + (j as f64 + 0.57) * PI / 20.0,
                )
            })
        })
    }

    /// Eq. 7 as printed, every angle by atan2 and every power by powf: what the fast paths (m = 4 read from
    /// the direction, integer exponents by multiplication) must reproduce.
    fn radial_as_printed(shape: &Supershape, p: &Point3<f64>) -> f64 {
        let r = |f: &Superformula, angle: f64| {
            let (sin, cos) = (f.m * angle / 4.0).sin_cos();
            ((cos / f.a).abs().powf(f.n2) + (sin / f.b).abs().powf(f.n3)).powf(-1.0 / f.n1)
        };
        let q = Point3::new(
            p.x / shape.scale[0],
            p.y / shape.scale[1],
            p.z / shape.scale[2],
        );
        let r1 = r(&shape.r1, q.y.atan2(q.x));
        let phi = (q.z * r1).atan2(q.x.hypot(q.y));
        let spread = phi.cos().powi(2) * (r1 * r1 - 1.0) + 1.0;
        1.0 - q.coords.norm() / (r(&shape.r2, phi) * spread.sqrt())
    }

    #[test]
    fn the_fast_paths_give_eq_7_as_printed() {
        // The shapes above, and a part's cylinder and box-like shapes (m = 4 in both formulas, exponents 2 and
        // 40), the lobes of the brake hub (m = 5, exponents 7).
        let mut all = shapes();
        all.push(Supershape {
            r1: Superformula::circle(),
            r2: formula(4.0, 40.0, 40.0, 40.0),
            scale: [12.0, 12.0, 20.0],
        });
        all.push(Supershape {
            r1: formula(4.0, 40.0, 40.0, 40.0),
            r2: formula(4.0, 40.0, 40.0, 40.0),
            scale: [16.0, 2.0, 4.0],
        });
        all.push(Supershape {
            r1: formula(5.0, 2.0, 7.0, 7.0),
            r2: Superformula::circle(),
            scale: [3.0; 3],
        });
        // Equal fractional exponents above 2 (the equal-exponent path, with powf where the ratio's power is not
        // negligible), with m != 4.
        all.push(Supershape {
            r1: formula(6.0, 3.5, 3.5, 3.5),
            r2: formula(4.0, 2.5, 2.5, 2.5),
            scale: [5.0, 4.0, 3.0],
        });
        for shape in &all {
            for k in 0..500 {
                let t = k as f64;
                let p = Point3::new(
                    (0.37 * t).sin() * 1.3 * shape.scale[0],
                    (0.71 * t).cos() * 1.1 * shape.scale[1],
                    (0.13 * t).sin() * 1.2 * shape.scale[2],
                );
                let expected = radial_as_printed(shape, &p);
                let got = shape.radial(&p);
                assert!(
                    (got - expected).abs() < 1e-13 * (1.0 + expected.abs()),
                    "{p}: {got} vs {expected}"
                );
                assert!(
                    (shape.radial_and_gradient(&p).0 - expected).abs()
                        < 1e-13 * (1.0 + expected.abs())
                );
            }
        }
    }

    #[test]
    fn parametric_points_lie_on_both_zero_sets() {
        for shape in shapes() {
            for (theta, phi) in parameters() {
                let p = shape.point(theta, phi);
                let (f1, f2) = (shape.implicit(&p), shape.radial(&p));
                assert!(
                    f1.abs() < 1e-9 && f2.abs() < 1e-9,
                    "{theta} {phi}: {f1} {f2}"
                );
            }
        }
    }

    #[test]
    fn the_unit_sphere_is_the_special_case() {
        let sphere = Supershape::sphere();
        for (theta, phi) in parameters() {
            let p = sphere.point(theta, phi);
            assert!((p.coords.norm() - 1.0).abs() < 1e-15);
            let inner = Point3::from(p.coords * 0.3);
            // F1 = 1 - |P|^2 and F2 = 1 - |P| on the sphere.
            assert!((sphere.implicit(&inner) - 0.91).abs() < 1e-14);
            assert!((sphere.radial(&inner) - 0.7).abs() < 1e-14);
        }
    }

    #[test]
    fn inside_is_positive_and_outside_negative() {
        for shape in shapes() {
            for (theta, phi) in parameters() {
                let p = shape.point(theta, phi).coords;
                let (inside, outside) = (Point3::from(p * 0.5), Point3::from(p * 2.0));
                // P = t I gives F1 = 1 - t^2 and F2 = 1 - t exactly.
                assert!((shape.implicit(&inside) - 0.75).abs() < 1e-9);
                assert!((shape.radial(&inside) - 0.5).abs() < 1e-9);
                assert!((shape.implicit(&outside) + 3.0).abs() < 1e-9);
                assert!((shape.radial(&outside) + 1.0).abs() < 1e-9);
            }
        }
    }

    /// Fourth-order central difference, so truncation stays far below the 1e-6 tolerance.
    fn numeric_gradient(f: impl Fn(&Point3<f64>) -> f64, p: &Point3<f64>, h: f64) -> Vector3<f64> {
        Vector3::from_fn(|i, _| {
            let at = |k: f64| {
                let mut q = *p;
                q[i] += k * h;
                f(&q)
            };
            (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * h)
        })
    }

    #[test]
    fn the_value_with_the_gradient_is_the_radial_function() {
        for shape in shapes() {
            for (theta, phi) in parameters().step_by(5) {
                let p = Point3::from(shape.point(theta, phi).coords * 1.3);
                let (value, _) = shape.radial_and_gradient(&p);
                assert!((value - shape.radial(&p)).abs() < 1e-14, "{value}");
            }
        }
    }

    #[test]
    fn analytic_gradients_match_central_differences() {
        for shape in shapes() {
            let size = shape.scale.iter().cloned().fold(0.0, f64::max);
            for (theta, phi) in parameters().step_by(7) {
                for t in [0.6, 1.0, 1.7] {
                    let p = Point3::from(shape.point(theta, phi).coords * t);
                    let h = 1e-5 * size;
                    for (analytic, numeric) in [
                        (
                            shape.implicit_gradient(&p),
                            numeric_gradient(|q| shape.implicit(q), &p, h),
                        ),
                        (
                            shape.radial_gradient(&p),
                            numeric_gradient(|q| shape.radial(q), &p, h),
                        ),
                    ] {
                        let error = (analytic - numeric).norm();
                        assert!(
                            error <= 1e-6 * analytic.norm(),
                            "{theta} {phi} {t}: {analytic} vs {numeric}"
                        );
                    }
                }
            }
        }
    }
}
