//! A job's analysis, off the machine workers: every point a worker forwards is written to its profile's partial
//! file, compensated for the probe ball, measured against the reference (when inspecting) and published at once;
//! when a profile's scan ends its points are written as a complete scan file and only then does the profile count
//! as done. The queue from the workers is bounded, so a stalled disk slows scanning down rather than losing points.

use std::collections::HashMap;
use std::sync::Arc;

use nalgebra::{Isometry3, Point3};
use tokio::sync::{broadcast, mpsc};

use super::clock;
use super::journal::{JobDir, PartialScan, ScanFile, ScanHeader};
use super::DaemonMsg;
use crate::analysis::deviation::{ProfileGauge, ScanGauge};
use crate::analysis::stats::{RunningStats, Tolerance};
use crate::analysis::{surface_point, RawPoint};
use crate::api::{Event, ScanRef};
use crate::plan::{Plan, ProfileKey};

/// Points in flight between the workers and the analysis: about a minute of scanning at 20 points a second per
/// machine, far more than analysis ever falls behind.
pub const QUEUE_POINTS: usize = 4096;

/// What a worker tells the pipeline, in order, for each scan.
#[derive(Debug)]
pub enum PipelineMsg {
    Start {
        key: ProfileKey,
        machine: String,
        ball_radius_mm: f64,
    },
    Point {
        key: ProfileKey,
        raw: RawPoint,
        received_us: u64,
    },
    /// The scan completed.
    End { key: ProfileKey },
    /// The scan was cut short; its partial file stays for the record and for the way out after a restart.
    Cut { key: ProfileKey },
}

/// The analysis of one job.
pub struct Pipeline {
    pub job: String,
    pub plan: Arc<Plan>,
    pub dir: JobDir,
    /// One gauge per profile when inspecting; none when teaching.
    pub gauges: Option<Arc<Vec<ProfileGauge>>>,
    pub tolerance: Tolerance,
    pub events: broadcast::Sender<Event>,
    pub daemon: mpsc::Sender<DaemonMsg>,
}

/// A profile being scanned.
struct Active<'g> {
    header: ScanHeader,
    partial: PartialScan,
    points: Vec<RawPoint>,
    machine_to_part: Isometry3<f64>,
    gauge: Option<ScanGauge<'g>>,
    stats: RunningStats,
    outside: usize,
}

impl Pipeline {
    pub async fn run(self, mut inbox: mpsc::Receiver<PipelineMsg>) {
        let gauges = self.gauges.clone();
        let mut active: HashMap<ProfileKey, Active<'_>> = HashMap::new();
        while let Some(message) = inbox.recv().await {
            match message {
                PipelineMsg::Start {
                    key,
                    machine,
                    ball_radius_mm,
                } => {
                    let header = ScanHeader {
                        machine,
                        ball_radius_mm,
                        started: clock::now_rfc3339(),
                    };
                    match self.dir.start_partial(&self.scan_ref(key), &header) {
                        Ok(partial) => {
                            let gauge = gauges.as_deref().map(|g| g[key.profile].scan());
                            active.insert(
                                key,
                                Active {
                                    header,
                                    partial,
                                    points: Vec::new(),
                                    machine_to_part: self
                                        .plan
                                        .instance_to_machine(key.instance)
                                        .inverse(),
                                    gauge,
                                    stats: RunningStats::default(),
                                    outside: 0,
                                },
                            );
                        }
                        Err(error) => self.failed(key, error.to_string()).await,
                    }
                }
                PipelineMsg::Point {
                    key,
                    raw,
                    received_us,
                } => {
                    let Some(profile) = active.get_mut(&key) else {
                        continue;
                    };
                    // Published first, written right after: the write costs a system call that the watchers
                    // need not wait for, and the point is in memory for the complete scan file either way.
                    let event = self.measure(key, profile, raw, received_us);
                    let _ = self.events.send(event);
                    if let Err(error) = profile.partial.push(&raw) {
                        active.remove(&key);
                        self.failed(key, error.to_string()).await;
                        continue;
                    }
                }
                PipelineMsg::End { key } => {
                    if let Some(profile) = active.remove(&key) {
                        self.complete(key, profile);
                    }
                }
                PipelineMsg::Cut { key } => {
                    active.remove(&key);
                }
            }
        }
    }

