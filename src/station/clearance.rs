//! The clearance of an inspection's moves, checked before the job starts (issue 6, seed 002): for every scan,
//! the vertical descent from the clearance height to the scan's entry and the way out along the nominal curve
//! and up (`escape`), each swept by the stylus (ball and shank) and measured against the taught part model (a
//! mesh of every instance, machine coordinates) by conservative advancement, which cannot step over a thin edge.
//! A move that comes closer than the configured margin refuses the job, naming the instance, profile and move,
//! where and by how much.
//!
//! The contact scan itself is measured too (the ball touches by design, so only the shank counts) and shown by
//! `zeroset sweep`, but it does not refuse the job: a vertical stylus scanning a closed blade section passes its
//! shank through the blade wherever the ball runs under it, which a real station avoids with a probe head that
//! turns the stylus. The simulator's probe is a ball alone.

use nalgebra::Point3;

use super::job::{job_scans, load_plan, reference_path};
use super::motion::{job_motions, Scan, ScanMotion};
use crate::analysis::part_mesh::part_mesh;
use crate::analysis::Reference;
use crate::api::JobKind;
use crate::config::StationConfig;
use crate::geometry::sweep::clearance::{check_move, Clearance};
use crate::geometry::sweep::mesh::MeshPart;
use crate::geometry::sweep::motion::{Motion, ScanPath};
use crate::geometry::sweep::stylus::Stylus;
use crate::plan::{Plan, ProfileKey};

/// What a planned move does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MoveKind {
    /// Straight down from the clearance height to the scan's entry, off the surface by the scan margin.
    Descent,
    /// Along the nominal curve with the ball in contact.
    Scan,
    /// The first leg of the way out: from the ball in contact along the normal to the margin off the surface.
    LiftOff,
    /// From the end of the scan back along its path, off the surface, and up to the clearance height.
    WayOut,
}

impl MoveKind {
    pub fn describe(self) -> &'static str {
        match self {
            Self::Descent => "descent to the entry",
            Self::Scan => "contact scan",
            Self::LiftOff => "lift-off after the scan",
            Self::WayOut => "way out",
        }
    }
}

/// One move of an inspection, machine coordinates.
#[derive(Debug, Clone)]
pub struct PlannedMove {
    pub key: ProfileKey,
    pub kind: MoveKind,
    pub motion: Motion,
}

/// A move with its clearance.
#[derive(Debug, Clone)]
pub struct CheckedMove {
    pub planned: PlannedMove,
    pub clearance: Clearance,
}

/// The stylus of the station's probe, with the largest ball the station accepts: the ball's surface stays where
/// the plan puts it whatever the radius (entries are offset by radius plus margin), and the shank's position
/// changes by less than the difference in radii.
pub fn station_stylus(config: &StationConfig) -> Result<Stylus, String> {
    Stylus::new(
        config.safety.max_ball_radius_mm,
        config.probe.shank_radius_mm,
        config.probe.shank_length_mm,
    )
    .map_err(|e| format!("[probe] of the station file: {e}"))
}

