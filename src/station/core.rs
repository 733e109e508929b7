//! The daemon's decisions, with no I/O: `Core::handle(input) -> effects`, like the simulator's `Controller`. It
//! owns the machines' states and the job, and decides which machine scans what next, when a job stops, resumes,
//! is aborted or ends. Everything slow (loading and checking a job, writing records, fitting, reports) is an
//! effect that the shell (`daemon`) runs off this task and that comes back as an input, so `status` and `abort`
//! are answered at once whatever a job is doing.
//!
//! Safety rules kept here: a machine's lockout (an alarm, a fault, an operator's abort) is lifted only by an
//! operator's `zeroset clear`; an abort sends AbortE to the scanning machines and nothing else, never a clear or
//! a move; a job does not start while any machine is locked out.

use std::collections::BTreeMap;
use std::sync::Arc;

use nalgebra::Point3;

use super::escape::{EscapeModel, ScanPath};
use super::finish::Outcome;
use super::job::{Job, JobError};
use super::journal::{JobDir, JobRecord, JobState};
use super::motion::ScanMotion;
use super::pipeline::scan_ref;
use super::worker::{ScanResult, WorkerError};
use crate::api::{
    Event, FaultKind, JobKind, JobPhase, JobStatus, MachineFault, MachineState, MachineStatus,
    PreparingJob, Reply, Request, ScanRef, StationStatus,
};
use crate::geometry::sweep::mesh::MeshPart;
use crate::plan::ProfileKey;

/// Which request a reply answers; the shell keeps the reply channels.
pub type RequestId = u64;

/// What the core hears.
pub enum Input {
    Request {
        id: RequestId,
        request: Request,
    },
    /// A job was set up (or could not be) off the decision task.
    Prepared {
        id: RequestId,
        result: Result<Box<Job>, JobError>,
    },
    /// A worker ended a scan order (or the order could not be given).
    ScanEnded {
        machine: String,
        key: ProfileKey,
        result: ScanResult,
    },
    /// The recorder stored a profile's scan on disk (or could not).
    Stored {
        job: String,
        key: ProfileKey,
        result: Result<(), String>,
    },
    /// A worker's watch looked at its machine for the first time and found it ready.
    Seen {
        machine: String,
    },
    /// A worker's watch saw its idle machine stop: an alarm, an emergency stop, a lost line, a missing port.
    Observed {
        machine: String,
        fault: WorkerError,
    },
    /// A worker cleared its machine (or could not).
    Cleared {
        machine: String,
        result: Result<(), WorkerError>,
    },
    /// The analysis that ran before the one [`Effect::StartPipeline`] started has ended, every profile it had
    /// been given stored (or reported not stored); or it has not ended in time, and why.
    EarlierAnalysisEnded {
        job: String,
        result: Result<(), String>,
    },
    /// A job's reference was fitted or its report written (or not).
    Finished {
        job: String,
        result: Result<Outcome, String>,
    },
}

/// What the core asks the shell to do.
pub enum Effect {
    Reply {
        id: RequestId,
        reply: Reply,
    },
    Publish(Event),
    /// Load and check a new job; the result comes back as [`Input::Prepared`].
    Prepare {
        id: RequestId,
        kind: JobKind,
        part: String,
        serial: Option<String>,
    },
    /// A fresh analysis pipeline for the current job (at its start and when it resumes); once the one before it
    /// has ended the shell answers [`Input::EarlierAnalysisEnded`].
    StartPipeline,
    /// The current job's analysis is no longer needed (it is over or finishing).
    StopPipeline,
    /// Execute this planned motion on `machine`, its points to the job's pipeline.
    Scan {
        machine: String,
        motion: Box<ScanMotion>,
        /// The taught part model, against which the lift-off from where the scan really ended is checked.
        part: Option<Arc<MeshPart>>,
    },
    /// AbortE on `machine`: stop its motion now.
    Abort {
        machine: String,
    },
    /// Clear `machine`'s errors and take its probe clear of the part.
    Clear {
        machine: String,
        escape: EscapeModel,
    },
    /// Record how the job stands, on disk (fsynced).
    SaveRecord {
        dir: JobDir,
        record: JobRecord,
    },
    /// Fit the reference (teach) or write the report (inspect) from the scans on disk; comes back as
    /// [`Input::Finished`].
    Finish,
    /// Read the newest report of a serial number and answer `id` with it.
    ReadReport {
        id: RequestId,
        serial: String,
    },
}

