//! The daemon's shell around its decisions (`core`): it turns messages from the control socket, the workers,
//! the pipeline and its own blocking tasks into the core's inputs, and carries out the effects the core returns.
//! Nothing here blocks: loading and checking a job, saving records, finishing a job and reading a report run on
//! blocking threads and come back as messages.

use std::collections::{HashMap, VecDeque};
use std::path::PathBuf;
use std::sync::Arc;

use tokio::sync::{broadcast, mpsc, oneshot};

use super::core::{Core, Effect, Input, RequestId};
use super::finish::{self, Outcome, ReportInputs};
use super::job::{prepare, reference_path, Job};
use super::journal::{open_jobs, JobDir, JobRecord};
use super::pipeline::{Pipeline, PipelineMsg, QUEUE_POINTS};
use super::worker::{Order, WorkerError, WorkerHandle};
use super::DaemonMsg;
use crate::api::{Event, FaultKind, JobKind, Reply};
use crate::config::StationConfig;

/// How long a resumed job waits for the analysis from before its stop to store what it was given: a healthy
/// disk takes milliseconds, a stalled one is a fault worth stopping for.
const EARLIER_ANALYSIS_LIMIT: std::time::Duration = std::time::Duration::from_secs(30);

pub struct Daemon {
    config: Arc<StationConfig>,
    core: Core,
    workers: HashMap<String, WorkerHandle>,
    events: broadcast::Sender<Event>,
    to_self: mpsc::Sender<DaemonMsg>,
    replies: HashMap<RequestId, oneshot::Sender<Reply>>,
    next_request: RequestId,
    /// The current job's analysis, while its machines scan.
    pipeline: Option<mpsc::Sender<PipelineMsg>>,
    /// The task of the analysis started last: it may still be storing scans after its queue was let go.
    analysis: Option<tokio::task::JoinHandle<Result<(), String>>>,
    /// Job records go to disk in the order they were decided, on one thread of their own.
    records: std::sync::mpsc::Sender<(JobDir, JobRecord)>,
}

impl Daemon {
    /// The daemon, with the newest job a previous daemon left open, stopped until `zeroset clear`.
    pub async fn start(
        config: StationConfig,
        workers: Vec<WorkerHandle>,
        events: broadcast::Sender<Event>,
        to_self: mpsc::Sender<DaemonMsg>,
    ) -> anyhow::Result<Daemon> {
        let config = Arc::new(config);
        let reopened = {
            let config = config.clone();
            tokio::task::spawn_blocking(move || reopen(&config))
                .await
                .map_err(|e| anyhow::anyhow!("reopening the job left open failed: {e}"))??
        };
        let core = Core::new(
            config.name.clone(),
            workers.iter().map(|w| w.name.clone()).collect(),
            reopened,
        );
        let (records, inbox) = std::sync::mpsc::channel::<(JobDir, JobRecord)>();
        std::thread::Builder::new()
            .name("job records".into())
            .spawn(move || {
                for (dir, record) in inbox {
                    if let Err(error) = dir.save_record(&record) {
                        tracing::error!(job = %record.id, %error, "cannot record the job's state");
                    }
                }
            })?;
        Ok(Daemon {
            config,
            core,
            workers: workers.into_iter().map(|w| (w.name.clone(), w)).collect(),
            events,
            to_self,
            replies: HashMap::new(),
            next_request: 0,
            pipeline: None,
            analysis: None,
            records,
        })
    }

    pub async fn run(mut self, mut inbox: mpsc::Receiver<DaemonMsg>) {
        while let Some(message) = inbox.recv().await {
            let input = self.input(message);
            self.handle(input);
        }
    }

    fn input(&mut self, message: DaemonMsg) -> Input {
        match message {
            DaemonMsg::Request { request, reply } => {
                let id = self.next_request;
                self.next_request += 1;
                self.replies.insert(id, reply);
                Input::Request { id, request }
            }
            DaemonMsg::Input(input) => input,
        }
    }