    /// Compensates, measures and records one point; returns its event.
    fn measure(
        &self,
        key: ProfileKey,
        profile: &mut Active<'_>,
        raw: RawPoint,
        received_us: u64,
    ) -> Event {
        let index = profile.points.len();
        profile.points.push(raw);
        let surface = surface_point(&raw, profile.header.ball_radius_mm);
        let deviation = profile.gauge.as_mut().and_then(|gauge| {
            let in_part = profile.machine_to_part * surface;
            match gauge.measure(&in_part) {
                Ok(measured) => Some(measured.deviation_mm),
                Err(error) => {
                    tracing::warn!(job = %self.job, scan = %self.plan.describe(key), index, %error, "no deviation for a point");
                    None
                }
            }
        });
        if let Some(d) = deviation {
            profile.stats.push(d, surface.coords.into());
            if !self.tolerance.contains(d) {
                profile.outside += 1;
            }
        }
        Event::Point {
            job: self.job.clone(),
            machine: profile.header.machine.clone(),
            scan: self.scan_ref(key),
            index,
            surface_mm: surface.coords.into(),
            deviation_mm: deviation,
            received_unix_us: received_us,
        }
    }

    /// Writes the complete scan, then the profile counts as done. The write (flushed to the disk) runs on a
    /// blocking thread of its own, so the next profile's points are measured and published meanwhile.
    fn complete(&self, key: ProfileKey, profile: Active<'_>) {
        let file = ScanFile {
            header: profile.header.clone(),
            finished: clock::now_rfc3339(),
            points: profile.points,
        };
        let stats = profile.stats.summary();
        let verdict = stats.map(|s| self.tolerance.verdict(&s, profile.outside));
        let (machine, points) = (profile.header.machine, file.points.len());
        let (dir, scan, job) = (self.dir.clone(), self.scan_ref(key), self.job.clone());
        let (events, daemon) = (self.events.clone(), self.daemon.clone());
        tokio::spawn(async move {
            let written = {
                let scan = scan.clone();
                tokio::task::spawn_blocking(move || dir.write_scan(&scan, &file)).await
            };
            let result = match written {
                Ok(Ok(())) => {
                    let _ = events.send(Event::ProfileDone {
                        job: job.clone(),
                        machine,
                        scan,
                        points,
                        stats,
                        verdict,
                        at_unix_ms: clock::unix_ms(),
                    });
                    Ok(())
                }
                Ok(Err(error)) => Err(error.to_string()),
                Err(panic) => Err(format!("writing the scan failed: {panic}")),
            };
            let _ = daemon.send(DaemonMsg::Stored { job, key, result }).await;
        });
    }

    async fn failed(&self, key: ProfileKey, error: String) {
        let _ = self
            .daemon
            .send(DaemonMsg::Stored {
                job: self.job.clone(),
                key,
                result: Err(error),
            })
            .await;
    }

    fn scan_ref(&self, key: ProfileKey) -> ScanRef {
        scan_ref(&self.plan, key)
    }
}

/// A profile of an instance by its names.
pub fn scan_ref(plan: &Plan, key: ProfileKey) -> ScanRef {
    ScanRef {
        instance: plan.instance_names()[key.instance].clone(),
        profile: plan.profile_names()[key.profile].to_string(),
    }
}

/// The surface point of a raw point in the master's part frame.
pub fn in_part_frame(
    plan: &Plan,
    key: ProfileKey,
    raw: &RawPoint,
    ball_radius_mm: f64,
) -> Point3<f64> {
    plan.instance_to_machine(key.instance).inverse() * surface_point(raw, ball_radius_mm)
}