/// A machine as the core sees it.
struct Slot {
    name: String,
    state: MachineState,
    /// Where its last scan started, for choosing the nearest next one.
    at: Option<Point3<f64>>,
}

/// A job being set up.
struct Preparing {
    id: RequestId,
    job: PreparingJob,
    /// The operator aborted it before it started.
    aborted: bool,
}

pub struct Core {
    station: String,
    slots: Vec<Slot>,
    preparing: Option<Preparing>,
    job: Option<Job>,
    /// The request owed an answer once every machine has cleared.
    clearing: Option<RequestId>,
    /// The operator's commands not answered yet, as the log names them: each answer is logged with its command.
    commands: BTreeMap<RequestId, String>,
    effects: Vec<Effect>,
}

const CLEAR_TO_CONTINUE: &str =
    "remove the cause, then run `zeroset clear`: the job continues from its last complete profile";

impl Core {
    /// The station's machines, not yet seen, and a job a previous daemon left open (stopped until `zeroset clear`).
    pub fn new(station: String, machines: Vec<String>, reopened: Option<Job>) -> Core {
        // A job left open means a daemon stopped while it ran: where its probes are is not known, so each machine
        // starts locked out, and only `zeroset clear` (with the cut scans' ways out) lifts that.
        let state = match &reopened {
            Some(job) => MachineState::LockedOut {
                fault: MachineFault {
                    kind: FaultKind::Station,
                    message: format!(
                        "the daemon stopped while job {} ran; the probe may be near the part",
                        job.info.id
                    ),
                },
            },
            None => MachineState::Unseen,
        };
        Core {
            station,
            slots: machines
                .into_iter()
                .map(|name| Slot {
                    name,
                    state: state.clone(),
                    at: None,
                })
                .collect(),
            preparing: None,
            commands: BTreeMap::new(),
            job: reopened,
            clearing: None,
            effects: Vec::new(),
        }
    }

    /// The current job (for the shell's pipeline and finishing work).
    pub fn job(&self) -> Option<&Job> {
        self.job.as_ref()
    }

    /// Handles one input; returns what the shell must do, in order.
    pub fn handle(&mut self, input: Input) -> Vec<Effect> {
        match input {
            Input::Request { id, request } => self.request(id, request),
            Input::Prepared { id, result } => self.prepared(id, result),
            Input::ScanEnded {
                machine,
                key,
                result,
            } => self.scan_ended(&machine, key, result),
            Input::Stored { job, key, result } => self.stored(&job, key, result),
            Input::Cleared { machine, result } => self.cleared(&machine, result),
            Input::Seen { machine } => self.seen(&machine),
            Input::Observed { machine, fault } => self.observed(&machine, fault),
            Input::EarlierAnalysisEnded { job, result } => {
                self.earlier_analysis_ended(&job, result)
            }
            Input::Finished { job, result } => self.finished(&job, result),
        }
        self.dispatch();
        self.finish_if_complete();
        std::mem::take(&mut self.effects)
    }

    fn emit(&mut self, effect: Effect) {
        self.effects.push(effect);
    }

    fn reply(&mut self, id: RequestId, reply: Reply) {
        if let Some(command) = self.commands.remove(&id) {
            match &reply {
                Reply::Error { message } => {
                    tracing::warn!(%command, outcome = %message, "operator command refused")
                }
                Reply::Done { message } => {
                    tracing::info!(%command, outcome = %message, "operator command done")
                }
                Reply::Started { job } => {
                    tracing::info!(%command, job = %job.id, "operator command started a job")
                }
                _ => {}
            }
        }
        self.emit(Effect::Reply { id, reply });
    }

    fn refuse(&mut self, id: RequestId, message: String) {
        self.reply(id, Reply::Error { message });
    }

    fn publish(&mut self, event: Event) {
        self.emit(Effect::Publish(event));
    }

