//! The parts on the simulated table, as analytic ground truth in machine coordinates (millimetres).
//!
//! Both parts are stacks of plane sections along an axis (a blade along its radius, the supershape nut along
//! its height). The simulator treats each as locally prismatic: the distance from a point is measured in the
//! section plane through that point, with flat caps at the ends. That makes every section exact (a scan in a
//! section plane touches exactly the analytic section, as the station's 2-D profile fits assume) at the cost
//! of ignoring how the surface leans along the axis, a second-order effect on a slender blade.

pub mod curve;
pub mod propeller;
pub mod supershape;

use std::sync::Arc;

use nalgebra::{Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;

use curve::{ClosedCurve, SampledCurve};

/// Where a part sits on the table: its own origin in machine coordinates and its turn about the machine's
/// z axis.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pose {
    pub x_mm: f64,
    pub y_mm: f64,
    pub z_mm: f64,
    pub rot_z_deg: f64,
}

impl Pose {
    pub fn isometry(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(self.x_mm, self.y_mm, self.z_mm),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.rot_z_deg.to_radians()),
        )
    }
}

/// An orthonormal right-handed frame: `w = u x v`. A section lives in its (u, v) plane at w = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub origin: Point3<f64>,
    pub u: Vector3<f64>,
    pub v: Vector3<f64>,
    pub w: Vector3<f64>,
}

impl Frame {
    /// The frame's axes and origin moved by `pose`.
    fn placed(
        origin: Point3<f64>,
        u: Vector3<f64>,
        v: Vector3<f64>,
        pose: &Isometry3<f64>,
    ) -> Self {
        let (u, v) = (pose * u, pose * v);
        Frame {
            origin: pose * origin,
            u,
            v,
            w: u.cross(&v),
        }
    }

    /// Coordinates (u, v, w) of a machine point.
    pub fn local(&self, p: &Point3<f64>) -> Vector3<f64> {
        let d = p - self.origin;
        Vector3::new(d.dot(&self.u), d.dot(&self.v), d.dot(&self.w))
    }

    /// The machine point at (u, v, w).
    pub fn world(&self, u: f64, v: f64, w: f64) -> Point3<f64> {
        self.origin + self.u * u + self.v * v + self.w * w
    }

    /// A direction given in (u, v, w), in machine coordinates.
    pub fn world_dir(&self, u: f64, v: f64, w: f64) -> Vector3<f64> {
        self.u * u + self.v * v + self.w * w
    }

    /// The same frame slid along w.
    fn shifted(&self, w: f64) -> Self {
        Frame {
            origin: self.origin + self.w * w,
            ..*self
        }
    }
}

/// The nearest surface point to a query, the outward unit normal there, and the query's signed distance
/// (positive outside the material).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    pub point: Point3<f64>,
    pub normal: Vector3<f64>,
    pub signed_distance: f64,
}

/// A plane given by a point and a normal (any length but zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    pub point: Point3<f64>,
    pub normal: Vector3<f64>,
}

/// A boxed curve is a curve, so sections of different parts share one type.
pub type AnyCurve = Box<dyn ClosedCurve>;

impl ClosedCurve for AnyCurve {
    fn point(&self, s: f64) -> Point2<f64> {
        (**self).point(s)
    }
}

/// A planar section of a part: a closed curve in the (u, v) plane of `frame`.
#[derive(Clone)]
pub struct Section {
    pub frame: Frame,
    pub curve: Arc<SampledCurve<AnyCurve>>,
}

/// What the simulator asks of a part.
pub trait Part: Send + Sync {
    /// The nearest surface point to `p` (machine coordinates).
    fn nearest(&self, p: &Point3<f64>) -> SurfacePoint;

    /// The section of the part by `plane`, if the plane cuts the part where it has an analytic plane
    /// section (perpendicular to a blade's radius, or to the supershape's axis); `None` if it misses.
    fn section(&self, plane: &Plane) -> Option<Section>;
}

/// Whether two directions are parallel or opposite, within a hundredth of a degree.
fn parallel(a: &Vector3<f64>, b: &Vector3<f64>) -> bool {
    a.normalize().dot(&b.normalize()).abs() > 1.0 - 1.5e-8
}

/// Beyond this distance from the surface, mm, the direction to a point is a reliable normal.
const OFF_SURFACE: f64 = 1e-6;

/// The nearest point of a section curve in its plane: a sampled curve, or one derived from another by a
/// similarity (a blade's sections are one airfoil scaled, turned and shifted).
pub trait PlaneNearest {
    fn nearest(&self, query: &Point2<f64>) -> curve::Nearest;
}

