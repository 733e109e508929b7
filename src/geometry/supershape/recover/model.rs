//! One supershape as the parameter vector of its recovery, and the radial implicit function of seed 001 eq. 3
//! as a function of that vector. The function is generic over the number type so that one piece of code gives
//! both the residuals (f64) and their exact Jacobian (forward-mode dual numbers from num-dual): the partials of
//! eq. 1 in the exponents, through both angles of eq. 8, are a page of chain rule each that a dual number
//! carries for free.

use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion};
use num_dual::DualNum;

use crate::geometry::supershape::deform::{Deformation, Deformations};
use crate::geometry::supershape::formula::Superformula;
use crate::geometry::supershape::shape::Supershape;

/// The parameters of one supershape: centre (3), rotation from the start frame as a Gibbs vector (3), the
/// logarithms of the sizes a1, a2, a3 (3) and of the exponents n1, n2, n3 of r1 (3) and of r2 (3), the latter as
/// l with n = `SMALLEST_EXPONENT` + exp(l). Logarithms keep sizes and exponents positive (the issue's
/// reparametrisation); the Gibbs vector g, the rotation of the
/// unit quaternion (1, g) / |(1, g)|, is smooth everywhere and covers every turn below a half turn from the
/// start, which the starts of the recovery are within.
pub const PARAMS: usize = 15;

/// The exponents stay above this: as n1 falls towards 0, r = (..)^(-1/n1) overflows to infinity or zero and the
/// residuals become NaN, a cliff a minimisation from a poor start walks off; mechanical parts need n >= 0.5.
pub const SMALLEST_EXPONENT: f64 = 0.25;

/// Cosines and sines below this are taken as this: |t|^n for n < 1 has an infinite slope at 0, and the points
/// that fall exactly on such a corner would stop the minimisation with a NaN.
const SMALLEST_TRIG: f64 = 1e-12;

/// Which radius the residuals use: seed 001 section 4 fits the rational supershape (eqs. 8-9) in the first
/// iterations, where the powers of eq. 1 make the cost steep and ill-conditioned, then the superformula itself.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Radius {
    Rational,
    Standard,
}

/// What stays fixed during one minimisation: the symmetry numbers m1, m2 (integers, seed 001 section 3) and
/// the start frame that the Gibbs vector turns.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub symmetry: [u32; 2],
    pub start: Rotation3<f64>,
}

/// A point of the parameter space, with the frame it is relative to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    pub frame: Frame,
    pub params: [f64; PARAMS],
}

impl Candidate {
    /// The sizes a1, a2, a3.
    pub fn sizes(&self) -> [f64; 3] {
        [
            self.params[6].exp(),
            self.params[7].exp(),
            self.params[8].exp(),
        ]
    }

    /// The six exponents n1, n2, n3 of r1 and of r2.
    pub fn exponents(&self) -> [f64; 6] {
        std::array::from_fn(|k| SMALLEST_EXPONENT + self.params[9 + k].exp())
    }

    /// The rotation from the canonical frame of the supershape to the frame of the points.
    pub fn rotation(&self) -> Rotation3<f64> {
        let g = &self.params[3..6];
        let turn =
            UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(1.0, g[0], g[1], g[2]));
        self.frame.start * turn.to_rotation_matrix()
    }

    /// The supershape in its canonical frame and the rigid placement that puts it among the points.
    pub fn supershape(&self) -> (Supershape, Deformations) {
        let p = &self.params;
        let formula = |m: u32, n: &[f64]| Superformula {
            m: f64::from(m),
            n1: SMALLEST_EXPONENT + n[0].exp(),
            n2: SMALLEST_EXPONENT + n[1].exp(),
            n3: SMALLEST_EXPONENT + n[2].exp(),
            a: 1.0,
            b: 1.0,
        };
        let shape = Supershape {
            r1: formula(self.frame.symmetry[0], &p[9..12]),
            r2: formula(self.frame.symmetry[1], &p[12..15]),
            scale: self.sizes(),
        };
        let place = Isometry3::from_parts(
            Translation3::new(p[0], p[1], p[2]),
            UnitQuaternion::from_rotation_matrix(&self.rotation()),
        );
        (shape, Deformations(vec![Deformation::Rigid(place)]))
    }
}

/// The residual of seed 001 eq. 4 at one point: sqrt(a1 a2 a3) F2(P), so that the sum of squares is the cost
/// a1 a2 a3 sum F2^2, positive inside the supershape.
pub fn residual<T>(frame: &Frame, radius: Radius, params: &[T; PARAMS], point: &Point3<f64>) -> T
where
    T: DualNum<Primitive = f64> + Copy,
{
    let q = canonical(&frame.start, params, point);
    let value = radial(frame.symmetry, radius, params, &q);
    let log_volume = params[6] + params[7] + params[8];
    (log_volume * 0.5).exp() * value
}