    fn request(&mut self, id: RequestId, request: Request) {
        // What an operator asks of the station is logged, and its answer (`reply`); looking (status, watch,
        // report) is not.
        let command = match &request {
            Request::Teach { part } => Some(format!("teach {part}")),
            Request::Inspect { part, serial } => Some(format!("inspect {part} --serial {serial}")),
            Request::Abort => Some("abort".to_string()),
            Request::Clear => Some("clear".to_string()),
            Request::Status | Request::Report { .. } | Request::Subscribe => None,
        };
        if let Some(command) = command {
            tracing::info!(%command, "operator command");
            self.commands.insert(id, command);
        }
        match request {
            Request::Status => {
                let status = self.status();
                self.reply(id, Reply::Status(Box::new(status)));
            }
            Request::Teach { part } => self.start_job(id, JobKind::Teach, part, None),
            Request::Inspect { part, serial } => {
                self.start_job(id, JobKind::Inspect, part, Some(serial))
            }
            Request::Abort => self.abort(id),
            Request::Clear => self.clear(id),
            Request::Report { serial } => self.emit(Effect::ReadReport { id, serial }),
            // The control task answers subscriptions itself.
            Request::Subscribe => self.reply(id, Reply::Subscribed),
        }
    }

    fn start_job(&mut self, id: RequestId, kind: JobKind, part: String, serial: Option<String>) {
        if let Some(preparing) = &self.preparing {
            let message = format!(
                "a job on part {} is being set up; wait for it to start, or `zeroset abort` it",
                preparing.job.part
            );
            return self.refuse(id, message);
        }
        if let Some(job) = self.job.as_ref().filter(|j| !j.is_over()) {
            let message = format!(
                "job {} is not over ({}); wait for it, run `zeroset clear` to continue it, or `zeroset abort` to end it",
                job.info.id, job.phase
            );
            return self.refuse(id, message);
        }
        if let Some(serial) = &serial {
            let usable = !serial.is_empty()
                && serial
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
                && !serial.starts_with('.');
            if !usable {
                let message = format!("serial number {serial:?}: use letters, digits, '-', '_' and '.' (it names the report's folder)");
                return self.refuse(id, message);
            }
        }
        if let Some(message) = self.machines_not_ready() {
            return self.refuse(id, message);
        }
        self.preparing = Some(Preparing {
            id,
            job: PreparingJob {
                kind,
                part: part.clone(),
                serial: serial.clone(),
            },
            aborted: false,
        });
        self.emit(Effect::Prepare {
            id,
            kind,
            part,
            serial,
        });
    }

    /// Why no job may start now: a machine locked out (only `zeroset clear` lifts that) or being cleared.
    fn machines_not_ready(&self) -> Option<String> {
        let blocked: Vec<String> = self
            .slots
            .iter()
            .filter(|s| !matches!(s.state, MachineState::Idle | MachineState::Unseen))
            .map(|s| format!("machine {} is {}", s.name, s.state))
            .collect();
        (!blocked.is_empty()).then(|| {
            format!(
                "no job can start: {}; run `zeroset clear` once the cause is removed",
                blocked.join("; ")
            )
        })
    }

    fn prepared(&mut self, id: RequestId, result: Result<Box<Job>, JobError>) {
        let Some(preparing) = self.preparing.take().filter(|p| p.id == id) else {
            return;
        };
        let mut job = match result {
            Ok(job) => *job,
            Err(error) => return self.refuse(id, error.to_string()),
        };
        if preparing.aborted {
            job.record.state = JobState::Aborted;
            job.phase = JobPhase::Aborted;
            let message = format!(
                "job {} was aborted before it started; no machine moved",
                job.info.id
            );
            self.save_record(&job);
            self.job = Some(job);
            return self.refuse(id, message);
        }
        // A machine may have failed a clear meanwhile.
        if let Some(message) = self.machines_not_ready() {
            job.record.state = JobState::Failed {
                error: message.clone(),
            };
            job.phase = JobPhase::Failed {
                error: message.clone(),
            };
            self.save_record(&job);
            self.job = Some(job);
            return self.refuse(id, message);
        }
        let info = job.info.clone();
        tracing::info!(job = %info.id, kind = %info.kind, part = %info.part, "job started");
        self.job = Some(job);
        self.emit(Effect::StartPipeline);
        self.publish(Event::JobStarted {
            job: info.clone(),
            done: Vec::new(),
        });
        self.reply(id, Reply::Started { job: info });
    }

