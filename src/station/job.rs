//! A job in the daemon: its plan, what is left to scan, what is done, and how its scans are set up. Built either
//! fresh from an operator's request or from a job folder left open by a fault or a killed daemon.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use super::clearance;
use super::escape::KnownPath;
use super::journal::{file_stem, JobDir, JobRecord, JobState};
use super::pipeline::{scan_ref, PipelineMsg};
use super::worker::{Scan, ScanOrder};
use crate::analysis::deviation::ProfileGauge;
use crate::analysis::reference::Reference;
use crate::analysis::stats::Tolerance;
use crate::analysis::surface_point;
use crate::api::{JobInfo, JobKind, ScanRef};
use crate::config::{PartConfig, StationConfig};
use crate::plan::{Plan, ProfileKey};

/// Teaching starts from a point of the drawing, not of the part: the probe enters this far above it, mm.
const TEACH_MARGIN_MM: f64 = 5.0;
/// Inspecting follows the taught curve; the real surface lies within the expected deviation of it, so the probe
/// keeps this much more off it when entering and leaving, mm.
const INSPECT_EXTRA_MARGIN_MM: f64 = 2.0;

/// Where a job is.
#[derive(Debug, Clone, PartialEq)]
pub enum Phase {
    Scanning,
    /// Stopped by a fault; waits for `zeroset clear`.
    Stopped {
        machine: Option<String>,
        scan: Option<ScanRef>,
        reason: String,
        next_step: String,
    },
    /// The operator aborted: waiting for the machines to stop and clear.
    Aborting,
    /// Every profile is on disk: fitting the reference or writing the report.
    Finishing,
    /// Finished, aborted or failed: kept for `zeroset status`.
    Over(String),
}

pub struct Job {
    pub info: JobInfo,
    pub record: JobRecord,
    pub dir: JobDir,
    pub plan: Arc<Plan>,
    pub reference: Option<Arc<Reference>>,
    pub gauges: Option<Arc<Vec<ProfileGauge>>>,
    pub remaining: Vec<ProfileKey>,
    pub stored: BTreeSet<ProfileKey>,
    pub total: usize,
    pub phase: Phase,
    pub pipeline: Option<tokio::sync::mpsc::Sender<PipelineMsg>>,
}

/// Why a job cannot start: said so that the operator knows what to do.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct JobError(pub String);

/// The part's plan, from its file in the station's parts folder.
pub fn load_plan(config: &StationConfig, part: &str) -> Result<Plan, JobError> {
    if part.is_empty()
        || !part
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_".contains(c))
    {
        return Err(JobError(format!(
            "part name {part:?}: use letters, digits, '-' and '_' (it names a file in {})",
            config.parts.display()
        )));
    }
    let path = config.part_path(part);
    let part_config = PartConfig::load(&path).map_err(|e| JobError(e.to_string()))?;
    Ok(Plan::new(&part_config, config.part_to_machine.isometry()))
}

/// Where a part's taught reference is kept.
pub fn reference_path(config: &StationConfig, part: &str) -> PathBuf {
    config
        .folders
        .data
        .join("references")
        .join(format!("{part}.json"))
}

/// The reference of a part, and a gauge per profile (sampling each profile's zero set: done once per job).
pub fn load_reference(
    config: &StationConfig,
    plan: &Plan,
) -> Result<(Arc<Reference>, Arc<Vec<ProfileGauge>>), JobError> {
    let path = reference_path(config, plan.part());
    if !path.exists() {
        return Err(JobError(format!(
            "part {} has no reference yet ({} is missing): teach it first with `zeroset teach {}`",
            plan.part(),
            path.display(),
            plan.part()
        )));
    }
    let reference = Reference::load(&path).map_err(|e| JobError(e.to_string()))?;
    if reference.profiles.len() != plan.profile_names().len() {
        return Err(JobError(format!(
            "{}: the reference has {} profiles but the part file has {}; teach the part again",
            path.display(),
            reference.profiles.len(),
            plan.profile_names().len()
        )));
    }
    let gauges = ProfileGauge::all(&reference);
    Ok((Arc::new(reference), Arc::new(gauges)))
}

