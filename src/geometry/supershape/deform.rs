//! Global deformations (Barr's scaling, tapering, twisting and bending, seed 000 section 3 and fig. 4)
//! and rigid transforms, each with its exact inverse. A globally deformed primitive is evaluated as
//! F(P) = F_can(D^-1(P)) (seed 000 eq. 9): the inverse brings a point of the model frame back into the
//! primitive's canonical frame.

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};
use serde::{Deserialize, Serialize};

/// One global deformation, acting on the canonical frame whose z axis is the primitive's axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Deformation {
    /// (x, y, z) -> (sx x, sy y, sz z); every factor nonzero.
    Scale([f64; 3]),
    /// Linear taper along z: (x, y, z) -> ((1 + kx z) x, (1 + ky z) y, z). Invertible where the
    /// factors 1 + k z are nonzero, i.e. for |z| < 1 / |k| on a primitive centred at the origin.
    Taper { kx: f64, ky: f64 },
    /// Twist about z by `rate` radians per unit of z: a rotation by rate * z of each section.
    Twist { rate: f64 },
    /// Circular bend of the z axis towards +x with curvature `curvature` (1 / radius): the point at
    /// height z goes to angle curvature * z on the circle of radius R = 1 / curvature centred at
    /// (R, 0, 0), at distance R - x from the centre. Invertible for x < R and |curvature z| < pi.
    Bend { curvature: f64 },
    /// A rotation followed by a translation.
    Rigid(Isometry3<f64>),
}

impl Deformation {
    /// D(P): from the canonical frame to the deformed one.
    pub fn apply(&self, p: &Point3<f64>) -> Point3<f64> {
        match *self {
            Deformation::Scale(s) => Point3::new(s[0] * p.x, s[1] * p.y, s[2] * p.z),
            Deformation::Taper { kx, ky } => {
                Point3::new((1.0 + kx * p.z) * p.x, (1.0 + ky * p.z) * p.y, p.z)
            }
            Deformation::Twist { rate } => rotate_about_z(p, rate * p.z),
            Deformation::Bend { curvature } => {
                if curvature == 0.0 {
                    return *p;
                }
                let radius = 1.0 / curvature;
                let (sin, cos) = (curvature * p.z).sin_cos();
                let from_centre = radius - p.x;
                Point3::new(radius - from_centre * cos, p.y, from_centre * sin)
            }
            Deformation::Rigid(iso) => iso * p,
        }
    }

    /// D^-1(P): from the deformed frame back to the canonical one.
    pub fn inverse(&self, p: &Point3<f64>) -> Point3<f64> {
        match *self {
            Deformation::Scale(s) => Point3::new(p.x / s[0], p.y / s[1], p.z / s[2]),
            Deformation::Taper { kx, ky } => {
                Point3::new(p.x / (1.0 + kx * p.z), p.y / (1.0 + ky * p.z), p.z)
            }
            Deformation::Twist { rate } => rotate_about_z(p, -rate * p.z),
            Deformation::Bend { curvature } => {
                if curvature == 0.0 {
                    return *p;
                }
                let radius = 1.0 / curvature;
                // Undo the polar map about the centre (R, 0, 0); for curvature < 0 the centre lies
                // on -x and the roles of the signs flip, which atan2 of the signed pair absorbs.
                let (along, across) = (radius - p.x, p.z);
                let angle = (curvature.signum() * across).atan2(curvature.signum() * along);
                let from_centre = curvature.signum() * along.hypot(across);
                Point3::new(radius - from_centre, p.y, angle / curvature)
            }
            Deformation::Rigid(iso) => iso.inverse_transform_point(p),
        }
    }

    /// The Jacobian of D^-1 at `p` (rows: canonical coordinates, columns: deformed ones), for the
    /// chain rule grad F(P) = J^T grad F_can(D^-1(P)).
    pub fn inverse_jacobian(&self, p: &Point3<f64>) -> Matrix3<f64> {
        match *self {
            Deformation::Scale(s) => {
                Matrix3::from_diagonal(&Vector3::new(1.0 / s[0], 1.0 / s[1], 1.0 / s[2]))
            }
            Deformation::Taper { kx, ky } => {
                let (fx, fy) = (1.0 + kx * p.z, 1.0 + ky * p.z);
                Matrix3::new(
                    1.0 / fx,
                    0.0,
                    -p.x * kx / (fx * fx),
                    0.0,
                    1.0 / fy,
                    -p.y * ky / (fy * fy),
                    0.0,
                    0.0,
                    1.0,
                )
            }
            Deformation::Twist { rate } => {
                let (sin, cos) = (-rate * p.z).sin_cos();
                // x' = cos a x - sin a y, y' = sin a x + cos a y with a = -rate z.
                Matrix3::new(
                    cos,
                    -sin,
                    (-sin * p.x - cos * p.y) * -rate,
                    sin,
                    cos,
                    (cos * p.x - sin * p.y) * -rate,
                    0.0,
                    0.0,
                    1.0,
                )
            }
            Deformation::Bend { curvature } => {
                if curvature == 0.0 {
                    return Matrix3::identity();
                }
                let radius = 1.0 / curvature;
                let sign = curvature.signum();
                let (along, across) = (radius - p.x, p.z);
                let h2 = along * along + across * across;
                let h = h2.sqrt();
                // x' = R - sign h, z' = atan2(sign across, sign along) / curvature.
                Matrix3::new(
                    sign * along / h,
                    0.0,
                    -sign * across / h,
                    0.0,
                    1.0,
                    0.0,
                    across / (h2 * curvature),
                    0.0,
                    along / (h2 * curvature),
                )
            }
            Deformation::Rigid(iso) => iso.rotation.inverse().to_rotation_matrix().into_inner(),
        }
    }
}

