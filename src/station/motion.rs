//! The one motion plan of a job: each scan's moves (approach, descent, scan, lift-off, way out) built once as
//! data. The clearance check sweeps these values and the worker sends these values, so the path proven safe and
//! the path driven cannot drift apart.
//!
//! Positions are ball centres planned for the largest ball the station accepts (`[safety] max_ball_radius_mm`),
//! the ball the clearance check sweeps: a smaller real ball at the same centres lies inside the swept one, only
//! further off the surface.

use nalgebra::{Point3, Vector3};

use super::escape::{way_out, KnownPath};
use crate::analysis::Reference;
use crate::api::JobKind;
use crate::config::{MachineEntry, Safety};
use crate::plan::{EdgeFan, Plan, ProfileKey};
use zeroset_drivers::machine::{CurveScan, InPlaneScan};

/// Teaching starts from a point of the drawing, not of the part: the probe enters this far above it, mm.
const TEACH_MARGIN_MM: f64 = 5.0;
/// Inspecting follows the taught curve; the real surface lies within the expected deviation of it, so the probe
/// keeps this much more off it when entering and leaving, mm.
const INSPECT_EXTRA_MARGIN_MM: f64 = 2.0;
/// How far beyond the margin the ball may end a scan from its planned end and still take the planned lift-off:
/// the machine's own retract after the scan and the real ball being smaller than the planned one, mm.
const END_TOLERANCE_MM: f64 = 3.0;

/// The scan command itself.
#[derive(Debug, Clone, PartialEq)]
pub enum Scan {
    /// The master's profile, shape unknown.
    InPlane(InPlaneScan),
    /// A profile along its taught nominal curve.
    Curve(CurveScan),
}

/// Every move of one profile's scan, machine coordinates, ball centres, mm.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanMotion {
    pub key: ProfileKey,
    /// The part, instance and profile, as the operator reads them.
    pub name: String,
    /// Above the entry at the clearance height, then straight down to the entry.
    pub approach: [Point3<f64>; 2],
    pub scan: Scan,
    /// The surface known before the scan, and its entry: what a way out after a stop follows.
    pub path: KnownPath,
    /// How far off the known surface the ball travels when entering and leaving, mm.
    pub margin_mm: f64,
    /// Where the ball is planned to stop when the scan ends, and how far from it a real end may lie for the
    /// lift-off to be the planned one (beyond it the worker refuses and waits for `zeroset clear`).
    pub end: Point3<f64>,
    pub end_tolerance_mm: f64,
    /// From the end: the lift-off off the surface, along the path back to the entry, and up.
    pub retract: Vec<Point3<f64>>,
    /// The ball radius these positions are planned for, mm.
    pub ball_radius_mm: f64,
    /// A curve scan's sharp edges, whose probing lines fan out from a pivot inside them: what a stop there is
    /// explained by. Empty for other scans.
    pub edges: Vec<EdgeFan>,
}

/// Why a scan's motion cannot be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{scan}: {problem}")]
pub struct PlanError {
    pub scan: String,
    pub problem: String,
}

/// How far the probe keeps off the known surface when entering and leaving a scan of a job of `kind`, mm.
pub(super) fn scan_margin_mm(plan: &Plan, kind: JobKind) -> f64 {
    match kind {
        JobKind::Teach => TEACH_MARGIN_MM,
        JobKind::Inspect => plan.scan_settings().max_deviation_mm + INSPECT_EXTRA_MARGIN_MM,
    }
}