    /// Gives every idle machine the remaining scan nearest to it.
    fn dispatch(&mut self) {
        let Some(job) = self.job.as_mut() else {
            return;
        };
        if job.phase != JobPhase::Running || job.awaiting_earlier_analysis {
            return;
        }
        let mut orders = Vec::new();
        for slot in &mut self.slots {
            if slot.state != MachineState::Idle || job.remaining.is_empty() {
                continue;
            }
            let from = slot.at.unwrap_or_else(|| Point3::new(0.0, 0.0, 0.0));
            let Some(index) = job
                .plan
                .nearest(&job.remaining, from, |key| job.scan_start(key))
            else {
                continue;
            };
            let key = job.remaining.remove(index);
            let scan = scan_ref(&job.plan, key);
            slot.state = MachineState::Scanning { scan: scan.clone() };
            slot.at = Some(job.scan_start(key));
            job.last_given.insert(slot.name.clone(), scan.clone());
            tracing::info!(job = %job.info.id, machine = %slot.name, scan = %job.plan.describe(key), "scan started");
            orders.push((slot.name.clone(), Box::new(job.motions[&key].clone()), scan));
        }
        let id = job.info.id.clone();
        let part = job.part_model.clone();
        for (machine, motion, scan) in orders {
            self.publish(Event::ScanStarted {
                job: id.clone(),
                machine: machine.clone(),
                scan,
                at_unix_ms: super::clock::unix_ms(),
            });
            self.emit(Effect::Scan {
                machine,
                motion,
                part: part.clone(),
            });
        }
    }

    fn slot(&mut self, machine: &str) -> Option<&mut Slot> {
        self.slots.iter_mut().find(|s| s.name == machine)
    }

    fn scanning(&self) -> bool {
        self.slots
            .iter()
            .any(|s| matches!(s.state, MachineState::Scanning { .. }))
    }

    fn scan_ended(&mut self, machine: &str, key: ProfileKey, result: ScanResult) {
        if let Err(error) = &result {
            if error.kind == FaultKind::Gap {
                return self.gap(machine, key, error);
            }
        }
        let aborting = self
            .job
            .as_ref()
            .is_some_and(|j| j.phase == JobPhase::Aborting);
        let fault = result.err().map(|error| {
            let mut fault = error.fault();
            // The scan an abort cut ends with the machine's "transaction aborted"; an alarm keeps its own kind.
            let alarm =
                matches!(fault.kind, FaultKind::Device { code, .. } if code == 500 || code == 2504);
            if aborting && !alarm {
                fault.kind = FaultKind::Aborted;
            }
            fault
        });
        let fault = match fault {
            // The abort was sent; it locks the machine out even when it came after the scan's last move.
            None if aborting => Some(MachineFault {
                kind: FaultKind::Aborted,
                message: format!("machine {machine}: aborted by the operator"),
            }),
            fault => fault,
        };
        if let Some(slot) = self.slot(machine) {
            slot.state = match &fault {
                None => MachineState::Idle,
                Some(fault) => MachineState::LockedOut {
                    fault: fault.clone(),
                },
            };
        }
        if let (Some(job), Some(fault)) = (self.job.as_mut(), &fault) {
            if !job.stored.contains(&key) && !job.remaining.contains(&key) {
                job.remaining.push(key);
            }
            if job.phase == JobPhase::Running {
                let scan = scan_ref(&job.plan, key);
                let reason = format!(
                    "{} of part {}: {}",
                    job.plan.describe(key),
                    job.info.part,
                    fault.message
                );
                let event = stop(job, Some(machine), Some(scan), reason, CLEAR_TO_CONTINUE);
                self.publish(event);
            }
        }
        self.abort_done_if_stopped();
    }

    /// The watch's first look found the machine ready: it may take scans. (A machine locked out or cleared since
    /// stays as it is.)
    fn seen(&mut self, machine: &str) {
        if let Some(slot) = self
            .slot(machine)
            .filter(|s| s.state == MachineState::Unseen)
        {
            slot.state = MachineState::Idle;
        }
    }

