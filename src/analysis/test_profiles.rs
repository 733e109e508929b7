//! Synthetic master profiles for the analysis tests: the sections x = 100 .. 500 mm of an elliptic "blade" whose
//! semi-axes and centre change along x, so that its surface normals lean along x as a twisted blade's do. The
//! ellipses give exact answers: a point moved along an ellipse's normal by d (less than the smallest radius of
//! curvature, 1.28 mm here) is exactly |d| from it.

use std::sync::OnceLock;

use nalgebra::{Point3, Vector2, Vector3};

use super::reference::{teach, MasterProfile, Reference, ReferenceSettings};
use crate::geometry::fit3l::FitMethod;

/// Points per taught profile.
pub const TAUGHT_POINTS: usize = 240;
pub const SETTINGS: ReferenceSettings = ReferenceSettings::ImplicitPolynomial {
    degree: 4,
    method: FitMethod::Orthogonal,
    nominal_spacing_mm: 5.0,
};

/// The section at x of (y - cy(x))^2 / a(x)^2 + (z - cz(x))^2 / b(x)^2 = 1.
pub struct Ellipse {
    pub x: f64,
}

impl Ellipse {
    pub fn stack() -> Vec<Ellipse> {
        (1..=5)
            .map(|k| Ellipse {
                x: 100.0 * k as f64,
            })
            .collect()
    }

    pub fn name(&self) -> String {
        format!("x{}", self.x)
    }

    /// Semi-axes a, b and centre (cy, cz) at x = 0, and their slopes along x.
    const AT_ZERO: (f64, f64, [f64; 2]) = (30.0, 6.0, [0.0, 0.0]);
    const SLOPES: (f64, f64, [f64; 2]) = (0.06, 0.008, [0.02, -0.01]);

    fn shape(&self) -> (f64, f64, Vector2<f64>) {
        let ((a, b, [cy, cz]), (da, db, [dcy, dcz])) = (Self::AT_ZERO, Self::SLOPES);
        let x = self.x;
        (
            a + da * x,
            b + db * x,
            Vector2::new(cy + dcy * x, cz + dcz * x),
        )
    }

    pub fn point(&self, t: f64) -> Point3<f64> {
        let (a, b, c) = self.shape();
        Point3::new(self.x, c.x + a * t.cos(), c.y + b * t.sin())
    }

    /// The outward unit normal of the ellipse in its plane.
    pub fn normal_in_plane(&self, t: f64) -> Vector2<f64> {
        let (a, b, _) = self.shape();
        Vector2::new(t.cos() / a, t.sin() / b).normalize()
    }

    /// The outward unit normal of the 3-D surface, which leans along x.
    pub fn surface_normal(&self, t: f64) -> Vector3<f64> {
        let (a, b, _) = self.shape();
        let (da, db, [dcy, dcz]) = Self::SLOPES;
        let (u, v) = (t.cos(), t.sin());
        // Gradient of the implicit surface at the point (y - cy = a u, z - cz = b v), halved.
        let along_x = -(u * dcy / a) - u * u * da / a - v * dcz / b - v * v * db / b;
        Vector3::new(along_x, u / a, v / b).normalize()
    }

    /// The point at parameter t moved by `d` mm along the in-plane normal.
    pub fn offset_point(&self, t: f64, d: f64) -> Point3<f64> {
        let n = self.normal_in_plane(t);
        self.point(t) + Vector3::new(0.0, n.x, n.y) * d
    }

    /// Unsigned distance from (y, z) to the ellipse, by a polyline of 20 000 chords (their sag is below 0.03 um).
    pub fn distance_in_plane(&self, y: f64, z: f64) -> f64 {
        let chords = 20_000;
        let at = |k: usize| {
            let p = self.point(std::f64::consts::TAU * k as f64 / chords as f64);
            Vector2::new(p.y, p.z)
        };
        let q = Vector2::new(y, z);
        (0..chords)
            .map(|k| {
                let (s, e) = (at(k), at(k + 1));
                let along = ((q - s).dot(&(e - s)) / (e - s).norm_squared()).clamp(0.0, 1.0);
                (q - (s + (e - s) * along)).norm()
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The master's scan of this section: evenly spaced in the parameter, with 3-D surface normals.
    pub fn master_profile(&self, count: usize) -> MasterProfile {
        let ts = (0..count).map(|k| std::f64::consts::TAU * k as f64 / count as f64);
        MasterProfile {
            name: self.name(),
            x_mm: self.x,
            points: ts.clone().map(|t| self.point(t)).collect(),
            normals: ts.map(|t| self.surface_normal(t)).collect(),
        }
    }
}

/// The reference taught once from the five ellipses, shared by the tests (an orthogonal fit takes a while).
pub fn taught_ellipses() -> &'static Reference {
    static REFERENCE: OnceLock<Reference> = OnceLock::new();
    REFERENCE.get_or_init(|| {
        let profiles: Vec<MasterProfile> = Ellipse::stack()
            .iter()
            .map(|e| e.master_profile(TAUGHT_POINTS))
            .collect();
        teach("ellipse-blade", &profiles, &SETTINGS).expect("the ellipses teach")
    })
}