/// The motion of one scan: a curve scan along the reference's nominals when there is one, else the teach's
/// in-plane scan from the part file's start point.
pub fn scan_motion(
    plan: &Plan,
    reference: Option<&Reference>,
    key: ProfileKey,
    safety: &Safety,
) -> Result<ScanMotion, PlanError> {
    let name = format!("part {}, {}", plan.part(), plan.describe(key));
    let (scan, path, kind, edges) = match reference {
        Some(reference) => {
            let profile = &reference.profiles[key.profile];
            let scan = plan.curve_scan(
                key,
                &profile.nominals,
                &profile.edges,
                safety.max_ball_radius_mm,
            );
            let path = KnownPath::of_curve_scan(&scan);
            let edges = plan.edge_fans(key, &profile.edges, safety.max_ball_radius_mm);
            (Scan::Curve(scan), path, JobKind::Inspect, edges)
        }
        None => {
            let scan = plan.in_plane_scan(key);
            let start = Point3::new(scan.start.x, scan.start.y, scan.start.z);
            let normal = Vector3::new(
                scan.start_normal.x,
                scan.start_normal.y,
                scan.start_normal.z,
            );
            let path = KnownPath {
                surface: vec![start],
                normals: vec![normal.try_normalize(1e-12).unwrap_or_default()],
                closed: false,
                entry: 0,
            };
            (Scan::InPlane(scan), path, JobKind::Teach, Vec::new())
        }
    };
    let motion = ScanMotion::plan(key, name, scan, path, scan_margin_mm(plan, kind), safety)?;
    Ok(ScanMotion { edges, ..motion })
}

impl ScanMotion {
    /// The moves of a scan over `path`, entered from above its entry: down from the clearance height to `margin`
    /// off the surface beyond the planned ball, and after the scan off the surface and back up the same way.
    pub fn plan(
        key: ProfileKey,
        name: String,
        scan: Scan,
        path: KnownPath,
        margin: f64,
        safety: &Safety,
    ) -> Result<ScanMotion, PlanError> {
        let fail = |problem: String| PlanError {
            scan: name.clone(),
            problem,
        };
        path.validate().map_err(fail)?;
        let radius = safety.max_ball_radius_mm;
        let entry = path.entry_offset(radius, margin);
        if entry.z >= safety.clearance_z_mm {
            return Err(fail(format!(
                "its entry ({:.3}, {:.3}, {:.3}) mm is not below the clearance height z = {} mm ([safety] \
                 clearance_z_mm): the clearance height must lie above the part",
                entry.x, entry.y, entry.z, safety.clearance_z_mm
            )));
        }
        let above = Point3::new(entry.x, entry.y, safety.clearance_z_mm);
        // A closed profile ends where it began; the teach's in-plane scan closes at its start point too.
        let end = path.surface[path.entry] + path.normals[path.entry] * radius;
        let retract = way_out(end, Some(&path), radius, margin, safety.clearance_z_mm)
            .map_err(|e| fail(e.to_string()))?;
        Ok(ScanMotion {
            key,
            name,
            approach: [above, entry],
            scan,
            path,
            margin_mm: margin,
            end,
            end_tolerance_mm: margin + END_TOLERANCE_MM,
            retract,
            ball_radius_mm: radius,
            edges: Vec::new(),
        })
    }
}

impl ScanMotion {
    /// Every ball centre the motion goes to: the approach, the scan along its known surface, its end, the way out.
    pub fn positions(&self) -> impl Iterator<Item = Point3<f64>> + '_ {
        let scanned = self
            .path
            .surface
            .iter()
            .zip(&self.path.normals)
            .map(|(p, n)| p + n * self.ball_radius_mm);
        self.approach
            .iter()
            .copied()
            .chain(scanned)
            .chain(std::iter::once(self.end))
            .chain(self.retract.iter().copied())
    }
}

/// Refuses motions that would take a machine's ball centre out of its volume (`[[machines]] volume_mm`): any
/// machine of the station may be given any scan.
pub fn check_volumes(motions: &[ScanMotion], machines: &[MachineEntry]) -> Result<(), PlanError> {
    for machine in machines {
        let Some(volume) = &machine.volume_mm else {
            continue;
        };
        for motion in motions {
            if let Some(p) = motion
                .positions()
                .find(|p| !volume.contains(&[p.x, p.y, p.z]))
            {
                return Err(PlanError {
                    scan: motion.name.clone(),
                    problem: format!(
                        "it would take the ball centre to ({:.3}, {:.3}, {:.3}) mm, outside machine {}'s volume \
                         (volume_mm, min {:?}, max {:?} mm); check part_to_machine and the part's placement",
                        p.x, p.y, p.z, machine.name, volume.min, volume.max
                    ),
                });
            }
        }
    }
    Ok(())
}