    /// The watch of an idle machine saw it stop (an alarm, an emergency stop, its line or port gone): it is
    /// locked out until the operator's clear, and a running job stops, since the machine can take no more of its
    /// scans. A machine busy with an order hears of the fault through the order's end instead.
    fn observed(&mut self, machine: &str, fault: WorkerError) {
        let Some(slot) = self
            .slot(machine)
            .filter(|s| matches!(s.state, MachineState::Idle | MachineState::Unseen))
        else {
            return;
        };
        slot.state = MachineState::LockedOut {
            fault: fault.fault(),
        };
        let from = slot.at.unwrap_or_else(Point3::origin);
        let Some(job) = self.job.as_mut().filter(|j| j.phase == JobPhase::Running) else {
            return;
        };
        // The machine is between scans: the profile it scanned last is where its probe is; before its first,
        // the one it would have been given.
        let (scan, which) = match job.last_given.get(machine) {
            Some(last) => (Some(last.clone()), "last"),
            None => {
                let next = job
                    .plan
                    .nearest(&job.remaining, from, |key| job.scan_start(key))
                    .map(|index| scan_ref(&job.plan, job.remaining[index]));
                (next, "next")
            }
        };
        let named = scan
            .as_ref()
            .map(|s| {
                format!(
                    " (its {which} scan: instance {} profile {})",
                    s.instance, s.profile
                )
            })
            .unwrap_or_default();
        let reason = format!("part {}: {}{named}", job.info.part, fault.message);
        let event = stop(job, Some(machine), scan, reason, CLEAR_TO_CONTINUE);
        self.publish(event);
    }

    /// A scan that ended well with a hole in it: the machine is ready; the profile is scanned again once, and a
    /// second hole stops the job.
    fn gap(&mut self, machine: &str, key: ProfileKey, error: &WorkerError) {
        let aborting = self
            .job
            .as_ref()
            .is_some_and(|j| j.phase == JobPhase::Aborting);
        if let Some(slot) = self.slot(machine) {
            slot.state = if aborting {
                MachineState::LockedOut {
                    fault: MachineFault {
                        kind: FaultKind::Aborted,
                        message: format!("machine {machine}: aborted by the operator"),
                    },
                }
            } else {
                MachineState::Idle
            };
        }
        let Some(job) = self.job.as_mut() else {
            return;
        };
        let scan = scan_ref(&job.plan, key);
        if !job.stored.contains(&key) && !job.remaining.contains(&key) {
            job.remaining.insert(0, key);
        }
        let first = job.rescanned.insert(key);
        job.record.rescans.push(crate::report::Rescan {
            instance: scan.instance.clone(),
            profile: scan.profile.clone(),
            reason: error.message.clone(),
            at: super::clock::now_rfc3339(),
        });
        let (dir, record) = (job.dir.clone(), job.record.clone());
        let id = job.info.id.clone();
        if first && job.phase == JobPhase::Running {
            tracing::warn!(job = %id, machine, scan = %job.plan.describe(key), error = %error.message, "scanning again");
            self.emit(Effect::SaveRecord { dir, record });
            self.publish(Event::ProfileRescanned {
                job: id,
                machine: machine.to_string(),
                scan,
                reason: error.message.clone(),
            });
            return;
        }
        let running = job.phase == JobPhase::Running;
        self.emit(Effect::SaveRecord { dir, record });
        if !running {
            return self.abort_done_if_stopped();
        }
        let Some(job) = self.job.as_mut() else {
            return;
        };
        let next_step = "check the line to the machine (cable, controller), then run `zeroset clear`: the profile \
                         is scanned again";
        let reason = format!(
            "{} of part {} has a hole again after a rescan: {}",
            job.plan.describe(key),
            job.info.part,
            error.message
        );
        let event = stop(job, Some(machine), Some(scan), reason, next_step);
        self.publish(event);
    }

    fn stored(&mut self, job_id: &str, key: ProfileKey, result: Result<(), String>) {
        let Some(job) = self.job.as_mut().filter(|j| j.info.id == job_id) else {
            return;
        };
        let error = match result {
            Ok(()) => {
                // The scan may have been put back for scanning when its machine failed after the last point
                // (the way out collided): its points are on disk, so it is done and never scanned again.
                job.stored.insert(key);
                job.remaining.retain(|k| *k != key);
                return;
            }
            Err(error) => error,
        };
        if !job.remaining.contains(&key) {
            job.remaining.push(key);
        }
        if job.phase != JobPhase::Running {
            return;
        }
        let next_step = "free space or fix the data folder's permissions, then run `zeroset clear`";
        let reason = format!(
            "{} of part {}: its points could not be stored: {error}",
            job.plan.describe(key),
            job.info.part
        );
        let scan = scan_ref(&job.plan, key);
        let machine = job
            .last_given
            .iter()
            .find(|(_, given)| **given == scan)
            .map(|(machine, _)| machine.clone());
        let event = stop(job, machine.as_deref(), Some(scan), reason, next_step);
        self.publish(event);
    }

