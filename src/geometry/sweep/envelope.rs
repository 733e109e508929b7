//! Closed forms of the envelopes swept by the ball. For any rigid motion the ball's body-frame normal field is
//! the unit sphere and its points are c(t) + r n, so the characteristic condition F = <omega x (x - c) + v, n> = 0
//! (seed 002 eq. 1 for a rigid motion) reduces to <v(t), n> = 0: the characteristic curve K^t is the great circle
//! of the ball perpendicular to the centre's velocity. The swept solid is the set of points within r of the
//! centre path, hence
//! - a ball on a line sweeps a capsule (cylinder with two hemispherical caps);
//! - a ball on an arc sweeps a section of a torus (tube radius r, centre-line radius R) with two hemispherical caps.

use nalgebra::{Point3, Unit, UnitQuaternion, Vector3};

use super::closest::{closest_between_segments, closest_on_segment};

/// The points within `radius_mm` of the segment [a, b].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    pub a: Point3<f64>,
    pub b: Point3<f64>,
    pub radius_mm: f64,
}

impl Capsule {
    /// Signed distance from p to the capsule's surface (negative inside).
    pub fn point_distance(&self, p: &Point3<f64>) -> f64 {
        (p - closest_on_segment(p, &self.a, &self.b).0).norm() - self.radius_mm
    }

    /// Distance from the segment [p, q] to the capsule's surface, negative when the segment enters it.
    pub fn segment_distance(&self, p: &Point3<f64>, q: &Point3<f64>) -> f64 {
        let (s, t) = closest_between_segments(p, q, &self.a, &self.b);
        (s - t).norm() - self.radius_mm
    }

    pub fn volume(&self) -> f64 {
        let r = self.radius_mm;
        std::f64::consts::PI * r * r * ((self.b - self.a).norm() + 4.0 / 3.0 * r)
    }
}

/// The region swept by a ball of radius `ball_radius_mm` whose centre runs along the arc of
/// [`super::motion::Motion::Arc`] (the ball centre turned about the axis through `centre`, by `angle_rad`).
#[derive(Debug, Clone, PartialEq)]
pub struct ArcSweptBall {
    pub centre: Point3<f64>,
    pub axis: Unit<Vector3<f64>>,
    pub start: Point3<f64>,
    pub angle_rad: f64,
    pub ball_radius_mm: f64,
}

/// A point of a closed-form envelope surface with its outward unit normal and the area density of the
/// parametrisation (dA = density du dv), for integrals over the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceSample {
    pub point: Point3<f64>,
    pub normal: Vector3<f64>,
    pub area_density: f64,
}

/// Which end cap of a swept ball.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    Start,
    End,
}

impl ArcSweptBall {
    /// Height of the arc's plane along the axis, measured from `centre`.
    fn height(&self) -> f64 {
        (self.start - self.centre).dot(&self.axis)
    }

    /// Unit radial direction of the ball centre at time t (from the axis towards the centre).
    fn radial(&self, t: f64) -> Vector3<f64> {
        let r = self.start - self.centre;
        let in_plane = r - self.axis.into_inner() * r.dot(&self.axis);
        UnitQuaternion::from_axis_angle(&self.axis, self.angle_rad * t) * in_plane.normalize()
    }

    /// The centre-line radius R.
    pub fn path_radius_mm(&self) -> f64 {
        let r = self.start - self.centre;
        (r - self.axis.into_inner() * r.dot(&self.axis)).norm()
    }

    pub fn ball_centre(&self, t: f64) -> Point3<f64> {
        self.centre
            + self.axis.into_inner() * self.height()
            + self.radial(t) * self.path_radius_mm()
    }

    /// Unit direction of travel of the ball centre at time t.
    fn direction(&self, t: f64) -> Vector3<f64> {
        self.axis.cross(&self.radial(t)) * self.angle_rad.signum()
    }

