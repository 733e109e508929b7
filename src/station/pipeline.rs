//! A job's analysis, off the machine workers: every point a worker forwards is compensated for the probe ball,
//! measured against the reference (when inspecting), published at once, and handed to the job's recorder, which
//! writes it to disk on its own thread; when a profile's scan ends the recorder writes its scan file, and only then
//! does the profile count as done. The queue from the workers is bounded, so analysis that falls behind slows
//! scanning down rather than losing points.

use std::collections::HashMap;
use std::sync::Arc;

use nalgebra::{Isometry3, Point3};
use tokio::sync::{broadcast, mpsc};

use super::clock;
use super::journal::{JobDir, ScanHeader};
use super::recorder::{Record, Recorder};
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
        /// Where on the surface the scan begins, machine coordinates: the gauge finds the model's nearest point
        /// there while the machine approaches, so the first point is measured as fast as the rest.
        entry: Point3<f64>,
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
    points: Vec<RawPoint>,
    machine_to_part: Isometry3<f64>,
    gauge: Option<ScanGauge<'g>>,
    stats: RunningStats,
    outside: usize,
}

impl Pipeline {
    pub async fn run(self, mut inbox: mpsc::Receiver<PipelineMsg>) {
        let recorder = Recorder {
            job: self.job.clone(),
            dir: self.dir.clone(),
            events: self.events.clone(),
            daemon: self.daemon.clone(),
        }
        .spawn();
        let gauges = self.gauges.clone();
        let mut active: HashMap<ProfileKey, Active<'_>> = HashMap::new();
        while let Some(message) = inbox.recv().await {
            // The recorder lives as long as this task; a send fails only if its thread panicked, which the
            // daemon learns from the profiles that never count as done.
            match message {
                PipelineMsg::Start {
                    key,
                    machine,
                    ball_radius_mm,
                    entry,
                } => {
                    let header = ScanHeader {
                        machine,
                        ball_radius_mm,
                        started: clock::now_rfc3339(),
                    };
                    let scan = self.scan_ref(key);
                    let _ = recorder.send(Record::Start {
                        key,
                        scan,
                        header: header.clone(),
                    });
                    let machine_to_part = self.plan.instance_to_machine(key.instance).inverse();
                    let mut gauge = gauges.as_deref().map(|g| g[key.profile].scan());
                    if let Some(gauge) = gauge.as_mut() {
                        // Without a neighbour's foot to start from, a point needs the gauge's full search.
                        let _ = gauge.measure(&(machine_to_part * entry));
                    }
                    active.insert(
                        key,
                        Active {
                            header,
                            points: Vec::new(),
                            machine_to_part,
                            gauge,
                            stats: RunningStats::default(),
                            outside: 0,
                        },
                    );
                }
                PipelineMsg::Point {
                    key,
                    raw,
                    received_us,
                } => {
                    let Some(profile) = active.get_mut(&key) else {
                        continue;
                    };
                    let event = self.measure(key, profile, raw, received_us);
                    let _ = self.events.send(event);
                    let _ = recorder.send(Record::Point { key, raw });
                }
                PipelineMsg::End { key } => {
                    if let Some(profile) = active.remove(&key) {
                        let stats = profile.stats.summary();
                        let _ = recorder.send(Record::End {
                            key,
                            points: profile.points,
                            verdict: stats.map(|s| self.tolerance.verdict(&s, profile.outside)),
                            stats,
                        });
                    }
                }
                PipelineMsg::Cut { key } => {
                    active.remove(&key);
                    let _ = recorder.send(Record::Cut { key });
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