/// The taught part, every instance placed on the machine, as one mesh to measure moves against.
pub fn machine_part(plan: &Plan, reference: &Reference) -> Result<MeshPart, String> {
    let mesh = part_mesh(reference)?;
    let mut vertices = Vec::with_capacity(mesh.vertices.len() * plan.instance_names().len());
    let mut triangles = Vec::with_capacity(mesh.triangles.len() * plan.instance_names().len());
    for instance in 0..plan.instance_names().len() {
        let placement = plan.instance_to_machine(instance);
        let base = vertices.len();
        vertices.extend(mesh.vertices.iter().map(|v| placement * v));
        triangles.extend(mesh.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    MeshPart::new(vertices, triangles, mesh.chord_tolerance_mm)
        .map_err(|e| format!("the model of part '{}': {e}", plan.part()))
}

/// Every planned move near the part, in scan order: descent, contact scan (a curve scan's), lift-off and way out,
/// per profile: the very positions the worker sends.
pub fn swept_moves(motions: &[ScanMotion]) -> Result<Vec<PlannedMove>, String> {
    let mut moves = Vec::new();
    for motion in motions {
        let key = motion.key;
        let [above, entry] = motion.approach;
        moves.push(PlannedMove {
            key,
            kind: MoveKind::Descent,
            motion: Motion::line(above, entry),
        });
        if let Scan::Curve(_) = motion.scan {
            let path = &motion.path;
            let radius = motion.ball_radius_mm;
            let centres: Vec<Point3<f64>> = path
                .surface
                .iter()
                .zip(&path.normals)
                .map(|(p, n)| p + n * radius)
                .chain(
                    path.closed
                        .then(|| path.surface[0] + path.normals[0] * radius),
                )
                .collect();
            let scan_path = ScanPath::new(centres, true)
                .map_err(|e| format!("the scan path of {}: {e}", motion.name))?;
            moves.push(PlannedMove {
                key,
                kind: MoveKind::Scan,
                motion: Motion::Scan(scan_path),
            });
        }
        let mut from = motion.end;
        for (leg, &to) in motion.retract.iter().enumerate() {
            if (to - from).norm() > 0.0 {
                // The first leg starts with the ball on the surface: like the scan, only the shank is judged.
                let (kind, swept) = if leg == 0 {
                    let lift = ScanPath::new(vec![from, to], true)
                        .map_err(|e| format!("the lift-off of {}: {e}", motion.name))?;
                    (MoveKind::LiftOff, Motion::Scan(lift))
                } else {
                    (MoveKind::WayOut, Motion::line(from, to))
                };
                moves.push(PlannedMove {
                    key,
                    kind,
                    motion: swept,
                });
            }
            from = to;
        }
    }
    Ok(moves)
}

/// Every move with its clearance against `part`; contact scans are measured for the shank only.
pub fn check_moves(
    stylus: &Stylus,
    moves: Vec<PlannedMove>,
    part: &MeshPart,
    margin_mm: f64,
) -> Vec<CheckedMove> {
    moves
        .into_iter()
        .map(|planned| {
            let clearance = check_move(stylus, &planned.motion, part, margin_mm);
            CheckedMove { planned, clearance }
        })
        .collect()
}

/// The part's taught model on the machine and every move of its inspection with its clearance, contact scans
/// included, for `zeroset sweep`.
pub struct PlanSweep {
    pub plan: Plan,
    pub stylus: Stylus,
    pub part: MeshPart,
    pub moves: Vec<CheckedMove>,
}

/// Loads the part and its reference as the daemon would for an inspection, and checks every move.
pub fn sweep_plan(config: &StationConfig, part: &str) -> Result<PlanSweep, String> {
    let plan = load_plan(config, part).map_err(|e| e.to_string())?;
    let path = reference_path(config, part);
    let reference = Reference::load(&path).map_err(|e| {
        format!("{e}; teach the part first (`zeroset teach {part}`): the moves are checked against its reference")
    })?;
    let stylus = station_stylus(config)?;
    let mesh = machine_part(&plan, &reference)?;
    let motions = job_motions(
        &plan,
        Some(&reference),
        &job_scans(&plan, JobKind::Inspect),
        &config.safety,
    )
    .map_err(|e| e.to_string())?;
    let moves = swept_moves(&motions)?;
    let moves = check_moves(&stylus, moves, &mesh, config.safety.move_margin_mm);
    Ok(PlanSweep {
        plan,
        stylus,
        part: mesh,
        moves,
    })
}

/// The first free move (descent, lift-off or way out) closer than `margin_mm`, as the operator's message.
pub fn refusal(plan: &Plan, checked: &[CheckedMove], margin_mm: f64) -> Option<String> {
    let (index, bad) = checked.iter().enumerate().find(|(_, c)| {
        c.planned.kind != MoveKind::Scan && c.clearance.min_distance_mm < margin_mm
    })?;
    let at = bad.clearance.at_point;
    Some(format!(
        "the plan of part '{}' is refused: move {index} ({} of instance {}, profile {}) brings the {} to {:.3} mm of \
         the part at ({:.3}, {:.3}, {:.3}) mm, {:.3} mm inside the {margin_mm} mm margin{}; check the part's placement \
         (part_to_machine) and its profiles' start points, or teach the part again",
        plan.part(),
        bad.planned.kind.describe(),
        plan.instance_names()[bad.planned.key.instance],
        plan.profile_names()[bad.planned.key.profile],
        bad.clearance.stylus_part,
        bad.clearance.min_distance_mm,
        at.x,
        at.y,
        at.z,
        margin_mm - bad.clearance.min_distance_mm,
        bad.clearance
            .first_contact_t
            .map_or(String::new(), |t| format!(" (it touches the part at {:.0}% of the move)", 100.0 * t))
    ))
}