    /// Hands `input` to the core and carries out its effects; an effect that cannot be carried out comes back to
    /// the core as the input it stands for (a scan order no worker took is a failed scan).
    fn handle(&mut self, input: Input) {
        let mut inputs = VecDeque::from([input]);
        while let Some(input) = inputs.pop_front() {
            for effect in self.core.handle(input) {
                if let Some(back) = self.effect(effect) {
                    inputs.push_back(back);
                }
            }
        }
    }

    fn effect(&mut self, effect: Effect) -> Option<Input> {
        match effect {
            Effect::Reply { id, reply } => {
                if let Some(sender) = self.replies.remove(&id) {
                    let _ = sender.send(reply);
                }
            }
            Effect::Publish(event) => {
                let _ = self.events.send(event);
            }
            Effect::Prepare {
                id,
                kind,
                part,
                serial,
            } => {
                let config = self.config.clone();
                self.blocking(move || {
                    let result = prepare(&config, kind, &part, serial).map(Box::new);
                    Input::Prepared { id, result }
                }, move |panic| Input::Prepared {
                    id,
                    result: Err(super::job::JobError(format!(
                        "setting up the job failed inside the station ({panic}); this is a bug: report it with the daemon's log"
                    ))),
                });
            }
            Effect::StartPipeline => self.start_pipeline(),
            Effect::StopPipeline => self.pipeline = None,
            Effect::Scan {
                machine,
                motion,
                part,
            } => {
                let key = motion.key;
                let Some(pipeline) = self.pipeline.clone() else {
                    return Some(station_fault(
                        machine,
                        key,
                        "the job has no analysis running",
                    ));
                };
                let given = self.workers.get(&machine).is_some_and(|worker| {
                    worker
                        .orders
                        .try_send(Order::Scan {
                            motion,
                            part,
                            pipeline,
                        })
                        .is_ok()
                });
                if !given {
                    return Some(station_fault(
                        machine,
                        key,
                        "its worker does not take orders",
                    ));
                }
            }
            Effect::Abort { machine } => {
                if let Some(worker) = self.workers.get(&machine).cloned() {
                    tokio::spawn(async move { worker.abort().await });
                }
            }
            Effect::Clear { machine, escape } => {
                let (reply, answer) = oneshot::channel();
                let given = self.workers.get(&machine).is_some_and(|worker| {
                    worker
                        .orders
                        .try_send(Order::Clear { escape, reply })
                        .is_ok()
                });
                if !given {
                    return Some(Input::Cleared {
                        result: Err(worker_gone(&machine)),
                        machine,
                    });
                }
                let to_self = self.to_self.clone();
                tokio::spawn(async move {
                    let result = answer.await.unwrap_or_else(|_| Err(worker_gone(&machine)));
                    let _ = to_self
                        .send(DaemonMsg::Input(Input::Cleared { machine, result }))
                        .await;
                });
            }
            Effect::SaveRecord { dir, record } => {
                if self.records.send((dir, record)).is_err() {
                    tracing::error!("the job records' thread stopped; a job's state was not saved");
                }
            }
            Effect::Finish => self.finish(),
            Effect::ReadReport { id, serial } => {
                if let Some(reply) = self.replies.remove(&id) {
                    let config = self.config.clone();
                    tokio::spawn(async move {
                        let answer = tokio::task::spawn_blocking(move || report(&config, &serial))
                            .await
                            .unwrap_or_else(|panic| Reply::Error {
                                message: format!("reading the report failed inside the station ({panic}); this is a bug"),
                            });
                        let _ = reply.send(answer);
                    });
                }
            }
        }
        None
    }