impl Job {
    /// A new job, its folder created.
    pub fn create(
        config: &StationConfig,
        kind: JobKind,
        plan: Plan,
        serial: Option<String>,
        reference: Option<(Arc<Reference>, Arc<Vec<ProfileGauge>>)>,
    ) -> Result<Job, JobError> {
        let started = super::clock::now_rfc3339();
        let id = format!(
            "{}-{}-{}",
            plan.part(),
            serial.as_deref().unwrap_or("teach"),
            super::clock::unix_ms()
        );
        let record = JobRecord {
            id,
            kind,
            part: plan.part().to_string(),
            serial,
            started,
            state: JobState::Open,
            report: None,
        };
        let dir = JobDir::create(&config.folders.data, &record)
            .map_err(|e| JobError(format!("cannot start the job: {e}")))?;
        Ok(Job::from_parts(
            config,
            record,
            dir,
            plan,
            reference,
            BTreeSet::new(),
        ))
    }

    /// A job left open on disk: its complete profiles stay done, the rest is scanned after `zeroset clear`.
    pub fn reopen(config: &StationConfig, dir: JobDir, record: JobRecord) -> Result<Job, JobError> {
        let plan = load_plan(config, &record.part)?;
        let reference = match record.kind {
            JobKind::Teach => None,
            JobKind::Inspect => Some(load_reference(config, &plan)?),
        };
        let completed = dir
            .completed()
            .map_err(|e| JobError(format!("cannot read {}: {e}", dir.path().display())))?;
        let keys = job_scans(&plan, record.kind);
        let stored = keys
            .iter()
            .copied()
            .filter(|key| completed.contains(&file_stem(&scan_ref(&plan, *key))))
            .collect();
        let mut job = Job::from_parts(config, record, dir, plan, reference, stored);
        job.phase = Phase::Stopped {
            machine: None,
            scan: None,
            reason: "the daemon stopped while this job was running".into(),
            next_step: "run `zeroset clear` to continue from its last complete profile".into(),
        };
        Ok(job)
    }

    fn from_parts(
        config: &StationConfig,
        record: JobRecord,
        dir: JobDir,
        plan: Plan,
        reference: Option<(Arc<Reference>, Arc<Vec<ProfileGauge>>)>,
        stored: BTreeSet<ProfileKey>,
    ) -> Job {
        let keys = job_scans(&plan, record.kind);
        let remaining = keys
            .iter()
            .copied()
            .filter(|k| !stored.contains(k))
            .collect();
        let instances = match record.kind {
            JobKind::Teach => vec![plan.instance_names()[plan.master()].clone()],
            JobKind::Inspect => plan.instance_names().to_vec(),
        };
        let tolerance = plan.tolerance();
        let info = JobInfo {
            id: record.id.clone(),
            kind: record.kind,
            part: record.part.clone(),
            serial: record.serial.clone(),
            instances,
            profiles: plan.profile_names().iter().map(|p| p.to_string()).collect(),
            machines: config.machines.iter().map(|m| m.name.clone()).collect(),
            tolerance_mm: [tolerance.lower_mm, tolerance.upper_mm],
        };
        let (reference, gauges) = reference.unzip();
        Job {
            info,
            record,
            dir,
            plan: Arc::new(plan),
            reference,
            gauges,
            remaining,
            stored,
            total: keys.len(),
            phase: Phase::Scanning,
            pipeline: None,
        }
    }

    pub fn tolerance(&self) -> Tolerance {
        let t = self.plan.tolerance();
        Tolerance {
            lower_mm: t.lower_mm,
            upper_mm: t.upper_mm,
        }
    }

    pub fn is_over(&self) -> bool {
        matches!(self.phase, Phase::Over(_))
    }

    pub fn done_refs(&self) -> Vec<ScanRef> {
        self.stored
            .iter()
            .map(|k| scan_ref(&self.plan, *k))
            .collect()
    }

    /// How far the probe keeps off the known surface when entering and leaving a scan, mm.
    pub fn margin_mm(&self) -> f64 {
        scan_margin_mm(&self.plan, self.record.kind)
    }

    /// Where a profile's scan starts, machine coordinates: for choosing the next scan nearest a machine.
    pub fn scan_start(&self, key: ProfileKey) -> Point3<f64> {
        let nominals = self
            .reference
            .as_ref()
            .map(|r| r.profiles[key.profile].nominals.as_slice());
        self.plan.scan_start(key, nominals)
    }