/// The motion of every scan in `keys`, in their order.
pub fn job_motions(
    plan: &Plan,
    reference: Option<&Reference>,
    keys: &[ProfileKey],
    safety: &Safety,
) -> Result<Vec<ScanMotion>, PlanError> {
    keys.iter()
        .map(|&key| scan_motion(plan, reference, key, safety))
        .collect()
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use nalgebra::Isometry3;

    use super::*;
    use crate::config::PartConfig;

    fn propeller() -> Plan {
        let file = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("config/parts/propeller.toml");
        Plan::new(&PartConfig::load(&file).unwrap(), Isometry3::identity())
    }

    fn safety(clearance_z_mm: f64) -> Safety {
        Safety {
            clearance_z_mm,
            max_ball_radius_mm: 1.5,
            move_margin_mm: 0.5,
        }
    }

    #[test]
    fn a_teach_scan_is_entered_straight_down_over_its_start_and_left_straight_up() {
        let plan = propeller();
        let keys = plan.teach_scans();
        let motions = job_motions(&plan, None, &keys, &safety(150.0)).unwrap();
        assert_eq!(motions.len(), 5);
        let r100 = &motions[0];
        // The part file's start point of r100, (100, 0, 23.98) with its normal up, entered 1.5 + 5 mm above it.
        assert_eq!(r100.approach[0], Point3::new(100.0, 0.0, 150.0));
        assert!((r100.approach[1] - Point3::new(100.0, 0.0, 30.48)).norm() < 1e-9);
        assert!((r100.end - Point3::new(100.0, 0.0, 25.48)).norm() < 1e-9);
        assert_eq!(r100.retract, vec![r100.approach[1], r100.approach[0]]);
        assert!(matches!(r100.scan, Scan::InPlane(_)));
        assert!(r100.name.contains("r100"), "{}", r100.name);
    }

    fn machine(min: [f64; 3], max: [f64; 3]) -> MachineEntry {
        MachineEntry {
            name: "cmm1".into(),
            port: "/dev/null".into(),
            baud: None,
            ack_timeout_s: 10.0,
            reply_timeout_s: 180.0,
            volume_mm: Some(crate::config::Volume { min, max }),
        }
    }

    #[test]
    fn a_scan_out_of_a_machines_volume_is_refused_naming_the_scan_and_the_machine() {
        let plan = propeller();
        let motions = job_motions(&plan, None, &plan.teach_scans(), &safety(150.0)).unwrap();
        // The simulator's travel holds every move.
        check_volumes(
            &motions,
            &[machine([-700.0, -700.0, -300.0], [700.0, 700.0, 500.0])],
        )
        .unwrap();
        // A machine that reaches x = 450 mm at most cannot scan the r500 profile.
        let error = check_volumes(
            &motions,
            &[machine([-700.0, -700.0, -300.0], [450.0, 700.0, 500.0])],
        )
        .unwrap_err();
        let message = error.to_string();
        assert!(
            message.contains("r500")
                && message.contains("machine cmm1")
                && message.contains("volume_mm"),
            "{message}"
        );
        // Every position counts, the approach at the clearance height included.
        let low_ceiling = machine([-700.0, -700.0, -300.0], [700.0, 700.0, 149.0]);
        assert!(check_volumes(&motions, &[low_ceiling]).is_err());
    }

    #[test]
    fn a_clearance_height_below_the_part_is_refused_before_anything_moves() {
        let plan = propeller();
        let error = job_motions(&plan, None, &plan.teach_scans(), &safety(10.0)).unwrap_err();
        let message = error.to_string();
        assert!(
            message.contains("clearance_z_mm") && message.contains("r100"),
            "{message}"
        );
    }

    #[test]
    fn a_path_with_a_zero_normal_is_refused_instead_of_sending_nan() {
        let path = KnownPath {
            surface: vec![Point3::new(100.0, 0.0, 20.0), Point3::new(100.0, 1.0, 20.0)],
            normals: vec![Vector3::new(0.0, 0.0, 1.0), Vector3::zeros()],
            closed: false,
            entry: 0,
        };
        let plan = propeller();
        let scan = Scan::InPlane(plan.in_plane_scan(plan.teach_scans()[0]));
        let key = plan.teach_scans()[0];
        let error =
            ScanMotion::plan(key, "r100".into(), scan, path, 5.0, &safety(150.0)).unwrap_err();
        assert!(error.to_string().contains("point 1"), "{error}");
    }
}