    /// Runs `work` on a blocking thread and sends its message back; a panic there becomes `on_panic`'s message,
    /// so a job never waits for an answer that cannot come.
    fn blocking(
        &self,
        work: impl FnOnce() -> Input + Send + 'static,
        on_panic: impl FnOnce(String) -> Input + Send + 'static,
    ) {
        let to_self = self.to_self.clone();
        tokio::spawn(async move {
            let message = tokio::task::spawn_blocking(work)
                .await
                .unwrap_or_else(|panic| on_panic(panic.to_string()));
            let _ = to_self.send(DaemonMsg::Input(message)).await;
        });
    }

    /// A fresh pipeline for the job (at its start, and when it resumes: a stopped job's scans were cut).
    fn start_pipeline(&mut self) {
        let Some(job) = self.core.job() else {
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
        // The earlier analysis ends once its last worker lets go of its queue (at a resume every machine has
        // been cleared, so none still scans into it) and its recorder has written what it was given.
        self.pipeline = Some(points);
        let earlier = self.analysis.replace(tokio::spawn(pipeline.run(inbox)));
        let (to_self, job) = (self.to_self.clone(), job.info.id.clone());
        tokio::spawn(async move {
            let result = match earlier {
                None => Ok(()),
                Some(task) => match tokio::time::timeout(EARLIER_ANALYSIS_LIMIT, task).await {
                    Ok(Ok(ended)) => ended,
                    Ok(Err(panic)) => Err(format!(
                        "it failed ({panic}); this is a bug: report it with the daemon's log"
                    )),
                    Err(_) => Err(format!(
                        "it was still storing scans after {} s",
                        EARLIER_ANALYSIS_LIMIT.as_secs()
                    )),
                },
            };
            let _ = to_self
                .send(DaemonMsg::Input(Input::EarlierAnalysisEnded {
                    job,
                    result,
                }))
                .await;
        });
    }

    /// Fits the reference or writes the report off the decision task, from the scans on disk.
    fn finish(&self) {
        let Some(job) = self.core.job() else {
            return;
        };
        let plan = job.plan.clone();
        let dir = job.dir.clone();
        let record = job.record.clone();
        let id = job.info.id.clone();
        let config = self.config.clone();
        let reference = job.reference.clone();
        let gauges = job.gauges.clone();
        let tolerance = job.tolerance();
        let kind = job.info.kind;
        let panic_id = id.clone();
        self.blocking(move || {
            let path = reference_path(&config, plan.part());
            let result = match (kind, reference, gauges) {
                (JobKind::Inspect, Some(reference), Some(gauges)) => finish::write_inspection(&ReportInputs {
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
            Input::Finished { job: id, result }
        }, move |panic| Input::Finished {
            job: panic_id,
            result: Err::<Outcome, _>(format!(
                "finishing the job failed inside the station ({panic}); its scans are on disk; this is a bug: report it with the daemon's log"
            )),
        });
    }
}

/// The newest job a previous daemon left open, if it can be reopened.
fn reopen(config: &StationConfig) -> anyhow::Result<Option<Job>> {
    let mut open = open_jobs(&config.folders.data)?;
    let Some((dir, record)) = open.pop() else {
        return Ok(None);
    };
    let id = record.id.clone();
    match Job::reopen(config, dir, record) {
        Ok(job) => {
            tracing::info!(job = %id, done = job.stored.len(), total = job.total, "reopened a job left open");
            Ok(Some(job))
        }
        Err(error) => {
            tracing::error!(job = %id, %error, "cannot reopen a job left open");
            Ok(None)
        }
    }
}

fn worker_gone(machine: &str) -> WorkerError {
    WorkerError {
        kind: FaultKind::Station,
        message: format!("machine {machine}: its worker stopped; restart the daemon"),
    }
}

fn station_fault(machine: String, key: crate::plan::ProfileKey, why: &str) -> Input {
    Input::ScanEnded {
        result: Err(WorkerError {
            kind: FaultKind::Station,
            message: format!("machine {machine}: the scan was not started: {why}"),
        }),
        machine,
        key,
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
