//! The daemon's state: the machines, the job, and every decision about them. One task owns it and handles one
//! message at a time, so no decision races another.

use std::path::PathBuf;
use std::sync::Arc;

use nalgebra::Point3;
use tokio::sync::{broadcast, mpsc, oneshot};

use super::finish::{self, Outcome, ReportInputs};
use super::job::{
    check_inspection_moves, load_plan, load_reference, reference_path, Job, JobError, Phase,
};
use super::journal::{open_jobs, JobState};
use super::pipeline::{scan_ref, Pipeline, QUEUE_POINTS};
use super::worker::{Order, WorkerError, WorkerHandle};
use super::DaemonMsg;
use crate::api::{Event, JobKind, JobStatus, MachineStatus, Reply, Request, StationStatus};
use crate::config::StationConfig;
use crate::plan::ProfileKey;

/// A machine as the daemon sees it.
struct Slot {
    handle: WorkerHandle,
    state: SlotState,
    /// Where its last scan started, for choosing the nearest next one.
    at: Option<Point3<f64>>,
}

#[derive(Debug, Clone, PartialEq)]
enum SlotState {
    Idle,
    Scanning(ProfileKey),
    Faulted(String),
    Clearing,
}

pub struct Daemon {
    config: Arc<StationConfig>,
    slots: Vec<Slot>,
    events: broadcast::Sender<Event>,
    to_self: mpsc::Sender<DaemonMsg>,
    job: Option<Job>,
    /// The reply owed to a `clear` until every machine has answered.
    clearing: Option<oneshot::Sender<Reply>>,
}

impl Daemon {
    /// The daemon's state, with the newest job a previous daemon left open, stopped until `zeroset clear`.
    pub fn start(
        config: StationConfig,
        workers: Vec<WorkerHandle>,
        events: broadcast::Sender<Event>,
        to_self: mpsc::Sender<DaemonMsg>,
    ) -> anyhow::Result<Daemon> {
        let mut open = open_jobs(&config.folders.data)?;
        let job = match open.pop() {
            Some((dir, record)) => {
                let id = record.id.clone();
                match Job::reopen(&config, dir, record) {
                    Ok(job) => {
                        tracing::info!(job = %id, done = job.stored.len(), total = job.total, "reopened a job left open");
                        Some(job)
                    }
                    Err(error) => {
                        tracing::error!(job = %id, %error, "cannot reopen a job left open");
                        None
                    }
                }
            }
            None => None,
        };
        let slots = workers
            .into_iter()
            .map(|handle| Slot {
                handle,
                state: SlotState::Idle,
                at: None,
            })
            .collect();
        Ok(Daemon {
            config: Arc::new(config),
            slots,
            events,
            to_self,
            job,
            clearing: None,
        })
    }

    pub async fn run(mut self, mut inbox: mpsc::Receiver<DaemonMsg>) {
        while let Some(message) = inbox.recv().await {
            match message {
                DaemonMsg::Request { request, reply } => self.request(request, reply).await,
                DaemonMsg::ScanEnded {
                    machine,
                    key,
                    result,
                } => self.scan_ended(&machine, key, result),
                DaemonMsg::Stored { job, key, result } => self.stored(&job, key, result),
                DaemonMsg::Cleared { machine, result } => self.cleared(&machine, result),
                DaemonMsg::Finished { job, result } => self.finished(&job, result),
            }
            self.dispatch();
            self.finish_if_complete();
        }
    }

    fn publish(&self, event: Event) {
        let _ = self.events.send(event);
    }

    async fn request(&mut self, request: Request, reply: oneshot::Sender<Reply>) {
        let answer = match request {
            Request::Status => Reply::Status(self.status()),
            Request::Teach { part } => self.start_job(JobKind::Teach, &part, None),
            Request::Inspect { part, serial } => {
                self.start_job(JobKind::Inspect, &part, Some(serial))
            }
            Request::Abort => self.abort(),
            Request::Clear => {
                self.clear(reply);
                return;
            }
            Request::Report { serial } => report(&self.config, &serial),
            // The control task answers subscriptions itself.
            Request::Subscribe => Reply::Subscribed,
        };
        let _ = reply.send(answer);
    }

