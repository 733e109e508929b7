//! A propeller of N blades about the hub axis z, as in seed 003: blade A points along the part's +x axis,
//! blade k is blade A turned k * 360/N degrees about z, and the profiles are the planar sections at constant
//! radius (x = 100, 200, ... mm for blade A). In a section plane the coordinates are u (the tangential
//! direction, +y for blade A) and v (+z, up the hub axis). Each section is a NACA 4-digit airfoil centred
//! at mid-chord on the hub's mid-plane, its chord turned by the blade angle
//! `atan(pitch / (2 pi r)) + twist(r)`, with chord and twist linear from root to tip.
//!
//! Each blade has its own manufacturing error, linear from root to tip: a shift along the hub axis (seed
//! 003's blade B lies 0.4 mm below A at the root and 1.0 mm at the tip) and a twist about mid-chord. A
//! shift rather than a normal offset keeps the section exact, and cannot pass through a sharp trailing
//! edge as an inward offset larger than half its thickness would.

use std::f64::consts::TAU;
use std::sync::Arc;

use nalgebra::{Isometry3, Point2, Point3, Vector2, Vector3};
use serde::Deserialize;

use super::curve::{sample_parameter, ClosedCurve, CurvePoint, Nearest, SampledCurve, SAMPLES};
use super::{
    parallel, prism_nearest, AnyCurve, Frame, Part, Plane, PlaneNearest, Pose, Section,
    SurfacePoint,
};
use crate::naca::{FoilStation, Naca4};

/// The propeller as configured (`kind = "propeller"` in config/sims/*.toml).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropellerSpec {
    pub blades: usize,
    /// The hub: a cylinder about z, centred on the part's origin.
    pub hub_radius_mm: f64,
    pub hub_height_mm: f64,
    /// The blades run from the root to the tip radius.
    pub root_radius_mm: f64,
    pub tip_radius_mm: f64,
    /// Four digits, e.g. "4412".
    pub naca: String,
    pub sharp_trailing_edge: bool,
    /// Chord at the root and at the tip.
    pub chord_mm: [f64; 2],
    /// Geometric pitch: the advance per turn that sets the blade angle atan(pitch / (2 pi r)).
    pub pitch_mm: f64,
    /// Designed twist added to the blade angle, at the root and at the tip.
    pub twist_deg: [f64; 2],
    /// One per blade, A first.
    pub blade_errors: Vec<BladeError>,
    pub pose: Pose,
}

/// A blade's manufacturing error, each pair given at the root and at the tip (linear between); each key but
/// `shift_mm` and `twist_deg` may be left out for no error.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BladeError {
    /// Shift along the hub axis (+z up): blade B of seed 003 is [-0.4, -1.0].
    pub shift_mm: [f64; 2],
    /// Extra turn of the section about its mid-chord.
    pub twist_deg: [f64; 2],
    /// The section's thickness (in mm) times this: 1.02 is 2 % thick.
    #[serde(default = "no_scale")]
    pub thickness_scale: [f64; 2],
    /// The chord's length times this, the thickness and camber in mm kept (the section stretched along its chord).
    #[serde(default = "no_scale")]
    pub chord_scale: [f64; 2],
    /// The mean line's camber (in mm) times this.
    #[serde(default = "no_scale")]
    pub camber_scale: [f64; 2],
    /// The geometric pitch that sets the blade angle, off by this percentage.
    #[serde(default)]
    pub pitch_error_pct: [f64; 2],
    /// The whole blade turned by this about the hub axis (counter-clockwise seen from +z), deg: an error of the
    /// angular spacing of the blades. A blade turned off its nominal radial plane has no analytic section in it
    /// (ScanInPlane across it fails with surface not found), so the master blade, which is taught, keeps 0.
    #[serde(default)]
    pub index_deg: f64,
}

fn no_scale() -> [f64; 2] {
    [1.0, 1.0]
}

/// Why a propeller configuration cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum PropellerError {
    #[error("naca = {0:?} is not four digits")]
    BadNaca(String),
    #[error("blade_errors has {found} entries; blades = {blades} needs one per blade")]
    ErrorsPerBlade { found: usize, blades: usize },
    #[error(
        "need 0 < hub_radius_mm <= root_radius_mm < tip_radius_mm, positive chords and hub height"
    )]
    BadDimensions,
    #[error("blade {blade}: thickness_scale, chord_scale and camber_scale must be positive")]
    BadScale { blade: usize },
}