/// The point in the unscaled canonical frame of a shape whose first nine parameters are its centre, its turn
/// from `start` as a Gibbs vector and the logarithms of its sizes: q_i = (R^T (P - c))_i / a_i.
pub(super) fn canonical<T>(start: &Rotation3<f64>, p: &[T], point: &Point3<f64>) -> [T; 3]
where
    T: DualNum<Primitive = f64> + Copy,
{
    let d = [-p[0] + point.x, -p[1] + point.y, -p[2] + point.z];
    // Into the start frame: its columns are the canonical axes in the points' frame.
    let start = start.matrix();
    let e: [T; 3] =
        std::array::from_fn(|i| d[0] * start[(0, i)] + d[1] * start[(1, i)] + d[2] * start[(2, i)]);
    // Then by the transpose of the Gibbs rotation, the quaternion (w, x, y, z) = (1, g).
    let (w, x, y, z) = (T::from(1.0), p[3], p[4], p[5]);
    let norm2 = w * w + x * x + y * y + z * z;
    let r = [
        [
            w * w + x * x - y * y - z * z,
            (x * y - w * z) * 2.0,
            (x * z + w * y) * 2.0,
        ],
        [
            (x * y + w * z) * 2.0,
            w * w - x * x + y * y - z * z,
            (y * z - w * x) * 2.0,
        ],
        [
            (x * z - w * y) * 2.0,
            (y * z + w * x) * 2.0,
            w * w - x * x - y * y + z * z,
        ],
    ];
    std::array::from_fn(|i| {
        let turned = (r[0][i] * e[0] + r[1][i] * e[1] + r[2][i] * e[2]) / norm2;
        turned / p[6 + i].exp()
    })
}

/// Seed 001 eq. 3 on the unscaled point: F2 = 1 - |q| / (r2(phi) sqrt(cos^2 phi (r1(theta)^2 - 1) + 1)), with
/// theta = atan2(y, x) and tan phi = z r1(theta) / sqrt(x^2 + y^2) (eq. 8 in every quadrant).
fn radial<T>(symmetry: [u32; 2], radius: Radius, p: &[T; PARAMS], q: &[T; 3]) -> T
where
    T: DualNum<Primitive = f64> + Copy,
{
    let theta = q[1].atan2(q[0]);
    let r1 = superformula(f64::from(symmetry[0]), [p[9], p[10], p[11]], theta, radius);
    let rho = (q[0] * q[0] + q[1] * q[1]).sqrt();
    let phi = (q[2] * r1).atan2(rho);
    let r2 = superformula(f64::from(symmetry[1]), [p[12], p[13], p[14]], phi, radius);
    let cos_phi = phi.cos();
    let spread = cos_phi * cos_phi * (r1 * r1 - 1.0) + 1.0;
    let norm = (rho * rho + q[2] * q[2]).sqrt();
    -(norm / (r2 * spread.sqrt())) + 1.0
}

/// r(angle) of seed 001 eq. 1 with a = b = 1 (the sizes carry the scale), or its rational form (eqs. 8-9, with
/// the factor 1/2 of W as `RationalSuperformula` explains), from the logarithms of n1, n2, n3.
fn superformula<T>(m: f64, log_n: [T; 3], angle: T, radius: Radius) -> T
where
    T: DualNum<Primitive = f64> + Copy,
{
    let (sin, cos) = (angle * (m / 4.0)).sin_cos();
    let floor = |t: T| {
        let t = t.abs();
        if t < SMALLEST_TRIG {
            T::from(SMALLEST_TRIG)
        } else {
            t
        }
    };
    let (u, v) = (floor(cos), floor(sin));
    let n = log_n.map(|l| l.exp() + SMALLEST_EXPONENT);
    match radius {
        Radius::Standard => {
            // (u^n2 + v^n3)^(-1/n1), every power through exp and ln since the exponents are variables.
            let sum = (u.ln() * n[1]).exp() + (v.ln() * n[2]).exp();
            (-(sum.ln() / n[0])).exp()
        }
        Radius::Rational => {
            let fraction = |t: T, power: T| t / (power + (-power + 1.0) * t);
            let w = (fraction(u, n[1]) + fraction(v, n[2])) * 0.5;
            let root_of_half = (-(n[0].recip() * std::f64::consts::LN_2)).exp();
            root_of_half * ((n[0] * w).recip() + 1.0 - n[0].recip())
        }
    }
}

/// The parameter l of an exponent n = `SMALLEST_EXPONENT` + exp(l) (n must be above `SMALLEST_EXPONENT`).
pub fn exponent_parameter(n: f64) -> f64 {
    (n - SMALLEST_EXPONENT).ln()
}