    fn start_job(&mut self, kind: JobKind, part: &str, serial: Option<String>) -> Reply {
        if let Some(job) = self.job.as_ref().filter(|j| !j.is_over()) {
            return Reply::Error {
                message: format!(
                    "job {} is not over ({}); wait for it, run `zeroset clear` to continue it, or `zeroset abort` to end it",
                    job.info.id,
                    phase_name(&job.phase)
                ),
            };
        }
        if let Some(serial) = &serial {
            if serial.is_empty()
                || !serial
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
                || serial.starts_with('.')
            {
                return Reply::Error {
                    message: format!("serial number {serial:?}: use letters, digits, '-', '_' and '.' (it names the report's folder)"),
                };
            }
        }
        let created = (|| -> Result<Job, JobError> {
            let plan = load_plan(&self.config, part)?;
            let reference = match kind {
                JobKind::Teach => None,
                JobKind::Inspect => {
                    let loaded = load_reference(&self.config, &plan)?;
                    check_inspection_moves(&self.config, &plan, &loaded.0)?;
                    Some(loaded)
                }
            };
            Job::create(&self.config, kind, plan, serial, reference)
        })();
        match created {
            Ok(job) => {
                let info = job.info.clone();
                tracing::info!(job = %info.id, kind = ?kind, part, "job started");
                self.job = Some(job);
                self.start_pipeline();
                self.publish(Event::JobStarted {
                    job: info.clone(),
                    done: Vec::new(),
                });
                Reply::Started { job: info }
            }
            Err(error) => Reply::Error {
                message: error.to_string(),
            },
        }
    }

    /// A fresh pipeline for the job (at its start, and when it resumes: a stopped job's scans were cut).
    fn start_pipeline(&mut self) {
        let Some(job) = self.job.as_mut() else {
            return;
        };
        let (points, inbox) = mpsc::channel(QUEUE_POINTS);
        let pipeline = Pipeline {
            job: job.info.id.clone(),
            plan: job.plan.clone(),
            dir: job.dir.clone(),
            gauges: job.gauges.clone(),
            tolerance: job.tolerance(),
            events: self.events.clone(),
            daemon: self.to_self.clone(),
        };
        tokio::spawn(pipeline.run(inbox));
        job.pipeline = Some(points);
    }

