//! A nut-like supershape solid (seed 000): Gielis' superformula outline
//! `r(theta) = (|cos(m theta / 4) / a|^n2 + |sin(m theta / 4) / b|^n3)^(-1/n1)`, scaled to size, extruded
//! along the part's z axis from z = 0 to its height. Its manufacturing error is a scale error and a turn
//! about its axis, so the made part is still an exact superformula solid.

use std::f64::consts::{PI, TAU};
use std::sync::Arc;

use nalgebra::{Isometry3, Point2, Point3, Vector3};
use serde::Deserialize;

use super::curve::{ClosedCurve, SampledCurve};
use super::{parallel, prism_nearest, AnyCurve, Frame, Part, Plane, Pose, Section, SurfacePoint};

/// The supershape as configured (`kind = "supershape"` in config/sims/*.toml).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SupershapeSpec {
    /// Symmetry number: 6 lobes for a nut.
    pub m: f64,
    pub a: f64,
    pub b: f64,
    pub n1: f64,
    pub n2: f64,
    pub n3: f64,
    /// The unit outline is scaled by this.
    pub size_mm: f64,
    pub height_mm: f64,
    /// Relative error of the size (0.001 = 0.1% too large).
    pub scale_error: f64,
    /// Turn of the made part about its axis against the nominal.
    pub rotation_error_deg: f64,
    pub pose: Pose,
}

/// Why a supershape configuration cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("supershape needs m, a, b, n1, size_mm and height_mm above zero, n2 and n3 at least zero")]
pub struct SupershapeError;

impl SupershapeSpec {
    /// The unit superformula radius at polar angle `theta`.
    pub fn unit_radius(&self, theta: f64) -> f64 {
        let quarter = self.m * theta / 4.0;
        let c = (quarter.cos() / self.a).abs().powf(self.n2);
        let s = (quarter.sin() / self.b).abs().powf(self.n3);
        (c + s).powf(-1.0 / self.n1)
    }

    /// Seed 000's radial implicit function of the made part (its eq. 7 in 2-D): `1 - |P| / r(theta_P)`,
    /// zero on the surface, positive inside. Points are in the part's own coordinates.
    pub fn implicit(&self, x: f64, y: f64) -> f64 {
        let theta = y.atan2(x) - self.rotation_error_deg.to_radians();
        1.0 - x.hypot(y) / (self.made_size() * self.unit_radius(theta))
    }

    fn made_size(&self) -> f64 {
        self.size_mm * (1.0 + self.scale_error)
    }
}

/// The made outline, counterclockwise in the polar angle.
pub struct Outline(SupershapeSpec);

impl ClosedCurve for Outline {
    fn point(&self, s: f64) -> Point2<f64> {
        let theta = TAU * s.rem_euclid(1.0) - PI;
        let radius = self.0.made_size() * self.0.unit_radius(theta);
        let turned = theta + self.0.rotation_error_deg.to_radians();
        Point2::new(radius * turned.cos(), radius * turned.sin())
    }
}

/// The supershape part, placed on the table.
pub struct Supershape {
    spec: SupershapeSpec,
    frame: Frame,
    outline: SampledCurve<Outline>,
}

impl Supershape {
    pub fn new(spec: SupershapeSpec) -> Result<Self, SupershapeError> {
        let positive = [
            spec.m,
            spec.a,
            spec.b,
            spec.n1,
            spec.size_mm,
            spec.height_mm,
        ];
        if positive.iter().any(|v| *v <= 0.0) || spec.n2 < 0.0 || spec.n3 < 0.0 {
            return Err(SupershapeError);
        }
        let pose: Isometry3<f64> = spec.pose.isometry();
        let frame = Frame::placed(Point3::origin(), Vector3::x(), Vector3::y(), &pose);
        Ok(Supershape {
            spec,
            frame,
            outline: SampledCurve::new(Outline(spec)),
        })
    }

    pub fn spec(&self) -> &SupershapeSpec {
        &self.spec
    }

