//! The station's analysis layer: teaching a reference from the master's profiles, the live signed deviation of
//! each arriving point against it, and the running statistics and tolerance verdicts of those deviations.
//!
//! Frames: the CMM reports machine coordinates; the daemon moves compensated points into the part frame of the
//! master (hub axis z, master blade along +x, profiles in the planes x = const) before they reach a gauge here.

pub mod deviation;
pub mod edges;
pub(crate) mod fit_sanity;
mod nominals;
pub mod part_mesh;
pub mod reference;
pub(crate) mod rolls;
pub mod section;
pub mod stats;
#[cfg(test)]
pub(crate) mod test_profiles;
pub mod tolerances;

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

use crate::geometry::sweep::compensation::{compensate_path, Compensated, CompensationSettings};

pub use deviation::{PointDeviation, ProfileGauge, ScanGauge};
pub use reference::{
    teach, MasterProfile, NominalPoint, Reference, ReferenceFileError, ReferenceProfile,
    ReferenceSettings, TeachError,
};
pub use stats::{DeviationStats, RunningStats, Tolerance, Verdict};

/// A point as the machine reported it: ball centre and outward unit normal (mm, machine frame), I++ quality.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RawPoint {
    pub centre: [f64; 3],
    pub normal: [f64; 3],
    pub quality: f64,
}

/// A scan's points compensated for the probe ball exactly as the pipeline compensates them live (so that a report
/// and a taught reference agree with the events): from the ball-centre path, in planes of normal `plane_normal`,
/// the reported normal only at the scan's first and last points and where the path cannot be fitted; points whose
/// contact is flagged (a cusp) are kept and marked. See `geometry::sweep::compensation`.
pub fn compensate_scan(
    points: &[RawPoint],
    ball_radius_mm: f64,
    plane_normal: Vector3<f64>,
) -> Vec<Compensated> {
    let path: Vec<(Point3<f64>, Vector3<f64>)> = points
        .iter()
        .map(|raw| (Point3::from(raw.centre), Vector3::from(raw.normal)))
        .collect();
    // A scan file is treated as an open path even when it goes round the section: the live pipeline cannot wrap
    // round before the scan ends, and the report must hold the deviations that were published.
    compensate_path(
        CompensationSettings::new(ball_radius_mm),
        plane_normal,
        &path,
        false,
    )
}

/// The surface point a CMM's ball touched: the centre moved back one ball radius along the reported normal. What
/// the station uses where it has a single point and no path: the way out of a cut scan
/// (`station::job::cut_scan_path`); scans are compensated by [`compensate_scan`].
///
/// The normal is normalised first: controllers report it to a few digits only, and a normal 0.1 % long would
/// misplace the point by 0.1 % of the ball radius. A zero normal gives non-finite coordinates, which a gauge
/// refuses to measure.
pub fn surface_point(raw: &RawPoint, ball_radius_mm: f64) -> Point3<f64> {
    let normal = Vector3::from(raw.normal);
    Point3::from(raw.centre) - normal / normal.norm() * ball_radius_mm
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_surface_point_is_one_radius_inside_the_centre_along_the_normal() {
        let raw = RawPoint {
            centre: [10.0, 20.0, 30.0],
            // Not quite unit, as a controller rounds it: 3-4-0 scaled by 1.0002.
            normal: [0.6 * 1.0002, 0.8 * 1.0002, 0.0],
            quality: 1.0,
        };
        let p = surface_point(&raw, 2.5);
        assert!((p - Point3::new(8.5, 18.0, 30.0)).norm() < 1e-12, "{p}");
        let zero = RawPoint {
            normal: [0.0; 3],
            ..raw
        };
        assert!(surface_point(&zero, 2.5).iter().any(|c| !c.is_finite()));
    }
}