/// The parameters of a supershape placed by a rigid transform, relative to `frame` (whose symmetry numbers
/// must be the supershape's): the inverse of [`Candidate::supershape`], for tests that start from a known model.
#[cfg(test)]
pub fn candidate_of(
    shape: &Supershape,
    rotation: &Rotation3<f64>,
    centre: &nalgebra::Vector3<f64>,
    frame: Frame,
) -> Candidate {
    let turn = UnitQuaternion::from_rotation_matrix(&(frame.start.inverse() * rotation));
    // (w, x, y, z) and (-w, -x, -y, -z) are the same turn; the Gibbs vector is x / w for the positive w.
    let q = if turn.w < 0.0 {
        -turn.into_inner()
    } else {
        turn.into_inner()
    };
    let log = |f: &Superformula| [f.n1, f.n2, f.n3].map(exponent_parameter);
    let mut params = [0.0; PARAMS];
    params[..3].copy_from_slice(centre.as_slice());
    params[3..6].copy_from_slice(&[q.i / q.w, q.j / q.w, q.k / q.w]);
    params[6..9].copy_from_slice(&shape.scale.map(f64::ln));
    params[9..12].copy_from_slice(&log(&shape.r1));
    params[12..15].copy_from_slice(&log(&shape.r2));
    Candidate { frame, params }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::supershape::csg::Node;
    use crate::geometry::supershape::formula::RationalSuperformula;
    use nalgebra::Vector3;
    use num_dual::DualSVec64;

    fn candidate() -> Candidate {
        let frame = Frame {
            symmetry: [6, 4],
            start: Rotation3::from_euler_angles(0.3, -0.2, 0.9),
        };
        let shape = Supershape {
            r1: Superformula::new(6.0, 3.0, 5.0, 4.0, 1.0, 1.0).unwrap(),
            r2: Superformula::new(4.0, 2.5, 3.0, 3.5, 1.0, 1.0).unwrap(),
            scale: [12.0, 11.0, 7.0],
        };
        let rotation = Rotation3::from_euler_angles(0.1, -0.4, 1.2);
        candidate_of(&shape, &rotation, &Vector3::new(3.0, -2.0, 1.0), frame)
    }

    fn points() -> Vec<Point3<f64>> {
        (0..200)
            .map(|k| {
                let t = k as f64 * 0.37;
                Point3::new(
                    3.0 + 14.0 * t.sin(),
                    -2.0 + 12.0 * (1.3 * t).cos(),
                    1.0 + 8.0 * (0.7 * t).sin(),
                )
            })
            .collect()
    }

    /// The generic residual in f64 is the station's own radial function of the placed supershape, times the
    /// square root of the volume term; the placement round-trips through the parameters.
    #[test]
    fn the_residual_is_the_placed_supershapes_radial_function() {
        let c = candidate();
        let (shape, place) = c.supershape();
        let node = Node::supershape(shape, place);
        let weight = (shape.scale.iter().product::<f64>()).sqrt();
        for p in points() {
            let mine = residual(&c.frame, Radius::Standard, &c.params, &p);
            assert!(
                (mine - weight * node.value(&p)).abs() < 1e-11,
                "{mine} at {p}"
            );
        }
        let again = candidate_of(
            &shape,
            &c.rotation(),
            &Vector3::new(3.0, -2.0, 1.0),
            c.frame,
        );
        for (a, b) in again.params.iter().zip(&c.params) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    /// The rational radius here is `RationalSuperformula`'s.
    #[test]
    fn the_rational_radius_is_seed_001_eq_8() {
        let f = Superformula::new(5.0, 1.7, 2.5, 3.2, 1.0, 1.0).unwrap();
        for k in 0..50 {
            let theta = -3.0 + 0.12 * k as f64;
            let l = [f.n1, f.n2, f.n3].map(exponent_parameter);
            let mine = superformula(5.0, l, theta, Radius::Rational);
            assert!((mine - RationalSuperformula(f).radius(theta)).abs() < 1e-12);
            let standard = superformula(5.0, l, theta, Radius::Standard);
            assert!((standard - f.radius(theta)).abs() < 1e-12);
        }
    }

    /// The dual numbers' Jacobian matches central differences in every parameter, for both radii.
    #[test]
    fn dual_jacobians_match_central_differences() {
        let c = candidate();
        for radius in [Radius::Rational, Radius::Standard] {
            for p in points().iter().step_by(7) {
                let duals: [DualSVec64<PARAMS>; PARAMS] =
                    std::array::from_fn(|j| DualSVec64::from_re(c.params[j]).derivative(j));
                let value = residual(&c.frame, radius, &duals, p);
                let gradient = value
                    .eps
                    .unwrap_generic(nalgebra::Const::<PARAMS>, nalgebra::U1);
                for j in 0..PARAMS {
                    let h = 1e-6;
                    let (mut up, mut down) = (c.params, c.params);
                    up[j] += h;
                    down[j] -= h;
                    let numeric = (residual(&c.frame, radius, &up, p)
                        - residual(&c.frame, radius, &down, p))
                        / (2.0 * h);
                    assert!(
                        (gradient[j] - numeric).abs() < 1e-5 * (1.0 + numeric.abs()),
                        "{radius:?} parameter {j}: {} vs {numeric}",
                        gradient[j]
                    );
                }
            }
        }
    }
}