/// One blade section at a radius: the airfoil placed in its (u, v) plane.
pub struct BladeSection {
    foil: Naca4,
    angle: f64,
    shift: f64,
}

impl ClosedCurve for BladeSection {
    fn point(&self, s: f64) -> Point2<f64> {
        self.placed(self.foil.point(s.rem_euclid(1.0)))
    }
}

impl BladeSection {
    /// A point of the airfoil in its own axes (leading edge at the origin) placed in the section plane: centred
    /// at mid-chord, turned and shifted.
    fn placed(&self, [x, y]: [f64; 2]) -> Point2<f64> {
        let x = x - self.foil.chord_mm / 2.0;
        let (sin, cos) = self.angle.sin_cos();
        Point2::new(x * cos - y * sin, x * sin + y * cos + self.shift)
    }
}

/// The propeller, placed on the table.
pub struct Propeller {
    spec: PropellerSpec,
    foil: Naca4,
    pose: Isometry3<f64>,
    /// The stations of the coarse samples of the airfoil, computed once: a blade section's samples are placed
    /// from them by its own thickness and camber, so a nearest-point query (a scan asks thousands of them)
    /// evaluates no trigonometry for its samples.
    stations: Vec<FoilStation>,
}

/// A blade section as a similarity of its airfoil at unit chord: exact, since a NACA section scales with its chord.
struct ScaledSection {
    unit: SampledCurve<BladeSection>,
    placement: Placement,
}

/// Where and how a blade's section lies at one radius.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Placement {
    chord: f64,
    /// The thickness and maximum camber as fractions of the chord.
    thickness: f64,
    max_camber: f64,
    angle: f64,
    shift: f64,
}

impl PlaneNearest for ScaledSection {
    fn nearest(&self, query: &Point2<f64>) -> Nearest {
        let Placement {
            chord,
            angle,
            shift,
            ..
        } = self.placement;
        let (sin, cos) = angle.sin_cos();
        let (u, v) = (query.x, query.y - shift);
        let in_unit = Point2::new(u * cos + v * sin, -u * sin + v * cos) / chord;
        let unit = self.unit.nearest(&in_unit);
        let turn = |w: Vector2<f64>| Vector2::new(w.x * cos - w.y * sin, w.x * sin + w.y * cos);
        let point = turn(unit.on_curve.point.coords * chord) + Vector2::new(0.0, shift);
        Nearest {
            on_curve: CurvePoint {
                s: unit.on_curve.s,
                point: Point2::from(point),
                normal: turn(unit.on_curve.normal),
            },
            signed_distance: unit.signed_distance * chord,
        }
    }
}

impl Propeller {
    pub fn new(spec: PropellerSpec) -> Result<Self, PropellerError> {
        let foil = Naca4::from_digits(&spec.naca, 1.0, spec.sharp_trailing_edge)
            .ok_or_else(|| PropellerError::BadNaca(spec.naca.clone()))?;
        if spec.blade_errors.len() != spec.blades {
            return Err(PropellerError::ErrorsPerBlade {
                found: spec.blade_errors.len(),
                blades: spec.blades,
            });
        }
        let sane = spec.hub_radius_mm > 0.0
            && spec.hub_radius_mm <= spec.root_radius_mm
            && spec.root_radius_mm < spec.tip_radius_mm
            && spec.chord_mm.iter().all(|c| *c > 0.0)
            && spec.hub_height_mm > 0.0;
        if !sane {
            return Err(PropellerError::BadDimensions);
        }
        // A scale is linear from root to tip: positive at both ends keeps it positive between.
        let scales = |e: &BladeError| [e.thickness_scale, e.chord_scale, e.camber_scale];
        if let Some(blade) = spec
            .blade_errors
            .iter()
            .position(|e| scales(e).iter().flatten().any(|s| s.is_nan() || *s <= 0.0))
        {
            return Err(PropellerError::BadScale { blade });
        }
        let pose = spec.pose.isometry();
        let stations = (0..SAMPLES)
            .map(|i| foil.station(sample_parameter(i)))
            .collect();
        Ok(Propeller {
            spec,
            foil,
            pose,
            stations,
        })
    }