    /// Distance from p to the centre path (the arc).
    pub fn distance_to_path(&self, p: &Point3<f64>) -> f64 {
        let rel = p - self.centre;
        let h = rel.dot(&self.axis) - self.height();
        let in_plane = rel - self.axis.into_inner() * rel.dot(&self.axis);
        let rho = in_plane.norm();
        let big_r = self.path_radius_mm();
        let e1 = self.radial(0.0);
        let e2 = self.axis.cross(&e1) * self.angle_rad.signum();
        // Angle of p about the axis, measured in the arc's direction of travel, in [0, 2 pi).
        let phi = in_plane
            .dot(&e2)
            .atan2(in_plane.dot(&e1))
            .rem_euclid(std::f64::consts::TAU);
        if rho > 0.0 && phi <= self.angle_rad.abs() {
            ((rho - big_r).powi(2) + h * h).sqrt()
        } else {
            // Off the arc's angular range (or on the axis) the nearest arc point is an end point.
            (p - self.ball_centre(0.0))
                .norm()
                .min((p - self.ball_centre(1.0)).norm())
        }
    }

    /// Signed distance from p to the swept solid's surface (negative inside).
    pub fn point_distance(&self, p: &Point3<f64>) -> f64 {
        self.distance_to_path(p) - self.ball_radius_mm
    }

    /// The characteristic circle K^t: centre, unit normal of its plane (the direction of travel) and radius.
    pub fn characteristic_circle(&self, t: f64) -> (Point3<f64>, Vector3<f64>, f64) {
        (self.ball_centre(t), self.direction(t), self.ball_radius_mm)
    }

    /// Whether the closed form of the volume holds: the tube does not reach the axis (r < R) and the caps, which
    /// reach asin(r / R) beyond the arc's ends about the axis, overlap neither each other nor the tube.
    pub fn is_simple(&self) -> bool {
        let (r, big_r) = (self.ball_radius_mm, self.path_radius_mm());
        r < big_r && self.angle_rad.abs() + 2.0 * (r / big_r).asin() <= std::f64::consts::TAU
    }

    /// Volume by Pappus's theorem (disc of area pi r^2 whose centroid travels R |theta|) plus the two half balls;
    /// `None` when the sweep overlaps itself (see [`Self::is_simple`]).
    pub fn volume(&self) -> Option<f64> {
        let r = self.ball_radius_mm;
        self.is_simple().then(|| {
            std::f64::consts::PI
                * r
                * r
                * (self.path_radius_mm() * self.angle_rad.abs() + 4.0 / 3.0 * r)
        })
    }

    /// The torus-section part of the envelope, the union of the characteristic circles: at time t in [0, 1] and
    /// angle psi around the circle (psi = 0 pointing away from the axis).
    pub fn tube_sample(&self, t: f64, psi: f64) -> SurfaceSample {
        let (r, big_r) = (self.ball_radius_mm, self.path_radius_mm());
        let normal = self.radial(t) * psi.cos() + self.axis.into_inner() * psi.sin();
        SurfaceSample {
            point: self.ball_centre(t) + normal * r,
            normal,
            area_density: r * (big_r + r * psi.cos()) * self.angle_rad.abs(),
        }
    }

    /// The hemispherical cap at one end: polar angle alpha in [0, pi / 2] from the outward direction of travel,
    /// azimuth beta.
    pub fn cap_sample(&self, end: End, alpha: f64, beta: f64) -> SurfaceSample {
        let r = self.ball_radius_mm;
        let (t, outward) = match end {
            End::Start => (0.0, -self.direction(0.0)),
            End::End => (1.0, self.direction(1.0)),
        };
        let e1 = self.radial(t);
        let e2 = outward.cross(&e1);
        let normal = outward * alpha.cos() + (e1 * beta.cos() + e2 * beta.sin()) * alpha.sin();
        SurfaceSample {
            point: self.ball_centre(t) + normal * r,
            normal,
            area_density: r * r * alpha.sin(),
        }
    }
}