    /// The analysis from before a resume has ended: scans are given again. One that does not end is a station
    /// fault (its recorder stalled, or it failed): the job stops rather than scan beside it.
    fn earlier_analysis_ended(&mut self, job_id: &str, result: Result<(), String>) {
        let Some(job) = self.job.as_mut().filter(|j| j.info.id == job_id) else {
            return;
        };
        if !std::mem::take(&mut job.awaiting_earlier_analysis) {
            return;
        }
        let Err(error) = result else {
            return;
        };
        if job.phase != JobPhase::Running {
            return;
        }
        let reason = format!(
            "the analysis of the scans before the stop did not end: {error}; no scan was given beside it"
        );
        let next_step = "check the data folder's disk, then run `zeroset clear`; if this recurs, restart the daemon (the job resumes from the scans on disk)";
        let event = stop(job, None, None, reason, next_step);
        self.publish(event);
    }

    /// Starts the fit or the report once every profile is on disk and no machine is still scanning.
    fn finish_if_complete(&mut self) {
        let busy = self.scanning();
        let Some(job) = self.job.as_mut() else {
            return;
        };
        if job.phase != JobPhase::Running || busy || job.stored.len() < job.total {
            return;
        }
        job.phase = JobPhase::Finishing;
        self.emit(Effect::StopPipeline);
        self.emit(Effect::Finish);
    }

    fn finished(&mut self, job_id: &str, result: Result<Outcome, String>) {
        let Some(job) = self.job.as_mut().filter(|j| j.info.id == job_id) else {
            return;
        };
        let event = match result {
            Ok(Outcome::Taught { path, profiles }) => {
                job.record.state = JobState::Finished;
                job.phase = JobPhase::Finished;
                Event::ReferenceSaved {
                    job: job_id.to_string(),
                    part: job.info.part.clone(),
                    path,
                    profiles,
                }
            }
            Ok(Outcome::Inspected {
                dir,
                instances,
                verdict,
            }) => {
                job.record.state = JobState::Finished;
                job.record.report = Some(dir.clone());
                job.phase = JobPhase::Finished;
                Event::JobFinished {
                    job: job_id.to_string(),
                    report: Some(dir),
                    instances,
                    verdict: Some(verdict),
                }
            }
            Err(error) => {
                // Every scan is on disk and stays counted: once the cause is removed (a reports folder that
                // cannot be written, a full disk) the job is finished from them, without scanning again.
                let what = match job.info.kind {
                    JobKind::Teach => "fitting its reference",
                    JobKind::Inspect => "writing its report",
                };
                let reason =
                    format!("job {job_id}: every profile is on disk, but {what} failed: {error}");
                let next_step = "remove the cause, then run `zeroset clear` to finish it from its scans (nothing \
                                 is scanned again), or `zeroset abort` to end it";
                let event = stop(job, None, None, reason, next_step);
                self.publish(event);
                return;
            }
        };
        tracing::info!(job = job_id, phase = %job.phase, "job over");
        let (dir, record) = (job.dir.clone(), job.record.clone());
        self.emit(Effect::SaveRecord { dir, record });
        self.publish(event);
    }