impl<C: ClosedCurve> PlaneNearest for SampledCurve<C> {
    fn nearest(&self, query: &Point2<f64>) -> curve::Nearest {
        SampledCurve::nearest(self, query)
    }
}

/// The nearest point of a prism-like solid: sections perpendicular to the frame's w axis for w in
/// `w_range`, `section` being the one at the clamped w of `p`, closed by flat caps at both ends.
fn prism_nearest(
    frame: &Frame,
    w_range: (f64, f64),
    section: &impl PlaneNearest,
    p: &Point3<f64>,
) -> SurfacePoint {
    let local = frame.local(p);
    let (lo, hi) = w_range;
    let w = local.z.clamp(lo, hi);
    let beyond = local.z - w;
    let plane_nearest = section.nearest(&Point2::new(local.x, local.y));
    let on_curve = plane_nearest.on_curve;
    let to_curve = |distance: f64| {
        let point = frame.world(on_curve.point.x, on_curve.point.y, w);
        // Outside, the normal is the direction from the surface point to the query: the curve's own normal
        // there, except at a sharp edge, where a ball touching the edge is pushed back along this direction and
        // a CMM reports it (so that the centre minus one radius along it is the touched point).
        let normal = if distance > OFF_SURFACE {
            (p - point) / (p - point).norm()
        } else {
            frame.world_dir(on_curve.normal.x, on_curve.normal.y, 0.0)
        };
        SurfacePoint {
            point,
            normal,
            signed_distance: distance,
        }
    };
    let to_cap = |cap: f64, distance: f64| SurfacePoint {
        point: frame.world(local.x, local.y, cap),
        normal: frame.w * if cap == hi { 1.0 } else { -1.0 },
        signed_distance: distance,
    };
    if beyond == 0.0 {
        let (cap, cap_depth) = if hi - w < w - lo {
            (hi, hi - w)
        } else {
            (lo, w - lo)
        };
        if plane_nearest.signed_distance < 0.0 && cap_depth < -plane_nearest.signed_distance {
            return to_cap(cap, -cap_depth);
        }
        return to_curve(plane_nearest.signed_distance);
    }
    if plane_nearest.signed_distance <= 0.0 {
        return to_cap(w, beyond.abs());
    }
    let point = frame.world(on_curve.point.x, on_curve.point.y, w);
    let distance = (p - point).norm();
    SurfacePoint {
        point,
        normal: (p - point) / distance,
        signed_distance: distance,
    }
}

#[cfg(test)]
mod tests {
    use super::curve::Circle;
    use super::*;

    fn unit_frame() -> Frame {
        Frame {
            origin: Point3::origin(),
            u: Vector3::x(),
            v: Vector3::y(),
            w: Vector3::z(),
        }
    }

    #[test]
    fn a_cylinder_as_prism_has_exact_distances_to_side_and_caps() {
        let circle = SampledCurve::new(Circle(10.0));
        let frame = unit_frame();
        let side = prism_nearest(&frame, (0.0, 20.0), &circle, &Point3::new(13.0, 0.0, 10.0));
        assert!((side.signed_distance - 3.0).abs() < 1e-9);
        assert!((side.normal - Vector3::x()).norm() < 1e-6);
        let cap = prism_nearest(&frame, (0.0, 20.0), &circle, &Point3::new(1.0, 2.0, 22.0));
        assert!((cap.signed_distance - 2.0).abs() < 1e-9);
        assert_eq!(cap.normal, Vector3::z());
        let inside_near_cap =
            prism_nearest(&frame, (0.0, 20.0), &circle, &Point3::new(0.0, 0.0, 1.0));
        assert!((inside_near_cap.signed_distance + 1.0).abs() < 1e-9);
        assert_eq!(inside_near_cap.normal, -Vector3::z());
        let edge = prism_nearest(&frame, (0.0, 20.0), &circle, &Point3::new(13.0, 0.0, 24.0));
        assert!((edge.signed_distance - 5.0).abs() < 1e-9);
    }

    #[test]
    fn a_pose_turns_about_z_then_translates() {
        let pose = Pose {
            x_mm: 100.0,
            y_mm: 0.0,
            z_mm: -5.0,
            rot_z_deg: 90.0,
        };
        let moved = pose.isometry() * Point3::new(1.0, 0.0, 0.0);
        assert!((moved - Point3::new(100.0, 1.0, -5.0)).norm() < 1e-12);
        assert!(parallel(&Vector3::new(0.0, 0.0, -2.0), &Vector3::z()));
        assert!(!parallel(&Vector3::new(0.0, 0.01, 1.0), &Vector3::z()));
    }
}
