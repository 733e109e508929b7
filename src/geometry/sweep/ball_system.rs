//! The equations of seed 002 for the swept ball, in body coordinates (S(u, v) = r n(u, v), N = n):
//! - eq. (1), the envelope condition, for a rigid motion F = <Omega x S + w, N> with Omega = R^T omega and
//!   w = R^T v (body-frame twist); the rotational term vanishes on a sphere (S is parallel to N), so F = <w(t), n>.
//! - eq. (2), the perspective silhouette condition from the eye P, G = <A(t)S - P, A(t)N> = <r n - p(t), n>
//!   = r - <p(t), n> with p(t) = R^T (P - c(t)).
//! - eq. (3), H = F_u G_v - F_v G_u, the t-component of grad F x grad G, zero at the t-extreme points.
//!
//! The unit normal (rather than S_u x S_v, which vanishes at a chart's poles) and the two-chart atlas keep the
//! equations free of fake solutions.

use nalgebra::{Matrix2x3, Point3, Vector2, Vector3};

use super::charts::SpherePoint;
use super::motion::Motion;

/// Step of the central differences for the t-derivatives of the body-frame twist and eye (the pose is analytic
/// in t; the derivatives feed only Newton's Jacobian, never a residual).
const DT: f64 = 1e-6;

/// A point (u, v, t) of the ball's surface-time space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceTime {
    pub s: SpherePoint,
    pub t: f64,
}

impl SurfaceTime {
    pub fn normal(&self) -> Vector3<f64> {
        self.s.normal()
    }

    /// The point shifted by (du, dv, dt) in its chart.
    pub fn shifted(&self, d: &Vector3<f64>) -> Self {
        Self {
            s: SpherePoint {
                chart: self.s.chart,
                u: self.s.u + d.x,
                v: self.s.v + d.y,
            },
            t: self.t + d.z,
        }
    }
}

/// A ball of radius r moved by a smooth motion, seen from an optional eye point.
pub struct BallSweep<'a> {
    pub motion: &'a Motion,
    pub radius_mm: f64,
    pub eye: Option<Point3<f64>>,
}

/// Value and gradient in (u, v, t).
#[derive(Debug, Clone, Copy)]
pub struct Value {
    pub value: f64,
    pub gradient: Vector3<f64>,
}

impl BallSweep<'_> {
    /// Body-frame velocity of the ball centre, w(t) = R(t)^T v(t).
    pub fn body_velocity(&self, t: f64) -> Vector3<f64> {
        let pose = self.motion.pose(t);
        pose.rotation.inverse() * self.motion.twist(t).centre_velocity
    }

    /// Body-frame eye, p(t) = R(t)^T (P - c(t)).
    pub fn body_eye(&self, t: f64) -> Option<Vector3<f64>> {
        self.eye
            .map(|eye| self.motion.pose(t).inverse_transform_point(&eye).coords)
    }

    /// F of eq. (1) and its gradient.
    pub fn envelope(&self, q: &SurfaceTime) -> Value {
        let f = q.s.frame();
        let w = self.body_velocity(q.t);
        let w_t = (self.body_velocity(q.t + DT) - self.body_velocity(q.t - DT)) / (2.0 * DT);
        Value {
            value: w.dot(&f.n),
            gradient: Vector3::new(w.dot(&f.n_u), w.dot(&f.n_v), w_t.dot(&f.n)),
        }
    }

    /// G of eq. (2) and its gradient; panics without an eye point.
    pub fn silhouette(&self, q: &SurfaceTime) -> Value {
        let f = q.s.frame();
        let eye = |t| self.body_eye(t).expect("the silhouette needs an eye point");
        let p = eye(q.t);
        let p_t = (eye(q.t + DT) - eye(q.t - DT)) / (2.0 * DT);
        Value {
            value: self.radius_mm - p.dot(&f.n),
            gradient: Vector3::new(-p.dot(&f.n_u), -p.dot(&f.n_v), -p_t.dot(&f.n)),
        }
    }

    /// H of eq. (3).
    pub fn t_extremality(&self, q: &SurfaceTime) -> f64 {
        let (f, g) = (self.envelope(q).gradient, self.silhouette(q).gradient);
        f.x * g.y - f.y * g.x
    }

    /// The world point A(t)S(u, v).
    pub fn world_point(&self, q: &SurfaceTime) -> Point3<f64> {
        self.motion.pose(q.t) * Point3::from(q.normal() * self.radius_mm)
    }

    /// A bound of how far the world point moves per unit of (n, t): r per unit of n, the speed bound per unit t.
    pub fn speed_bound(&self) -> f64 {
        self.motion.max_point_speed(self.radius_mm)
    }
}

/// Two equations in (u, v, t) whose common zero set is a curve.
pub trait CurveSystem {
    fn evaluate(&self, q: &SurfaceTime) -> (Vector2<f64>, Matrix2x3<f64>);
}

fn stack(a: Value, b: Value) -> (Vector2<f64>, Matrix2x3<f64>) {
    (
        Vector2::new(a.value, b.value),
        Matrix2x3::from_rows(&[a.gradient.transpose(), b.gradient.transpose()]),
    )
}

/// The characteristic curve K^t at a fixed time: F = 0 and t - t0 = 0.
pub struct CharacteristicAt<'a> {
    pub sweep: &'a BallSweep<'a>,
    pub t: f64,
}

impl CurveSystem for CharacteristicAt<'_> {
    fn evaluate(&self, q: &SurfaceTime) -> (Vector2<f64>, Matrix2x3<f64>) {
        stack(
            self.sweep.envelope(q),
            Value {
                value: q.t - self.t,
                gradient: Vector3::z(),
            },
        )
    }
}

/// The silhouette curve of the envelope: F = 0 and G = 0.
pub struct SilhouetteSystem<'a> {
    pub sweep: &'a BallSweep<'a>,
}

impl CurveSystem for SilhouetteSystem<'_> {
    fn evaluate(&self, q: &SurfaceTime) -> (Vector2<f64>, Matrix2x3<f64>) {
        stack(self.sweep.envelope(q), self.sweep.silhouette(q))
    }
}