    /// The frame of the outline at height 0: u, v the part's x, y; w its axis.
    pub fn frame(&self) -> Frame {
        self.frame
    }

    pub fn outline(&self) -> &SampledCurve<Outline> {
        &self.outline
    }
}

impl Part for Supershape {
    fn nearest(&self, p: &Point3<f64>) -> SurfacePoint {
        prism_nearest(&self.frame, (0.0, self.spec.height_mm), &self.outline, p)
    }

    fn section(&self, plane: &Plane) -> Option<Section> {
        let height = self.frame.local(&plane.point).z;
        let cuts =
            parallel(&plane.normal, &self.frame.w) && (0.0..=self.spec.height_mm).contains(&height);
        cuts.then(|| Section {
            frame: self.frame.shifted(height),
            curve: Arc::new(SampledCurve::new(Box::new(Outline(self.spec)) as AnyCurve)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nut() -> SupershapeSpec {
        SupershapeSpec {
            m: 6.0,
            a: 1.0,
            b: 1.0,
            n1: 8.0,
            n2: 4.0,
            n3: 4.0,
            size_mm: 40.0,
            height_mm: 25.0,
            scale_error: 0.002,
            rotation_error_deg: 0.5,
            pose: Pose {
                x_mm: 100.0,
                y_mm: -50.0,
                z_mm: 10.0,
                rot_z_deg: 30.0,
            },
        }
    }

    #[test]
    fn outline_points_satisfy_the_implicit_function() {
        let spec = nut();
        let outline = Outline(spec);
        for i in 0..360 {
            let p = outline.point(i as f64 / 360.0);
            assert!(spec.implicit(p.x, p.y).abs() < 1e-12, "at {i}");
            assert!(spec.implicit(p.x * 0.9, p.y * 0.9) > 0.0);
            assert!(spec.implicit(p.x * 1.1, p.y * 1.1) < 0.0);
        }
    }

    #[test]
    fn has_six_lobes() {
        let spec = nut();
        // The radius repeats every 60 degrees and differs between a lobe's middle and its side.
        for theta in [0.1, 0.7, 1.3] {
            let r = spec.unit_radius(theta);
            assert!((spec.unit_radius(theta + TAU / 6.0) - r).abs() < 1e-12);
        }
        assert!((spec.unit_radius(0.0) - spec.unit_radius(TAU / 12.0)).abs() > 0.01);
    }

    #[test]
    fn nearest_points_lie_on_the_placed_surface() {
        let part = Supershape::new(nut()).unwrap();
        let frame = part.frame();
        for s in [0.0, 0.13, 0.4, 0.77] {
            let on = part.outline().at(s);
            let surface = frame.world(on.point.x, on.point.y, 12.0);
            let outward = frame.world_dir(on.normal.x, on.normal.y, 0.0);
            let nearest = part.nearest(&(surface + outward * 2.0));
            assert!((nearest.signed_distance - 2.0).abs() < 1e-6);
            let local = frame.local(&nearest.point);
            assert!(part.spec().implicit(local.x, local.y).abs() < 1e-9);
        }
        let top = part.nearest(&frame.world(0.0, 0.0, 30.0));
        assert!((top.signed_distance - 5.0).abs() < 1e-9);
    }

    #[test]
    fn sections_exist_only_across_the_axis_within_the_height() {
        let part = Supershape::new(nut()).unwrap();
        let across = |z: f64| Plane {
            point: Point3::new(0.0, 0.0, z),
            normal: Vector3::z(),
        };
        assert!(part.section(&across(20.0)).is_some());
        assert!(part.section(&across(40.0)).is_none());
        let sideways = Plane {
            point: Point3::new(100.0, -50.0, 20.0),
            normal: Vector3::x(),
        };
        assert!(part.section(&sideways).is_none());
        assert!(Supershape::new(SupershapeSpec { m: 0.0, ..nut() }).is_err());
    }
}
