//! A job in the daemon: its plan, what is left to scan, what is done, and how its scans are set up. Built either
//! fresh from an operator's request or from a job folder left open by a fault or a killed daemon.

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::Arc;

use nalgebra::{Point3, Vector3};

use super::clearance;
use super::escape::ScanPath;
use super::journal::{file_stem, JobDir, JobRecord, JobState};
use super::motion::{check_volumes, job_motions, ScanMotion};
use super::pipeline::scan_ref;
use crate::analysis::deviation::ProfileGauge;
use crate::analysis::reference::Reference;
use crate::analysis::stats::Tolerance;
use crate::analysis::surface_point;
use crate::api::{JobInfo, JobKind, JobPhase, ScanRef};
use crate::config::{PartConfig, StationConfig};
use crate::geometry::sweep::mesh::MeshPart;
use crate::plan::{Plan, ProfileKey};

/// A job: what it scans and how, and how far it has got. Built off the daemon's decision task (loading and
/// checking take most of a second), then owned by it.
pub struct Job {
    pub info: JobInfo,
    pub record: JobRecord,
    pub dir: JobDir,
    pub plan: Arc<Plan>,
    pub reference: Option<Arc<Reference>>,
    pub gauges: Option<Arc<Vec<ProfileGauge>>>,
    /// Every scan's motion, built once: checked before the job starts and sent as it is.
    pub motions: BTreeMap<ProfileKey, ScanMotion>,
    /// The taught part on the machine, every instance: what a way out after a stop is checked against.
    pub part_model: Option<Arc<MeshPart>>,
    /// The scans a killed daemon cut short, read from their partial files when the job was reopened: the machine
    /// that scanned each, the path its way out follows and its margin (mm).
    pub cut_paths: Vec<(String, ScanPath)>,
    pub remaining: Vec<ProfileKey>,
    pub stored: BTreeSet<ProfileKey>,
    /// Profiles already scanned again for a hole in their scan: a second hole stops the job.
    pub rescanned: BTreeSet<ProfileKey>,
    /// The profile each machine was given last: what a fault seen while it is idle names.
    pub last_given: BTreeMap<String, ScanRef>,
    /// Set when the job resumes, while the analysis that ran before its stop may still be storing profiles its
    /// machines had finished: no scan is given until that analysis has ended, so a profile it stores is known to
    /// be done and never scanned (and written) a second time beside it.
    pub awaiting_earlier_analysis: bool,
    pub total: usize,
    pub phase: JobPhase,
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

/// A new job of `kind` on `part`, its moves planned and (inspecting) checked against the taught part, its folder
/// created. Blocking: it loads files and meshes the part.
pub fn prepare(
    config: &StationConfig,
    kind: JobKind,
    part: &str,
    serial: Option<String>,
) -> Result<Job, JobError> {
    let plan = load_plan(config, part)?;
    let reference = match kind {
        JobKind::Teach => None,
        JobKind::Inspect => Some(load_reference(config, &plan)?),
    };
    let (motions, part_model) = plan_moves(config, &plan, kind, reference.as_ref().map(|r| &*r.0))?;
    Job::create(config, kind, plan, serial, reference, motions, part_model)
}

/// A job's planned motions by profile, and the taught part they were checked against.
type PlannedMoves = (BTreeMap<ProfileKey, ScanMotion>, Option<Arc<MeshPart>>);

/// A reference and a gauge per profile.
type LoadedReference = (Arc<Reference>, Arc<Vec<ProfileGauge>>);

/// Every scan's motion, and (inspecting) the taught part on the machine with every free move checked against it.
fn plan_moves(
    config: &StationConfig,
    plan: &Plan,
    kind: JobKind,
    reference: Option<&Reference>,
) -> Result<PlannedMoves, JobError> {
    crate::plan::check_clearance(config, plan, reference).map_err(|e| JobError(e.to_string()))?;
    let keys = job_scans(plan, kind);
    let motions = job_motions(plan, reference, &keys, &config.safety)
        .and_then(|motions| check_volumes(&motions, &config.machines).map(|()| motions))
        .map_err(|e| {
            JobError(format!(
                "{e}; check the part file and [safety] of the station file"
            ))
        })?;
    let part_model = match reference {
        Some(reference) => {
            let part = clearance::machine_part(plan, reference).map_err(JobError)?;
            check_moves(config, plan, &motions, &part)?;
            Some(Arc::new(part))
        }
        None => None,
    };
    let motions = motions.into_iter().map(|m| (m.key, m)).collect();
    Ok((motions, part_model))
}

/// Refuses a plan whose descents, lift-offs or ways out would bring the stylus closer to the taught part than the
/// station's move margin (`clearance`).
fn check_moves(
    config: &StationConfig,
    plan: &Plan,
    motions: &[ScanMotion],
    part: &MeshPart,
) -> Result<(), JobError> {
    let stylus = clearance::station_stylus(config).map_err(JobError)?;
    let moves = clearance::swept_moves(motions)
        .map_err(JobError)?
        .into_iter()
        .filter(|m| m.kind != clearance::MoveKind::Scan)
        .collect();
    let margin = config.safety.move_margin_mm;
    let checked = clearance::check_moves(&stylus, moves, part, margin);
    match clearance::refusal(plan, &checked, margin) {
        Some(message) => Err(JobError(message)),
        None => Ok(()),
    }
}

/// The reference of a part, and a gauge per profile (sampling each profile's zero set: done once per job).
pub fn load_reference(config: &StationConfig, plan: &Plan) -> Result<LoadedReference, JobError> {
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
    fn create(
        config: &StationConfig,
        kind: JobKind,
        plan: Plan,
        serial: Option<String>,
        reference: Option<LoadedReference>,
        motions: BTreeMap<ProfileKey, ScanMotion>,
        part_model: Option<Arc<MeshPart>>,
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
            rescans: Vec::new(),
        };
        let dir = JobDir::create(&config.folders.data, &record)
            .map_err(|e| JobError(format!("cannot start the job: {e}")))?;
        Ok(Job::from_parts(
            config,
            record,
            dir,
            plan,
            reference,
            (motions, part_model),
            BTreeSet::new(),
        ))
    }