    /// The blade's section at `radius` in its plane's (u, v) coordinates, with the blade's error.
    pub fn section_curve(&self, blade: usize, radius: f64) -> BladeSection {
        let placement = self.section_placement(blade, radius);
        BladeSection {
            foil: self.foil_of(&placement, placement.chord),
            angle: placement.angle,
            shift: placement.shift,
        }
    }

    /// The airfoil of a placed section, at `chord_mm`.
    fn foil_of(&self, placement: &Placement, chord_mm: f64) -> Naca4 {
        Naca4 {
            chord_mm,
            thickness: placement.thickness,
            max_camber: placement.max_camber,
            ..self.foil
        }
    }

    /// Chord, shape, turn and shift of the blade's section at `radius`.
    fn section_placement(&self, blade: usize, radius: f64) -> Placement {
        let error = &self.spec.blade_errors[blade];
        let along = self.along(radius);
        let pitch = self.spec.pitch_mm * (1.0 + along(error.pitch_error_pct) / 100.0);
        let angle = (pitch / (TAU * radius)).atan()
            + along(self.spec.twist_deg).to_radians()
            + along(error.twist_deg).to_radians();
        // Stretched along the chord by its scale, the section keeps its thickness and camber in mm: as fractions
        // of the chord they shrink by the same scale.
        let chord_scale = along(error.chord_scale);
        Placement {
            chord: along(self.spec.chord_mm) * chord_scale,
            thickness: self.foil.thickness * along(error.thickness_scale) / chord_scale,
            max_camber: self.foil.max_camber * along(error.camber_scale) / chord_scale,
            angle,
            shift: along(error.shift_mm),
        }
    }

    /// The section at `radius` for nearest-point queries: its airfoil at unit chord with its samples placed
    /// from the stored stations.
    fn scaled_section(&self, blade: usize, radius: f64) -> ScaledSection {
        let placement = self.section_placement(blade, radius);
        let section = BladeSection {
            foil: self.foil_of(&placement, 1.0),
            angle: 0.0,
            shift: 0.0,
        };
        let samples = self
            .stations
            .iter()
            .map(|station| section.placed(section.foil.place(station)))
            .collect();
        ScaledSection {
            unit: SampledCurve::with_samples(section, samples),
            placement,
        }
    }

    /// The plane frame of the blade's section at `radius`, in machine coordinates: origin on the blade
    /// axis at that radius, u tangential, v up the hub axis, w along the blade's radius.
    pub fn section_frame(&self, blade: usize, radius: f64) -> Frame {
        let angle = TAU * blade as f64 / self.spec.blades as f64
            + self.spec.blade_errors[blade].index_deg.to_radians();
        let (sin, cos) = angle.sin_cos();
        let radial = Vector3::new(cos, sin, 0.0);
        let tangential = Vector3::new(-sin, cos, 0.0);
        Frame::placed(
            Point3::from(radial * radius),
            tangential,
            Vector3::z(),
            &self.pose,
        )
    }

    /// Linear interpolation of a [root, tip] pair at `radius`.
    fn along(&self, radius: f64) -> impl Fn([f64; 2]) -> f64 {
        let t = (radius - self.spec.root_radius_mm)
            / (self.spec.tip_radius_mm - self.spec.root_radius_mm);
        move |[root, tip]| root + (tip - root) * t
    }

    /// A blade's solid: its sections stacked along its radius from root to tip.
    fn blade_nearest(&self, blade: usize, p: &Point3<f64>) -> SurfacePoint {
        let axis = self.section_frame(blade, 0.0);
        let range = (self.spec.root_radius_mm, self.spec.tip_radius_mm);
        let radius = axis.local(p).z.clamp(range.0, range.1);
        prism_nearest(&axis, range, &self.scaled_section(blade, radius), p)
    }

    /// A lower bound of the distance from `p` to the blade: the distance to a box about the blade that
    /// holds every section (half the root chord covers any turn of the chord; the thickness and the shifts
    /// are far smaller).
    fn blade_bound(&self, blade: usize, p: &Point3<f64>) -> f64 {
        let local = self.section_frame(blade, 0.0).local(p);
        let half = self.spec.chord_mm[0].max(self.spec.chord_mm[1]) / 2.0 + 10.0;
        let outside = |value: f64, lo: f64, hi: f64| (lo - value).max(value - hi).max(0.0);
        Vector3::new(
            outside(local.x, -half, half),
            outside(local.y, -half, half),
            outside(local.z, self.spec.root_radius_mm, self.spec.tip_radius_mm),
        )
        .norm()
    }