    /// Gives every idle machine the remaining scan nearest to it.
    fn dispatch(&mut self) {
        let Some(job) = self.job.as_mut() else {
            return;
        };
        if job.phase != Phase::Scanning {
            return;
        }
        let Some(pipeline) = job.pipeline.clone() else {
            return;
        };
        for slot in &mut self.slots {
            if slot.state != SlotState::Idle || job.remaining.is_empty() {
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
            let order = job.order(key, pipeline.clone());
            if slot.handle.orders.try_send(Order::Scan(order)).is_err() {
                job.remaining.insert(index, key);
                continue;
            }
            slot.state = SlotState::Scanning(key);
            slot.at = Some(job.scan_start(key));
            self.events
                .send(Event::ScanStarted {
                    job: job.info.id.clone(),
                    machine: slot.handle.name.clone(),
                    scan: scan_ref(&job.plan, key),
                    at_unix_ms: super::clock::unix_ms(),
                })
                .ok();
            tracing::info!(job = %job.info.id, machine = %slot.handle.name, scan = %job.plan.describe(key), "scan started");
        }
    }

    fn slot(&mut self, machine: &str) -> Option<&mut Slot> {
        self.slots.iter_mut().find(|s| s.handle.name == machine)
    }

    fn scan_ended(&mut self, machine: &str, key: ProfileKey, result: Result<(), WorkerError>) {
        let failed = result.as_ref().err().map(|e| e.message.clone());
        if let Some(slot) = self.slot(machine) {
            slot.state = match &failed {
                None => SlotState::Idle,
                Some(message) => SlotState::Faulted(message.clone()),
            };
        }
        let Some(job) = self.job.as_mut() else {
            return;
        };
        let Some(message) = failed else {
            return;
        };
        if !job.stored.contains(&key) && !job.remaining.contains(&key) {
            job.remaining.push(key);
        }
        if job.phase == Phase::Scanning {
            let scan = scan_ref(&job.plan, key);
            tracing::error!(job = %job.info.id, machine, scan = %job.plan.describe(key), error = %message, "job stopped");
            let next_step = "remove the cause, then run `zeroset clear`: the job continues from its last complete profile".to_string();
            job.phase = Phase::Stopped {
                machine: Some(machine.to_string()),
                scan: Some(scan.clone()),
                reason: format!(
                    "{} of part {}: {message}",
                    job.plan.describe(key),
                    job.info.part
                ),
                next_step: next_step.clone(),
            };
            let event = Event::JobStopped {
                job: job.info.id.clone(),
                machine: Some(machine.to_string()),
                scan: Some(scan),
                reason: message,
                next_step,
            };
            self.publish(event);
        }
        self.abort_done_if_idle();
    }

    fn stored(&mut self, job_id: &str, key: ProfileKey, result: Result<(), String>) {
        let Some(job) = self.job.as_mut().filter(|j| j.info.id == job_id) else {
            return;
        };
        match result {
            Ok(()) => {
                job.stored.insert(key);
            }
            Err(error) => {
                if !job.remaining.contains(&key) {
                    job.remaining.push(key);
                }
                if job.phase == Phase::Scanning {
                    let next_step =
                        "free space or fix the data folder's permissions, then run `zeroset clear`"
                            .to_string();
                    let reason = format!(
                        "{}: its points could not be stored: {error}",
                        job.plan.describe(key)
                    );
                    job.phase = Phase::Stopped {
                        machine: None,
                        scan: Some(scan_ref(&job.plan, key)),
                        reason: reason.clone(),
                        next_step: next_step.clone(),
                    };
                    let event = Event::JobStopped {
                        job: job_id.to_string(),
                        machine: None,
                        scan: Some(scan_ref(&job.plan, key)),
                        reason,
                        next_step,
                    };
                    self.publish(event);
                }
            }
        }
    }

    /// Starts the fit or the report once every profile is on disk and no machine is still scanning.
    fn finish_if_complete(&mut self) {
        let busy = self
            .slots
            .iter()
            .any(|s| matches!(s.state, SlotState::Scanning(_)));
        let Some(job) = self.job.as_mut() else {
            return;
        };
        if job.phase != Phase::Scanning || busy || job.stored.len() < job.total {
            return;
        }
        job.phase = Phase::Finishing;
        job.pipeline = None;
        let plan = job.plan.clone();
        let dir = job.dir.clone();
        let record = job.record.clone();
        let id = job.info.id.clone();
        let to_self = self.to_self.clone();
        let config = self.config.clone();
        let reference = job.reference.clone();
        let gauges = job.gauges.clone();
        let tolerance = job.tolerance();
        tokio::task::spawn_blocking(move || {
            let path = reference_path(&config, plan.part());
            let result = match (reference, gauges) {
                (Some(reference), Some(gauges)) => finish::write_inspection(&ReportInputs {
                    plan: &plan,
                    dir: &dir,
                    record: &record,
                    reference: &reference,
                    reference_path: &path,
                    gauges: &gauges,
                    tolerance,
                    reports: &config.folders.reports,
                    store: &store_path(&config),
                }),
                _ => finish::fit_reference(&plan, &dir, &path),
            };
            let _ = to_self.blocking_send(DaemonMsg::Finished { job: id, result });
        });
    }

    fn finished(&mut self, job_id: &str, result: Result<Outcome, String>) {
        let Some(job) = self.job.as_mut().filter(|j| j.info.id == job_id) else {
            return;
        };
        let event = match result {
            Ok(Outcome::Taught { path, profiles }) => {
                job.record.state = JobState::Finished;
                job.phase = Phase::Over("finished".into());
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
                job.phase = Phase::Over("finished".into());
                Event::JobFinished {
                    job: job_id.to_string(),
                    report: Some(dir),
                    instances,
                    verdict: Some(verdict),
                }
            }
            Err(error) => {
                job.record.state = JobState::Failed {
                    error: error.clone(),
                };
                job.phase = Phase::Over(format!("failed: {error}"));
                Event::JobFailed {
                    job: job_id.to_string(),
                    error,
                }
            }
        };
        if let Err(error) = job.dir.save_record(&job.record) {
            tracing::error!(job = job_id, %error, "cannot record the job's end");
        }
        tracing::info!(job = job_id, ?event, "job over");
        self.publish(event);
    }

    fn abort(&mut self) -> Reply {
        let Some(job) = self.job.as_mut().filter(|j| !j.is_over()) else {
            return Reply::Error {
                message: "no job to abort".into(),
            };
        };
        if job.phase == Phase::Finishing {
            return Reply::Error {
                message: format!(
                    "job {} has every profile on disk and is being finished; it cannot be aborted now",
                    job.info.id
                ),
            };
        }
        job.phase = Phase::Aborting;
        let id = job.info.id.clone();
        for slot in &self.slots {
            if matches!(slot.state, SlotState::Scanning(_)) {
                let handle = slot.handle.clone();
                tokio::spawn(async move { handle.abort().await });
            }
        }
        self.abort_done_if_idle();
        Reply::Done {
            message: format!(
                "job {id}: motion stopped; the job is aborted (its scans so far stay on disk)"
            ),
        }
    }

    /// Once an aborted job's machines have stopped: the job is over and the machines are cleared (an operator's
    /// abort is no fault to remove).
    fn abort_done_if_idle(&mut self) {
        if self
            .slots
            .iter()
            .any(|s| matches!(s.state, SlotState::Scanning(_)))
        {
            return;
        }
        let Some(job) = self.job.as_mut().filter(|j| j.phase == Phase::Aborting) else {
            return;
        };
        job.record.state = JobState::Aborted;
        job.phase = Phase::Over("aborted".into());
        if let Err(error) = job.dir.save_record(&job.record) {
            tracing::error!(job = %job.info.id, %error, "cannot record the abort");
        }
        let id = job.info.id.clone();
        self.publish(Event::JobAborted { job: id });
        self.clear_machines();
    }

    fn clear(&mut self, reply: oneshot::Sender<Reply>) {
        if self.clearing.is_some() || self.slots.iter().any(|s| s.state == SlotState::Clearing) {
            let _ = reply.send(Reply::Error {
                message: "a clear is already in progress".into(),
            });
            return;
        }
        if let Some(job) = self.job.as_ref() {
            if matches!(
                job.phase,
                Phase::Scanning | Phase::Finishing | Phase::Aborting
            ) {
                let _ = reply.send(Reply::Error {
                    message: format!(
                        "job {} is {}: nothing to clear",
                        job.info.id,
                        phase_name(&job.phase)
                    ),
                });
                return;
            }
        }
        self.clearing = Some(reply);
        self.clear_machines();
        self.resume_if_clear();
    }

    /// Asks every machine that is not scanning to clear its errors and leave the part, with the path of a scan a
    /// killed daemon cut short when the machine has none of its own.
    fn clear_machines(&mut self) {
        let cut_paths: Vec<(String, super::KnownPath, f64)> = self
            .job
            .as_ref()
            .filter(|j| !j.is_over())
            .map(|job| {
                job.cut_scans()
                    .into_iter()
                    .filter_map(|key| job.cut_scan_path(key))
                    .map(|(machine, path)| (machine, path, job.margin_mm()))
                    .collect()
            })
            .unwrap_or_default();
        for slot in &mut self.slots {
            if matches!(slot.state, SlotState::Scanning(_) | SlotState::Clearing) {
                continue;
            }
            let path = cut_paths
                .iter()
                .find(|(machine, _, _)| *machine == slot.handle.name)
                .map(|(_, path, margin)| (path.clone(), *margin));
            let (reply, answer) = oneshot::channel();
            if slot
                .handle
                .orders
                .try_send(Order::Clear { path, reply })
                .is_err()
            {
                continue;
            }
            slot.state = SlotState::Clearing;
            let machine = slot.handle.name.clone();
            let to_self = self.to_self.clone();
            tokio::spawn(async move {
                let result = answer
                    .await
                    .unwrap_or_else(|_| Err(format!("machine {machine}: its worker stopped")));
                let _ = to_self.send(DaemonMsg::Cleared { machine, result }).await;
            });
        }
    }

    fn cleared(&mut self, machine: &str, result: Result<(), String>) {
        if let Some(slot) = self.slot(machine) {
            slot.state = match &result {
                Ok(()) => SlotState::Idle,
                Err(message) => SlotState::Faulted(message.clone()),
            };
        }
        if let Err(message) = &result {
            tracing::error!(machine, error = %message, "clear failed");
        }
        self.resume_if_clear();
    }

    /// When no machine is clearing any more: answer the operator, and resume a stopped job if all went well.
    fn resume_if_clear(&mut self) {
        if self.slots.iter().any(|s| s.state == SlotState::Clearing) {
            return;
        }
        let faults: Vec<String> = self
            .slots
            .iter()
            .filter_map(|s| match &s.state {
                SlotState::Faulted(message) => Some(message.clone()),
                _ => None,
            })
            .collect();
        let Some(reply) = self.clearing.take() else {
            return;
        };
        if !faults.is_empty() {
            let _ = reply.send(Reply::Error {
                message: format!("not cleared: {}", faults.join("; ")),
            });
            return;
        }
        let resumed = match self.job.as_mut() {
            Some(job) if matches!(job.phase, Phase::Stopped { .. }) => {
                job.phase = Phase::Scanning;
                Some((job.info.clone(), job.done_refs()))
            }
            _ => None,
        };
        let message = match resumed {
            Some((info, done)) => {
                self.start_pipeline();
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
        let _ = reply.send(Reply::Done { message });
    }

    fn status(&self) -> StationStatus {
        let machines = self
            .slots
            .iter()
            .map(|slot| MachineStatus {
                name: slot.handle.name.clone(),
                state: match (&slot.state, &self.job) {
                    (SlotState::Idle, _) => "idle".into(),
                    (SlotState::Scanning(key), Some(job)) => {
                        format!("scanning {}", job.plan.describe(*key))
                    }
                    (SlotState::Scanning(_), None) => "scanning".into(),
                    (SlotState::Faulted(message), _) => format!("stopped: {message}"),
                    (SlotState::Clearing, _) => "clearing".into(),
                },
            })
            .collect();
        let job = self.job.as_ref().map(|job| JobStatus {
            job: job.info.clone(),
            state: phase_name(&job.phase),
            stopped: match &job.phase {
                Phase::Stopped {
                    reason, next_step, ..
                } => Some(format!("{reason}; {next_step}")),
                _ => None,
            },
            profiles_done: job.stored.len(),
            profiles_total: job.total,
        });
        StationStatus {
            station: self.config.name.clone(),
            machines,
            job,
        }
    }
}

fn phase_name(phase: &Phase) -> String {
    match phase {
        Phase::Scanning => "running".into(),
        Phase::Stopped { .. } => "stopped".into(),
        Phase::Aborting => "aborting".into(),
        Phase::Finishing => "finishing".into(),
        Phase::Over(how) => how.clone(),
    }
}

/// The inspection history's database file.
fn store_path(config: &StationConfig) -> PathBuf {
    config.folders.data.join(crate::report::STORE_FILE)
}

/// The newest report of a serial number, as the operator reads it.
fn report(config: &StationConfig, serial: &str) -> Reply {
    let found = crate::report::Store::open(&store_path(config))
        .and_then(|store| store.latest_report(serial))
        .map_err(|e| e.to_string())
        .and_then(|dir| {
            dir.ok_or_else(|| {
                format!(
                    "no inspection of serial {serial} in the history; inspect it with `zeroset inspect PART --serial {serial}`"
                )
            })
        });
    let read = found.and_then(|dir| {
        crate::report::read_report(&dir)
            .map(|report| (dir, report))
            .map_err(|e| e.to_string())
    });
    match read {
        Ok((dir, report)) => Reply::Report {
            summary: crate::report::summary_text(&report),
            dir,
        },
        Err(message) => Reply::Error { message },
    }
}