    /// A job left open on disk: its complete profiles stay done, the rest is scanned after `zeroset clear` by the
    /// same motions, planned and checked again.
    pub fn reopen(config: &StationConfig, dir: JobDir, record: JobRecord) -> Result<Job, JobError> {
        let plan = load_plan(config, &record.part)?;
        let reference = match record.kind {
            JobKind::Teach => None,
            JobKind::Inspect => Some(load_reference(config, &plan)?),
        };
        let moves = plan_moves(
            config,
            &plan,
            record.kind,
            reference.as_ref().map(|r| &*r.0),
        )?;
        let completed = dir
            .completed()
            .map_err(|e| JobError(format!("cannot read {}: {e}", dir.path().display())))?;
        let keys = job_scans(&plan, record.kind);
        let stored = keys
            .iter()
            .copied()
            .filter(|key| completed.contains(&file_stem(&scan_ref(&plan, *key))))
            .collect();
        let mut job = Job::from_parts(config, record, dir, plan, reference, moves, stored);
        job.cut_paths = job
            .cut_scans()
            .into_iter()
            .filter_map(|key| job.cut_scan_path(key))
            .collect();
        job.phase = JobPhase::Stopped {
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
        reference: Option<LoadedReference>,
        (motions, part_model): PlannedMoves,
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
            motions,
            part_model,
            cut_paths: Vec::new(),
            remaining,
            stored,
            rescanned: BTreeSet::new(),
            last_given: BTreeMap::new(),
            awaiting_earlier_analysis: false,
            total: keys.len(),
            phase: JobPhase::Running,
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
        self.phase.is_over()
    }

    pub fn done_refs(&self) -> Vec<ScanRef> {
        self.stored
            .iter()
            .map(|k| scan_ref(&self.plan, *k))
            .collect()
    }

    /// Where a profile's scan starts, machine coordinates: for choosing the next scan nearest a machine.
    pub fn scan_start(&self, key: ProfileKey) -> Point3<f64> {
        let nominals = self
            .reference
            .as_ref()
            .map(|r| r.profiles[key.profile].nominals.as_slice());
        self.plan.scan_start(key, nominals)
    }

    /// The surface around a profile whose scan was cut by a killed daemon, from its partial file: the machine
    /// that scanned it and the path for its way out. `None` when no such file is there.
    fn cut_scan_path(&self, key: ProfileKey) -> Option<(String, ScanPath)> {
        let (header, points) = self.dir.read_partial(&scan_ref(&self.plan, key)).ok()??;
        let motion = self.motions.get(&key)?;
        let mut path = motion.path.clone();
        if self.reference.is_none() {
            // Along the reported normals, point by point: the way out needs a safe path near the surface, not
            // the compensated contacts, and a cut scan's last points have no look-ahead anyway.
            for raw in &points {
                if let Some(normal) = Vector3::from(raw.normal).try_normalize(1e-9) {
                    path.surface.push(surface_point(raw, header.ball_radius_mm));
                    path.normals.push(normal);
                }
            }
        }
        let scan = ScanPath {
            name: motion.name.clone(),
            path,
            margin_mm: motion.margin_mm,
        };
        Some((header.machine, scan))
    }

    /// Every profile of this job with a partial file on disk.
    fn cut_scans(&self) -> Vec<ProfileKey> {
        let partial = self.dir.partial_scans().unwrap_or_default();
        job_scans(&self.plan, self.record.kind)
            .into_iter()
            .filter(|key| partial.contains(&file_stem(&scan_ref(&self.plan, *key))))
            .collect()
    }
}

/// The scans a job of this kind makes.
pub fn job_scans(plan: &Plan, kind: JobKind) -> Vec<ProfileKey> {
    match kind {
        JobKind::Teach => plan.teach_scans(),
        JobKind::Inspect => plan.inspect_scans(),
    }
}