    /// The hub: a cylinder about z, exact distance.
    fn hub_nearest(&self, p: &Point3<f64>) -> SurfacePoint {
        let local = self.pose.inverse() * p;
        let (radius, half) = (self.spec.hub_radius_mm, self.spec.hub_height_mm / 2.0);
        let rho = local.xy().coords.norm();
        let radial = if rho > 1e-12 {
            Vector3::new(local.x / rho, local.y / rho, 0.0)
        } else {
            Vector3::x()
        };
        let side_out = rho - radius;
        let cap_out = local.z.abs() - half;
        let up = Vector3::z() * local.z.signum();
        let (point, normal, distance) = if side_out > 0.0 && cap_out > 0.0 {
            let rim = Point3::from(radial * radius + up * half);
            let distance = (local - rim).norm();
            (rim, (local - rim) / distance, distance)
        } else if side_out > cap_out {
            let on_side = Point3::new(radial.x * radius, radial.y * radius, local.z);
            (on_side, radial, side_out)
        } else {
            (
                Point3::new(local.x, local.y, half * local.z.signum()),
                up,
                cap_out,
            )
        };
        SurfacePoint {
            point: self.pose * point,
            normal: self.pose * normal,
            signed_distance: distance,
        }
    }
}

impl Part for Propeller {
    /// The union of hub and blades: the nearest of them (exact outside the material, which is where the
    /// probe is).
    fn nearest(&self, p: &Point3<f64>) -> SurfacePoint {
        let mut best = self.hub_nearest(p);
        for blade in 0..self.spec.blades {
            if self.blade_bound(blade, p) >= best.signed_distance {
                continue;
            }
            let candidate = self.blade_nearest(blade, p);
            if candidate.signed_distance < best.signed_distance {
                best = candidate;
            }
        }
        best
    }