    fn abort(&mut self, id: RequestId) {
        // A machine leaving the part after `zeroset clear` is stopped too: the operator saw it going wrong.
        let clearing: Vec<String> = self
            .slots
            .iter()
            .filter(|s| s.state == MachineState::Clearing)
            .map(|s| s.name.clone())
            .collect();
        for machine in &clearing {
            self.emit(Effect::Abort {
                machine: machine.clone(),
            });
        }
        if !clearing.is_empty() && self.job.as_ref().is_none_or(|j| j.is_over()) {
            let message = format!(
                "motion stopped on {}; run `zeroset clear` once the probe's way is free",
                clearing.join(", ")
            );
            return self.reply(id, Reply::Done { message });
        }
        if let Some(preparing) = self.preparing.as_mut() {
            preparing.aborted = true;
            let message = format!(
                "the job on part {} that is being set up will not start; no machine moves",
                preparing.job.part
            );
            return self.reply(id, Reply::Done { message });
        }
        let Some(job) = self.job.as_mut().filter(|j| !j.is_over()) else {
            return self.refuse(id, "no job to abort".into());
        };
        let job_id = job.info.id.clone();
        match &job.phase {
            JobPhase::Finishing => {
                let message = format!(
                    "job {job_id} has every profile on disk and is being finished; it cannot be aborted now"
                );
                self.refuse(id, message);
            }
            JobPhase::Aborting => {
                self.refuse(id, format!("job {job_id} is already being aborted"));
            }
            phase => {
                // A stopped job's faulted machines stay as the fault left them, locked out until `zeroset
                // clear`; only machines still scanning are stopped.
                let stopped = matches!(phase, JobPhase::Stopped { .. });
                job.phase = JobPhase::Aborting;
                let scanning: Vec<String> = self
                    .slots
                    .iter()
                    .filter(|s| matches!(s.state, MachineState::Scanning { .. }))
                    .map(|s| s.name.clone())
                    .collect();
                for machine in &scanning {
                    self.emit(Effect::Abort {
                        machine: machine.clone(),
                    });
                }
                tracing::warn!(job = %job_id, machines = %scanning.join(", "), "aborted by the operator");
                self.abort_done_if_stopped();
                let mut message =
                    format!("job {job_id} is aborted (its scans so far stay on disk)");
                if !scanning.is_empty() {
                    message.push_str(&format!("; motion stopped on {}", scanning.join(", ")));
                }
                message.push_str(if stopped {
                    "; no machine was cleared or moved: run `zeroset clear` once the cause of the stop is removed"
                } else if scanning.is_empty() {
                    ""
                } else {
                    "; run `zeroset clear` to take the probe clear of the part"
                });
                self.reply(id, Reply::Done { message });
            }
        }
    }

    /// Once an aborted job's machines have stopped, the job is over. They stay locked out: lifting that is the
    /// operator's `zeroset clear`.
    fn abort_done_if_stopped(&mut self) {
        if self.scanning() {
            return;
        }
        let Some(job) = self.job.as_mut().filter(|j| j.phase == JobPhase::Aborting) else {
            return;
        };
        job.record.state = JobState::Aborted;
        job.phase = JobPhase::Aborted;
        let (id, dir, record) = (job.info.id.clone(), job.dir.clone(), job.record.clone());
        self.emit(Effect::SaveRecord { dir, record });
        self.emit(Effect::StopPipeline);
        self.publish(Event::JobAborted { job: id });
    }

    fn save_record(&mut self, job: &Job) {
        self.emit(Effect::SaveRecord {
            dir: job.dir.clone(),
            record: job.record.clone(),
        });
    }

    fn clear(&mut self, id: RequestId) {
        if self.clearing.is_some() {
            return self.refuse(id, "a clear is already in progress".into());
        }
        if self.preparing.is_some() {
            return self.refuse(
                id,
                "a job is being set up: nothing moves until it starts; clear after it".into(),
            );
        }
        if let Some(job) = self.job.as_ref() {
            if matches!(
                job.phase,
                JobPhase::Running | JobPhase::Finishing | JobPhase::Aborting
            ) {
                let message = format!("job {} is {}: nothing to clear", job.info.id, job.phase);
                return self.refuse(id, message);
            }
        }
        self.clearing = Some(id);
        let open = self.job.as_ref().filter(|j| !j.is_over());
        let part = self.job.as_ref().and_then(|j| j.part_model.clone());
        let deviation_margin_mm = self
            .job
            .as_ref()
            .and_then(|j| j.motions.values().next())
            .map_or(0.0, |m| m.margin_mm);
        let cut: Vec<(String, ScanPath)> = open.map(|j| j.cut_paths.clone()).unwrap_or_default();
        // Every scan the job plans, for a machine whose probe may be on any of them (after a restart).
        let planned: Vec<ScanPath> = open
            .map(|j| {
                j.motions
                    .values()
                    .map(|m| ScanPath {
                        name: m.name.clone(),
                        path: m.path.clone(),
                        margin_mm: m.margin_mm,
                    })
                    .collect()
            })
            .unwrap_or_default();
        let mut orders = Vec::new();
        for slot in &mut self.slots {
            if matches!(slot.state, MachineState::Scanning { .. }) {
                continue;
            }
            let escape = EscapeModel {
                paths: cut
                    .iter()
                    .filter(|(machine, _)| *machine == slot.name)
                    .map(|(_, scan)| scan.clone())
                    .chain(planned.iter().cloned())
                    .collect(),
                part: part.clone(),
                deviation_margin_mm,
            };
            slot.state = MachineState::Clearing;
            orders.push(Effect::Clear {
                machine: slot.name.clone(),
                escape,
            });
        }
        self.effects.extend(orders);
        self.resume_if_clear();
    }