/// A chain of deformations applied in order: D = D_n o ... o D_1, so D^-1 undoes them from the last.
/// In a CSG tree each node's chain is inverted from the root down to the primitive (seed 000 eq. 9).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Deformations(pub Vec<Deformation>);

impl Deformations {
    /// D(P), the first deformation acting first.
    pub fn apply(&self, p: &Point3<f64>) -> Point3<f64> {
        self.0.iter().fold(*p, |q, d| d.apply(&q))
    }

    /// D^-1(P), undoing the last deformation first.
    pub fn inverse(&self, p: &Point3<f64>) -> Point3<f64> {
        self.0.iter().rev().fold(*p, |q, d| d.inverse(&q))
    }

    /// D^-1(P) and its Jacobian, by the chain rule through the chain from the last deformation.
    pub fn inverse_with_jacobian(&self, p: &Point3<f64>) -> (Point3<f64>, Matrix3<f64>) {
        self.0
            .iter()
            .rev()
            .fold((*p, Matrix3::identity()), |(q, jacobian), d| {
                (d.inverse(&q), d.inverse_jacobian(&q) * jacobian)
            })
    }
}

fn rotate_about_z(p: &Point3<f64>, angle: f64) -> Point3<f64> {
    let (sin, cos) = angle.sin_cos();
    Point3::new(cos * p.x - sin * p.y, sin * p.x + cos * p.y, p.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    fn rigid() -> Deformation {
        Deformation::Rigid(Isometry3::from_parts(
            Translation3::new(12.0, -4.5, 30.0),
            UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.8)
                * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), -2.1),
        ))
    }

    fn deformations() -> Vec<Deformation> {
        vec![
            Deformation::Scale([2.0, 0.5, 3.0]),
            Deformation::Taper { kx: 0.3, ky: -0.2 },
            Deformation::Twist { rate: 1.3 },
            Deformation::Bend { curvature: 0.25 },
            Deformation::Bend { curvature: -0.4 },
            Deformation::Bend { curvature: 0.0 },
            rigid(),
        ]
    }

    /// Points of a primitive of unit size, inside every deformation's domain.
    fn points() -> impl Iterator<Item = Point3<f64>> {
        (0..7).flat_map(|i| {
            (0..7).flat_map(move |j| {
                (0..7).map(move |k| {
                    Point3::new(
                        -1.0 + i as f64 / 3.0,
                        -1.0 + j as f64 / 3.0,
                        -1.0 + k as f64 / 3.0,
                    )
                })
            })
        })
    }

    #[test]
    fn every_deformation_inverts() {
        for d in deformations() {
            for p in points() {
                let back = d.inverse(&d.apply(&p));
                assert!((back - p).norm() < 1e-12, "{d:?} at {p}: {back}");
            }
        }
    }

    #[test]
    fn a_chain_inverts_in_reverse_order() {
        let chain = Deformations(deformations());
        for p in points() {
            assert!((chain.inverse(&chain.apply(&p)) - p).norm() < 1e-12);
            assert!((chain.apply(&chain.inverse(&p)) - p).norm() < 1e-12);
        }
    }

    #[test]
    fn inverse_jacobians_match_finite_differences() {
        let chain = Deformations(deformations());
        let h = 1e-6;
        for p in points() {
            let p = chain.apply(&p);
            let (_, jacobian) = chain.inverse_with_jacobian(&p);
            for axis in 0..3 {
                let mut step = Vector3::zeros();
                step[axis] = h;
                let column = (chain.inverse(&(p + step)) - chain.inverse(&(p - step))) / (2.0 * h);
                let error = (column - jacobian.column(axis)).norm();
                assert!(
                    error < 1e-6 * (1.0 + column.norm()),
                    "{p} axis {axis}: {error}"
                );
            }
        }
    }

    #[test]
    fn deformations_do_what_they_say() {
        let p = Point3::new(1.0, 0.0, 2.0);
        let tapered = Deformation::Taper { kx: 0.5, ky: 0.0 }.apply(&p);
        assert!((tapered - Point3::new(2.0, 0.0, 2.0)).norm() < 1e-15);
        // A quarter turn per unit z rotates the section at z = 2 by half a turn.
        let twisted = Deformation::Twist {
            rate: std::f64::consts::FRAC_PI_2,
        }
        .apply(&p);
        assert!((twisted - Point3::new(-1.0, 0.0, 2.0)).norm() < 1e-15);
        // The axis point at arc length pi R / 2 lands a quarter circle round, at (R, 0, R).
        let radius = 4.0;
        let axis = Point3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2 * radius);
        let bent = Deformation::Bend {
            curvature: 1.0 / radius,
        }
        .apply(&axis);
        assert!(
            (bent - Point3::new(radius, 0.0, radius)).norm() < 1e-14,
            "{bent}"
        );
    }
}