    fn section(&self, plane: &Plane) -> Option<Section> {
        (0..self.spec.blades).find_map(|blade| {
            let axis = self.section_frame(blade, 0.0);
            let radius = axis.local(&plane.point).z;
            let cuts = parallel(&plane.normal, &axis.w)
                && (self.spec.root_radius_mm..=self.spec.tip_radius_mm).contains(&radius);
            cuts.then(|| Section {
                frame: axis.shifted(radius),
                curve: Arc::new(SampledCurve::new(
                    Box::new(self.section_curve(blade, radius)) as AnyCurve,
                )),
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> PropellerSpec {
        let exact = BladeError {
            shift_mm: [0.0, 0.0],
            twist_deg: [0.0, 0.0],
            thickness_scale: [1.0, 1.0],
            chord_scale: [1.0, 1.0],
            camber_scale: [1.0, 1.0],
            pitch_error_pct: [0.0, 0.0],
            index_deg: 0.0,
        };
        PropellerSpec {
            blades: 3,
            hub_radius_mm: 50.0,
            hub_height_mm: 120.0,
            root_radius_mm: 60.0,
            tip_radius_mm: 560.0,
            naca: "4412".into(),
            sharp_trailing_edge: true,
            chord_mm: [180.0, 90.0],
            pitch_mm: 900.0,
            twist_deg: [0.0, 0.0],
            blade_errors: vec![
                exact,
                BladeError {
                    shift_mm: [-0.4, -1.0],
                    ..exact
                },
                BladeError {
                    shift_mm: [0.4, 1.0],
                    ..exact
                },
            ],
            pose: Pose {
                x_mm: 0.0,
                y_mm: 0.0,
                z_mm: 0.0,
                rot_z_deg: 0.0,
            },
        }
    }

    #[test]
    fn blade_b_lies_below_a_by_its_error_and_c_above() {
        let propeller = Propeller::new(spec()).unwrap();
        for (radius, expected) in [(60.0, 0.4), (310.0, 0.7), (560.0, 1.0)] {
            let a = propeller.section_curve(0, radius);
            let b = propeller.section_curve(1, radius);
            let c = propeller.section_curve(2, radius);
            for s in [0.1, 0.3, 0.5, 0.8] {
                let (pa, pb, pc) = (a.point(s), b.point(s), c.point(s));
                assert!((pa.x - pb.x).abs() < 1e-12 && (pa.x - pc.x).abs() < 1e-12);
                assert!((pa.y - pb.y - expected).abs() < 1e-9, "B at r={radius}");
                assert!((pc.y - pa.y - expected).abs() < 1e-9, "C at r={radius}");
            }
        }
    }

    /// A section's chord, its thickness and camber at station s (chord fraction (1 + cos 2 pi s) / 2, s in
    /// (0, 0.5)) and its chord's angle (rad), read from its points: at one station the upper and lower points lie
    /// on the mean line's normal, the thickness apart, with the mean line's point between them.
    fn measured(section: &BladeSection, s: f64) -> (f64, f64, f64, f64) {
        let (te, le) = (section.point(0.0), section.point(0.5));
        let chord = (te - le).norm();
        let (upper, lower) = (section.point(s), section.point(1.0 - s));
        let along = (te - le) / chord;
        let camber = ((upper + lower.coords) / 2.0 - le).perp(&along).abs();
        let angle = along.y.atan2(along.x);
        (chord, (upper - lower).norm(), camber, angle)
    }

    #[test]
    fn each_blade_error_changes_its_own_parameter_only() {
        let mut errors = spec();
        let exact = errors.blade_errors[0];
        // Halfway from root to tip (r = 310) each takes its mean of root and tip.
        errors.blade_errors[1] = BladeError {
            thickness_scale: [1.01, 1.03],
            chord_scale: [0.99, 0.97],
            ..exact
        };
        errors.blade_errors[2] = BladeError {
            camber_scale: [1.1, 1.3],
            pitch_error_pct: [1.0, 3.0],
            index_deg: 0.25,
            ..exact
        };
        let propeller = Propeller::new(errors).unwrap();
        let r = 310.0;
        let (a, b, c) = (
            measured(&propeller.section_curve(0, r), 0.3),
            measured(&propeller.section_curve(1, r), 0.3),
            measured(&propeller.section_curve(2, r), 0.3),
        );
        let close = |x: f64, y: f64| (x - y).abs() < 1e-9 * (1.0 + y.abs());
        // B: 2 % thicker and 2 % shorter; the same camber in mm (chord positions keep their fraction, so the
        // thickness compares at the same station).
        assert!(close(b.0, a.0 * 0.98), "chord {b:?} {a:?}");
        assert!(close(b.1, a.1 * 1.02), "thickness {b:?} {a:?}");
        assert!(close(b.2, a.2), "camber {b:?} {a:?}");
        assert!(close(b.3, a.3), "angle {b:?} {a:?}");
        // C: 20 % more camber, the blade angle of a pitch 2 % coarse, the chord and thickness kept.
        assert!(close(c.0, a.0) && close(c.1, a.1), "{c:?} {a:?}");
        assert!(close(c.2, a.2 * 1.2), "camber {c:?} {a:?}");
        assert!(close(c.3, (900.0 * 1.02 / (TAU * r)).atan()), "angle {c:?}");
        // C turned 0.25 deg more about the hub axis than its place (240 deg).
        let frame = propeller.section_frame(2, r);
        let expected = (240.25f64).to_radians();
        assert!(
            (frame.origin - Point3::new(r * expected.cos(), r * expected.sin(), 0.0)).norm() < 1e-9
        );
        let mut bad = spec();
        bad.blade_errors[2].chord_scale = [1.0, 0.0];
        assert_eq!(
            Propeller::new(bad).err(),
            Some(PropellerError::BadScale { blade: 2 })
        );
    }

    #[test]
    fn sections_of_blade_a_lie_in_planes_of_constant_x() {
        let propeller = Propeller::new(spec()).unwrap();
        let frame = propeller.section_frame(0, 200.0);
        let curve = propeller.section_curve(0, 200.0);
        let p = curve.point(0.25);
        let world = frame.world(p.x, p.y, 0.0);
        assert!((world.x - 200.0).abs() < 1e-12);
        assert!((world.y - p.x).abs() < 1e-12 && (world.z - p.y).abs() < 1e-12);
        // Blade B is blade A turned 120 degrees about z.
        let b = propeller.section_frame(1, 200.0);
        assert!((b.origin - Point3::new(-100.0, 200.0 * 0.75f64.sqrt(), 0.0)).norm() < 1e-9);
    }

    #[test]
    fn surface_points_and_normals_are_consistent() {
        let propeller = Propeller::new(spec()).unwrap();
        let frame = propeller.section_frame(0, 300.0);
        let curve = SampledCurve::new(propeller.section_curve(0, 300.0));
        for s in [0.05, 0.2, 0.45, 0.6, 0.9] {
            let on = curve.at(s);
            let surface = frame.world(on.point.x, on.point.y, 0.0);
            let outward = frame.world_dir(on.normal.x, on.normal.y, 0.0);
            let probe = surface + outward * 3.0;
            let nearest = propeller.nearest(&probe);
            assert!(
                (nearest.signed_distance - 3.0).abs() < 1e-6,
                "s={s}: {}",
                nearest.signed_distance
            );
            assert!((nearest.point - surface).norm() < 1e-5);
            let inside = propeller.nearest(&(surface - outward * 0.5));
            assert!(inside.signed_distance < 0.0);
        }
    }

    #[test]
    fn the_scaled_unit_section_is_the_sampled_section() {
        // Blade B's shape is off too: its samples are placed from the stations of the nominal airfoil.
        let mut errors = spec();
        errors.blade_errors[1].thickness_scale = [1.05, 0.9];
        errors.blade_errors[1].chord_scale = [1.1, 0.95];
        errors.blade_errors[1].camber_scale = [0.8, 1.2];
        let propeller = Propeller::new(errors).unwrap();
        for (blade, radius) in [(0, 100.0), (1, 333.3), (2, 560.0)] {
            let sampled = SampledCurve::new(propeller.section_curve(blade, radius));
            let scaled = propeller.scaled_section(blade, radius);
            for query in [[3.0, 40.0], [-70.0, -5.0], [0.5, 0.2], [55.0, -60.0]] {
                let query = Point2::from(query);
                let a = SampledCurve::nearest(&sampled, &query);
                let b = PlaneNearest::nearest(&scaled, &query);
                assert!(
                    (a.signed_distance - b.signed_distance).abs() < 1e-9,
                    "{a:?} {b:?}"
                );
                // The parameter search ends where the distance is flat to rounding, which moves the foot by
                // about 1e-7 of the distance either way (a nanometre at 10 mm).
                let flat = 1e-7 * (1.0 + a.signed_distance.abs());
                assert!(
                    (a.on_curve.point - b.on_curve.point).norm() < flat,
                    "{query}: {a:?} {b:?}"
                );
                assert!((a.on_curve.normal - b.on_curve.normal).norm() < 1e-6);
            }
        }
    }

    #[test]
    fn the_hub_is_material_and_far_points_are_outside() {
        let propeller = Propeller::new(spec()).unwrap();
        let hub = propeller.nearest(&Point3::new(0.0, 0.0, 70.0));
        assert!((hub.signed_distance - 10.0).abs() < 1e-9);
        assert_eq!(hub.normal, Vector3::z());
        assert!(
            propeller
                .nearest(&Point3::new(0.0, 0.0, 0.0))
                .signed_distance
                < 0.0
        );
        assert!(
            propeller
                .nearest(&Point3::new(0.0, 0.0, 400.0))
                .signed_distance
                > 300.0
        );
    }

    #[test]
    fn only_planes_across_a_blade_have_sections() {
        let propeller = Propeller::new(spec()).unwrap();
        let across_a = Plane {
            point: Point3::new(200.0, 5.0, 3.0),
            normal: -Vector3::x(),
        };
        let section = propeller
            .section(&across_a)
            .expect("plane x = 200 cuts blade A");
        assert!((section.frame.origin - Point3::new(200.0, 0.0, 0.0)).norm() < 1e-9);
        let beyond_tip = Plane {
            point: Point3::new(600.0, 0.0, 0.0),
            normal: Vector3::x(),
        };
        assert!(propeller.section(&beyond_tip).is_none());
        let slanted = Plane {
            point: Point3::new(200.0, 0.0, 0.0),
            normal: Vector3::new(1.0, 1.0, 0.0),
        };
        assert!(propeller.section(&slanted).is_none());
    }

    #[test]
    fn bad_configurations_are_refused() {
        let mut two_errors = spec();
        two_errors.blade_errors.pop();
        assert_eq!(
            Propeller::new(two_errors).err(),
            Some(PropellerError::ErrorsPerBlade {
                found: 2,
                blades: 3
            })
        );
        let mut bad_naca = spec();
        bad_naca.naca = "44123".into();
        assert!(matches!(
            Propeller::new(bad_naca),
            Err(PropellerError::BadNaca(_))
        ));
    }
}