    fn cleared(&mut self, machine: &str, result: Result<(), WorkerError>) {
        if let Err(error) = &result {
            tracing::error!(machine, error = %error, "clear failed");
        }
        if let Some(slot) = self.slot(machine) {
            slot.state = match result {
                Ok(()) => MachineState::Idle,
                Err(error) => MachineState::LockedOut {
                    fault: error.fault(),
                },
            };
        }
        // The cut scans' paths served their one way out.
        if let Some(job) = self.job.as_mut() {
            job.cut_paths.retain(|(m, _)| m != machine);
        }
        self.resume_if_clear();
    }

    /// When no machine is clearing any more: answer the operator, and resume a stopped job if all went well.
    fn resume_if_clear(&mut self) {
        if self.slots.iter().any(|s| s.state == MachineState::Clearing) {
            return;
        }
        let Some(id) = self.clearing.take() else {
            return;
        };
        let faults: Vec<String> = self
            .slots
            .iter()
            .filter_map(|s| match &s.state {
                MachineState::LockedOut {
                    fault: MachineFault { kind, message },
                } => Some(format!("{message} ({kind})")),
                _ => None,
            })
            .collect();
        if !faults.is_empty() {
            return self.refuse(id, format!("not cleared: {}", faults.join("; ")));
        }
        let resumed = match self.job.as_mut() {
            Some(job) if matches!(job.phase, JobPhase::Stopped { .. }) => {
                job.phase = JobPhase::Running;
                job.awaiting_earlier_analysis = true;
                Some((job.info.clone(), job.done_refs()))
            }
            _ => None,
        };
        let message = match resumed {
            Some((info, done)) => {
                self.emit(Effect::StartPipeline);
                self.publish(Event::JobStarted {
                    job: info.clone(),
                    done,
                });
                self.publish(Event::JobResumed {
                    job: info.id.clone(),
                });
                format!(
                    "machines clear; job {} continues from its last complete profile",
                    info.id
                )
            }
            None => "machines clear".to_string(),
        };
        self.reply(id, Reply::Done { message });
    }

    fn status(&self) -> StationStatus {
        let machines = self
            .slots
            .iter()
            .map(|slot| MachineStatus {
                name: slot.name.clone(),
                state: slot.state.clone(),
            })
            .collect();
        let job = self.job.as_ref().map(|job| JobStatus {
            job: job.info.clone(),
            state: job.phase.clone(),
            profiles_done: job.stored.len(),
            profiles_total: job.total,
        });
        StationStatus {
            station: self.station.clone(),
            machines,
            preparing: self.preparing.as_ref().map(|p| p.job.clone()),
            job,
        }
    }
}

/// Stops `job` for `reason` (logged), waiting for what `next_step` says; the event that tells the operator.
fn stop(
    job: &mut Job,
    machine: Option<&str>,
    scan: Option<ScanRef>,
    reason: String,
    next_step: &str,
) -> Event {
    tracing::error!(job = %job.info.id, machine, %reason, "job stopped");
    job.phase = JobPhase::Stopped {
        machine: machine.map(str::to_string),
        scan: scan.clone(),
        reason: reason.clone(),
        next_step: next_step.to_string(),
    };
    Event::JobStopped {
        job: job.info.id.clone(),
        machine: machine.map(str::to_string),
        scan,
        reason,
        next_step: next_step.to_string(),
    }
}

#[cfg(test)]
mod tests;