    /// The order that scans `key`, and the surface the station knows around it before scanning.
    pub fn order(
        &self,
        key: ProfileKey,
        pipeline: tokio::sync::mpsc::Sender<PipelineMsg>,
    ) -> ScanOrder {
        let (scan, path) = self.scan_and_path(key);
        ScanOrder {
            key,
            scan,
            path,
            margin_mm: self.margin_mm(),
            pipeline,
        }
    }

    fn scan_and_path(&self, key: ProfileKey) -> (Scan, KnownPath) {
        match &self.reference {
            Some(reference) => {
                let plan = self
                    .plan
                    .curve_scan(key, &reference.profiles[key.profile].nominals);
                let path = KnownPath::of_curve_scan(&plan);
                (Scan::Curve(plan), path)
            }
            None => {
                let plan = self.plan.in_plane_scan(key);
                let path = KnownPath {
                    surface: vec![Point3::new(plan.start.x, plan.start.y, plan.start.z)],
                    normals: vec![Vector3::new(
                        plan.start_normal.x,
                        plan.start_normal.y,
                        plan.start_normal.z,
                    )
                    .normalize()],
                    closed: false,
                    entry: 0,
                };
                (Scan::InPlane(plan), path)
            }
        }
    }

    /// The surface around a profile whose scan was cut by a killed daemon, from its partial file: the machine
    /// that scanned it and the path for its way out. `None` when no such file is there.
    pub fn cut_scan_path(&self, key: ProfileKey) -> Option<(String, KnownPath)> {
        let (header, points) = self.dir.read_partial(&scan_ref(&self.plan, key)).ok()??;
        let (_, mut path) = self.scan_and_path(key);
        if self.reference.is_none() {
            // Along the reported normals, point by point: the way out needs a safe path near the surface, not
            // the compensated contacts, and a cut scan's last points have no look-ahead anyway.
            for raw in &points {
                path.surface.push(surface_point(raw, header.ball_radius_mm));
                path.normals.push(Vector3::from(raw.normal).normalize());
            }
        }
        Some((header.machine, path))
    }

    /// Every profile of this job with a partial file on disk.
    pub fn cut_scans(&self) -> Vec<ProfileKey> {
        let partial = self.dir.partial_scans().unwrap_or_default();
        job_scans(&self.plan, self.record.kind)
            .into_iter()
            .filter(|key| partial.contains(&file_stem(&scan_ref(&self.plan, *key))))
            .collect()
    }
}

/// The scans a job of this kind makes.
/// How far the probe keeps off the known surface when entering and leaving a scan of a job of `kind`, mm.
pub(super) fn scan_margin_mm(plan: &Plan, kind: JobKind) -> f64 {
    match kind {
        JobKind::Teach => TEACH_MARGIN_MM,
        JobKind::Inspect => plan.scan_settings().max_deviation_mm + INSPECT_EXTRA_MARGIN_MM,
    }
}

/// Refuses an inspection whose descents or ways out would bring the stylus closer to the taught part than the
/// station's move margin (`clearance`).
pub fn check_inspection_moves(
    config: &StationConfig,
    plan: &Plan,
    reference: &Reference,
) -> Result<(), JobError> {
    let stylus = clearance::station_stylus(config).map_err(JobError)?;
    let part = clearance::machine_part(plan, reference).map_err(JobError)?;
    let moves = clearance::inspection_moves(
        plan,
        reference,
        &job_scans(plan, JobKind::Inspect),
        stylus.ball_radius_mm,
        scan_margin_mm(plan, JobKind::Inspect),
        config.safety.clearance_z_mm,
    )
    .map_err(JobError)?
    .into_iter()
    .filter(|m| m.kind != clearance::MoveKind::Scan)
    .collect();
    let margin = config.safety.move_margin_mm;
    let checked = clearance::check_moves(&stylus, moves, &part, margin);
    match clearance::refusal(plan, &checked, margin) {
        Some(message) => Err(JobError(message)),
        None => Ok(()),
    }
}

pub fn job_scans(plan: &Plan, kind: JobKind) -> Vec<ProfileKey> {
    match kind {
        JobKind::Teach => plan.teach_scans(),
        JobKind::Inspect => plan.inspect_scans(),
    }
}
