//! A job's analysis, off the machine workers: every point a worker forwards is handed at once to the job's
//! recorder, which writes it to disk on its own thread; it is compensated for the probe ball from the path of ball
//! centres around it (`geometry::sweep::compensation`: a point is compensated once the four points after it have
//! arrived, the last four when the scan ends), measured against the reference (when inspecting) and published.
//! Until then each point is published at once as a preview, from the path up to it, so the live deviation does
//! not wait for the machine's next line of points.
//! When a profile's scan ends the recorder writes its scan file, and only then does the profile count as done;
//! meanwhile an inspected section is evaluated (best fits, parameters) on a blocking thread and published.
//! Points whose contact compensation flags (a cusp: the surface more concave than the ball) are published and
//! recorded but left out of the profile's statistics and verdict, and counted in the log. The queue from the
//! workers is bounded, so analysis that falls behind slows scanning down rather than losing points; so is the
//! recorder's, which the analysis waits on, so a disk that falls behind slows scanning down the same way.

use std::collections::{HashMap, VecDeque};
use std::sync::Arc;

use nalgebra::{Isometry3, Point3, Vector3};
use tokio::sync::{broadcast, mpsc};

use super::clock;
use super::journal::{JobDir, ScanHeader};
use super::recorder::{Record, Recorder};
use super::DaemonMsg;
use crate::analysis::deviation::{ProfileGauge, ScanGauge};
use crate::analysis::section::{self, ScannedSection};
use crate::analysis::stats::{RunningStats, Tolerance};
use crate::analysis::RawPoint;
use crate::api::{Event, ScanRef};
use crate::geometry::sweep::compensation::{Compensated, CompensationSettings, Compensator};
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
    compensator: Compensator,
    /// When each point not yet compensated arrived, in scan order.
    waiting: VecDeque<u64>,
    stats: RunningStats,
    outside: usize,
    /// Points kept but left out of the statistics: compensation flagged their contact.
    flagged: usize,
    /// The compensated points not flagged, part frame, in scan order: the section evaluated at the scan's end
    /// (inspect only; a teach scan keeps none).
    in_part: ScannedSection,
}

impl Pipeline {
    /// Analyses until every sender of `inbox` is gone, and returns once the recorder has written all it was
    /// given (an error if its thread panicked).
    pub async fn run(self, inbox: mpsc::Receiver<PipelineMsg>) -> Result<(), String> {
        let (recorder, thread) = Recorder {
            job: self.job.clone(),
            dir: self.dir.clone(),
            events: self.events.clone(),
            daemon: self.daemon.clone(),
        }
        .spawn();
        self.analyse(inbox, recorder).await;
        tokio::task::spawn_blocking(move || thread.join())
            .await
            .map_err(|e| e.to_string())?
            .map_err(|_| "its recorder failed (a bug: report it with the daemon's log)".to_string())
    }

    /// The analysis itself, writing through `recorder`.
    async fn analyse(self, mut inbox: mpsc::Receiver<PipelineMsg>, recorder: mpsc::Sender<Record>) {
        let gauges = self.gauges.clone();
        let mut active: HashMap<ProfileKey, Active<'_>> = HashMap::new();
        while let Some(message) = inbox.recv().await {
            // The recorder lives as long as this task; a send fails only if its thread panicked, which the
            // daemon learns from the profiles that never count as done. A send waits while the recorder's queue
            // is full: the disk's back-pressure reaches the workers through this task's own bounded queue.
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
                    let _ = recorder
                        .send(Record::Start {
                            key,
                            scan,
                            header: header.clone(),
                        })
                        .await;
                    let machine_to_part = self.plan.instance_to_machine(key.instance).inverse();
                    let compensator = Compensator::new(
                        CompensationSettings::new(ball_radius_mm),
                        self.plan.plane_normal(key.instance),
                    );
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
                            compensator,
                            waiting: VecDeque::new(),
                            stats: RunningStats::default(),
                            outside: 0,
                            flagged: 0,
                            in_part: ScannedSection::default(),
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
                    profile.points.push(raw);
                    profile.waiting.push_back(received_us);
                    let _ = recorder.send(Record::Point { key, raw }).await;
                    let centre = Point3::from(raw.centre);
                    // The newest point's preview first: a roll's first points may come out of the compensator
                    // together once the roll shows its edge, and the live deviation must not wait for them.
                    let released = profile.compensator.push(centre, Vector3::from(raw.normal));
                    if let Some(preview) = profile.compensator.preview() {
                        self.publish_preview(key, profile, preview, received_us);
                    }
                    for point in released {
                        self.publish(key, profile, point);
                    }
                }
                PipelineMsg::End { key } => {
                    if let Some(mut profile) = active.remove(&key) {
                        self.publish_rest(key, &mut profile);
                        self.evaluate_section(key, &mut profile);
                        let stats = profile.stats.summary();
                        let _ = recorder
                            .send(Record::End {
                                key,
                                points: profile.points,
                                verdict: stats.map(|s| self.tolerance.verdict(&s, profile.outside)),
                                stats,
                            })
                            .await;
                    }
                }
                PipelineMsg::Cut { key } => {
                    // The points measured before the cut are published too (from the reported normals at the
                    // path's new end): they are in the partial file.
                    if let Some(mut profile) = active.remove(&key) {
                        self.publish_rest(key, &mut profile);
                    }
                    let _ = recorder.send(Record::Cut { key }).await;
                }
            }
        }
    }

    /// Publishes the points still waiting for their look-ahead when a scan ends, and logs the flagged ones.
    fn publish_rest(&self, key: ProfileKey, profile: &mut Active<'_>) {
        for point in profile.compensator.finish() {
            self.publish(key, profile, point);
        }
        if profile.flagged > 0 {
            tracing::warn!(
                job = %self.job,
                scan = %self.plan.describe(key),
                flagged = profile.flagged,
                points = profile.points.len(),
                "points kept but left out of the statistics: their contact is not unique (the surface is more concave than the ball there, or the ball's path is tighter than the ball)"
            );
        }
    }

    /// Evaluates the section of a completed inspect scan on a blocking thread (its best fits and parameters take
    /// tens of milliseconds, which the next profile's live points must not wait for) and publishes it. A profile's
    /// nominal parameters are worked out once per job, by its gauge.
    fn evaluate_section(&self, key: ProfileKey, profile: &mut Active<'_>) {
        let Some(gauges) = self.gauges.clone() else {
            return;
        };
        let in_part = std::mem::take(&mut profile.in_part);
        let events = self.events.clone();
        let (job, machine, scan) = (
            self.job.clone(),
            profile.header.machine.clone(),
            self.scan_ref(key),
        );
        let radius = self.plan.profile_radius(key.profile);
        let tolerances = self.plan.tolerance().parameter_tolerances();
        let fit_settings = *self.plan.best_fit();
        let described = self.plan.describe(key);
        tokio::task::spawn_blocking(move || {
            let gauge = &gauges[key.profile];
            let best_fits = section::best_fits(gauge, &in_part.points, &fit_settings)
                .map(|f| f.fits)
                .unwrap_or_else(|problem| {
                    tracing::warn!(scan = %described, %problem, "live: no best fit of the section");
                    Vec::new()
                });
            let parameters = gauge
                .nominal_parameters()
                .map_err(str::to_string)
                .and_then(|nominal| section::parameters(nominal, &in_part, radius))
                .map(|shape| shape.parameters)
                .map(|mut parameters| {
                    tolerances.judge_section(&mut parameters);
                    parameters
                })
                .map_err(|problem| {
                    tracing::warn!(scan = %described, %problem, "live: no parameters of the section");
                })
                .ok();
            let _ = events.send(Event::SectionEvaluated {
                job,
                machine,
                scan,
                best_fits,
                parameters: parameters.map(Box::new),
                at_unix_ms: clock::unix_ms(),
            });
        });
    }

    /// Measures a compensated point and publishes its event.
    fn publish(&self, key: ProfileKey, profile: &mut Active<'_>, point: Compensated) {
        let received_us = profile.waiting.pop_front().unwrap_or_default();
        let event = self.measure(key, profile, point, received_us);
        let _ = self.events.send(event);
    }

    /// Measures the newest point's provisional compensation and publishes it as a preview: nothing is counted.
    fn publish_preview(
        &self,
        key: ProfileKey,
        profile: &mut Active<'_>,
        preview: Compensated,
        received_us: u64,
    ) {
        let deviation = self.deviation(key, profile, &preview);
        let _ = self.events.send(Event::PointPreview {
            job: self.job.clone(),
            machine: profile.header.machine.clone(),
            scan: self.scan_ref(key),
            index: preview.index,
            surface_mm: preview.surface.coords.into(),
            deviation_mm: deviation,
            flagged: preview.is_flagged(),
            received_unix_us: received_us,
        });
    }

    /// A compensated point's deviation from the reference; `None` when teaching or when it has no foot (logged).
    fn deviation(
        &self,
        key: ProfileKey,
        profile: &mut Active<'_>,
        point: &Compensated,
    ) -> Option<f64> {
        let gauge = profile.gauge.as_mut()?;
        match gauge.measure(&(profile.machine_to_part * point.surface)) {
            Ok(measured) => Some(measured.deviation_mm),
            Err(error) => {
                tracing::warn!(job = %self.job, scan = %self.plan.describe(key), index = point.index, %error, "no deviation for a point");
                None
            }
        }
    }

    /// Measures one compensated point; returns its event.
    fn measure(
        &self,
        key: ProfileKey,
        profile: &mut Active<'_>,
        point: Compensated,
        received_us: u64,
    ) -> Event {
        let index = point.index;
        let surface = point.surface;
        let deviation = self.deviation(key, profile, &point);
        if point.is_flagged() {
            profile.flagged += 1;
        } else if profile.gauge.is_some() {
            profile.in_part.push(&point, &profile.machine_to_part);
        }
        if let (Some(d), false) = (deviation, point.is_flagged()) {
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
            flagged: point.is_flagged(),
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

#[cfg(test)]
mod tests {
    use std::path::Path;
    use std::sync::{Condvar, Mutex};
    use std::time::Duration;

    use nalgebra::Isometry3;

    use super::*;
    use crate::analysis::stats::DeviationStats;
    use crate::analysis::test_profiles::{taught_ellipses, Ellipse};
    use crate::api::JobKind;
    use crate::config::PartConfig;
    use crate::geometry::sweep::compensation::LOOK_AHEAD;
    use crate::station::journal::{JobRecord, JobState, PartialScan, ScanFile};
    use crate::station::recorder::{Disk, Partial, RECORDER_QUEUE};

    const BALL: f64 = 1.0;

    /// Instance A's profile r300.
    const KEY: ProfileKey = ProfileKey {
        instance: 0,
        profile: 2,
    };

    /// A point event's fields the tests look at.
    struct PointEvent {
        index: usize,
        surface: [f64; 3],
        deviation: Option<f64>,
        flagged: bool,
        received: u64,
        /// Its place among the point and preview events published.
        order: usize,
    }

    /// What the pipeline published for one scan.
    struct Published {
        /// In the order published.
        points: Vec<PointEvent>,
        /// The previews, in the order published.
        previews: Vec<PointEvent>,
        stats: Option<DeviationStats>,
    }

    /// A pipeline on the propeller's plan (master at the machine's origin), its job's folder in a temporary
    /// data folder (kept while the folder is), and a receiver of its events.
    fn propeller_pipeline(
        gauges: Option<Arc<Vec<ProfileGauge>>>,
    ) -> (Pipeline, tempfile::TempDir, broadcast::Receiver<Event>) {
        let part = PartConfig::load(
            &Path::new(env!("CARGO_MANIFEST_DIR")).join("config/parts/propeller.toml"),
        )
        .unwrap();
        let plan = Arc::new(Plan::new(&part, Isometry3::identity()));
        let data = tempfile::tempdir().unwrap();
        let record = JobRecord {
            id: "sweep-test".into(),
            kind: JobKind::Inspect,
            part: "propeller".into(),
            serial: None,
            started: "2026-11-23T10:00:00Z".into(),
            state: JobState::Open,
            report: None,
            rescans: Vec::new(),
        };
        let dir = JobDir::create(data.path(), &record).unwrap();
        let (events, watch) = broadcast::channel(4 * QUEUE_POINTS);
        let (daemon, _daemon_inbox) = mpsc::channel(16);
        let pipeline = Pipeline {
            job: record.id.clone(),
            plan,
            dir,
            gauges,
            tolerance: Tolerance {
                lower_mm: -0.1,
                upper_mm: 0.1,
            },
            events,
            daemon,
        };
        (pipeline, data, watch)
    }

    /// Runs a pipeline on the propeller's plan over one scan of instance A's profile `profile`: `Start`, the raw
    /// points (each received at 1000 + its index us), then `last`.
    async fn run(
        profile: usize,
        gauges: Option<Arc<Vec<ProfileGauge>>>,
        raws: &[RawPoint],
        last: fn(ProfileKey) -> PipelineMsg,
    ) -> Published {
        let (pipeline, _data, mut watch) = propeller_pipeline(gauges);
        let (to_pipeline, inbox) = mpsc::channel(QUEUE_POINTS);
        tokio::spawn(pipeline.run(inbox));
        let key = ProfileKey {
            instance: 0,
            profile,
        };
        let start = PipelineMsg::Start {
            key,
            machine: "cmm1".into(),
            ball_radius_mm: BALL,
            entry: Point3::from(raws[0].centre),
        };
        to_pipeline.send(start).await.unwrap();
        for (i, raw) in raws.iter().enumerate() {
            let point = PipelineMsg::Point {
                key,
                raw: *raw,
                received_us: 1000 + i as u64,
            };
            to_pipeline.send(point).await.unwrap();
        }
        to_pipeline.send(last(key)).await.unwrap();
        let mut published = Published {
            points: Vec::new(),
            previews: Vec::new(),
            stats: None,
        };
        let ends_with_done = matches!(last(key), PipelineMsg::End { .. });
        let mut order = 0;
        while published.points.len() < raws.len() || ends_with_done {
            let (event, into) = match watch.recv().await.unwrap() {
                Event::Point {
                    index,
                    surface_mm,
                    deviation_mm,
                    flagged,
                    received_unix_us,
                    ..
                } => (
                    (index, surface_mm, deviation_mm, flagged, received_unix_us),
                    &mut published.points,
                ),
                Event::PointPreview {
                    index,
                    surface_mm,
                    deviation_mm,
                    flagged,
                    received_unix_us,
                    ..
                } => (
                    (index, surface_mm, deviation_mm, flagged, received_unix_us),
                    &mut published.previews,
                ),
                Event::ProfileDone { stats, .. } => {
                    published.stats = stats;
                    break;
                }
                _ => continue,
            };
            let (index, surface, deviation, flagged, received) = event;
            into.push(PointEvent {
                index,
                surface,
                deviation,
                flagged,
                received,
                order,
            });
            order += 1;
        }
        published
    }

    /// The ball's centres round the section x = 300 of the taught elliptic blade (in-plane normals, 0.36 mm
    /// apart), with a V-shaped dent 0.5 mm deep in the path on the top: a concave corner the ball cannot follow at
    /// its bottom.
    fn dented_ellipse_scan() -> Vec<RawPoint> {
        let section = Ellipse { x: 300.0 };
        let count = 600;
        let dent_at = count / 4;
        (0..count)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / count as f64;
                let n = section.normal_in_plane(t);
                let normal = Vector3::new(0.0, n.x, n.y);
                let from_dent = (i as f64 - dent_at as f64).abs();
                let dent = 0.5 * (1.0 - from_dent / 3.0).max(0.0);
                RawPoint {
                    centre: (section.point(t) + normal * (BALL - dent)).coords.into(),
                    normal: normal.into(),
                    quality: 1.0,
                }
            })
            .collect()
    }

    #[tokio::test]
    async fn sweep_compensated_points_are_published_once_in_order_and_flagged_ones_left_out_of_the_stats(
    ) {
        let reference = taught_ellipses();
        let gauges: Vec<ProfileGauge> = ProfileGauge::all(reference);
        let raws = dented_ellipse_scan();
        let published = run(2, Some(Arc::new(gauges)), &raws, |key| PipelineMsg::End {
            key,
        })
        .await;
        let indices: Vec<usize> = published.points.iter().map(|p| p.index).collect();
        assert_eq!(indices, (0..raws.len()).collect::<Vec<_>>());
        // Each event carries its own point's arrival, not that of the point that completed its look-ahead.
        assert!(published
            .points
            .iter()
            .all(|p| p.received == 1000 + p.index as u64));
        let flagged: Vec<usize> = published
            .points
            .iter()
            .filter(|p| p.flagged)
            .map(|p| p.index)
            .collect();
        assert!(!flagged.is_empty());
        assert!(
            flagged.iter().all(|i| i.abs_diff(150) <= 3 + LOOK_AHEAD),
            "{flagged:?}"
        );
        // Every point that waits for its look-ahead is previewed as it arrives, before its point event, and away
        // from the dent within a micron of it.
        let previewed: Vec<usize> = published.previews.iter().map(|p| p.index).collect();
        assert_eq!(previewed, (LOOK_AHEAD..raws.len()).collect::<Vec<_>>());
        for preview in &published.previews {
            let point = &published.points[preview.index];
            assert!(preview.order < point.order, "point {}", preview.index);
            assert_eq!(preview.received, point.received);
            if preview.index.abs_diff(150) > 2 * LOOK_AHEAD + 3 {
                let difference = preview.deviation.unwrap() - point.deviation.unwrap();
                assert!(
                    difference.abs() < 1e-3,
                    "point {}: {difference} mm",
                    preview.index
                );
            }
        }
        // The dent's bottom is flagged, and still published with its deviation.
        assert!(flagged.contains(&150));
        assert!(published.points[150].deviation.is_some());
        let stats = published.stats.expect("inspect statistics");
        let counted = published
            .points
            .iter()
            .filter(|p| !p.flagged && p.deviation.is_some())
            .count();
        assert_eq!(stats.points, counted);
        assert_eq!(stats.points + flagged.len(), raws.len());
        // Away from the dent the compensated points lie on the taught section: the fit's own error, some um.
        let off_dent = published
            .points
            .iter()
            .filter(|p| p.index.abs_diff(150) > 3 + LOOK_AHEAD)
            .map(|p| p.deviation.unwrap().abs())
            .fold(0.0, f64::max);
        assert!(off_dent < 0.01, "{off_dent}");
    }

    #[tokio::test]
    async fn sweep_points_waiting_for_their_look_ahead_are_published_when_a_scan_is_cut() {
        let raws = dented_ellipse_scan();
        let published = run(2, None, &raws[..6], |key| PipelineMsg::Cut { key }).await;
        let indices: Vec<usize> = published.points.iter().map(|p| p.index).collect();
        assert_eq!(indices, (0..6).collect::<Vec<_>>());
        // Teaching: no deviations; the surface is the centre one ball radius in along the normal.
        for point in &published.points {
            assert!(point.deviation.is_none() && !point.flagged);
            let raw = raws[point.index];
            let expected = Point3::from(raw.centre) - Vector3::from(raw.normal) * BALL;
            assert!((Point3::from(point.surface) - expected).norm() < 1e-12);
        }
    }

    /// A disk whose point writes wait while `stalled` holds, and which notes every point it writes.
    #[derive(Clone)]
    struct StallingDisk {
        dir: JobDir,
        stalled: Arc<(Mutex<bool>, Condvar)>,
        written: Arc<Mutex<Vec<RawPoint>>>,
    }

    impl StallingDisk {
        fn release(&self) {
            let (stalled, changed) = &*self.stalled;
            *stalled.lock().unwrap() = false;
            changed.notify_all();
        }
    }

    struct StallingPartial {
        file: PartialScan,
        disk: StallingDisk,
    }

    impl Disk for StallingDisk {
        type Partial = StallingPartial;

        fn start_partial(
            &self,
            scan: &ScanRef,
            header: &ScanHeader,
        ) -> std::io::Result<StallingPartial> {
            Ok(StallingPartial {
                file: self.dir.start_partial(scan, header)?,
                disk: self.clone(),
            })
        }

        fn write_scan(&self, scan: &ScanRef, file: &ScanFile) -> std::io::Result<()> {
            self.dir.write_scan(scan, file)
        }
    }

    impl Partial for StallingPartial {
        fn push(&mut self, point: &RawPoint) -> std::io::Result<()> {
            let (stalled, changed) = &*self.disk.stalled;
            let mut waiting = stalled.lock().unwrap();
            while *waiting {
                waiting = changed.wait(waiting).unwrap();
            }
            self.disk.written.lock().unwrap().push(*point);
            self.file.push(point)
        }

        fn flush(&mut self) -> std::io::Result<()> {
            self.file.flush()
        }
    }

    /// The queues are measured, not assumed: while the disk stalls the worker's sends stop once the queues are
    /// full, then every point reaches the disk in order.
    #[tokio::test]
    async fn a_stalled_disk_makes_the_worker_wait_and_every_point_is_written_in_order() {
        let (pipeline, _data, mut watch) = propeller_pipeline(None);
        let disk = StallingDisk {
            dir: pipeline.dir.clone(),
            stalled: Arc::new((Mutex::new(true), Condvar::new())),
            written: Arc::default(),
        };
        let recorder = Recorder {
            job: pipeline.job.clone(),
            dir: disk.clone(),
            events: pipeline.events.clone(),
            daemon: pipeline.daemon.clone(),
        }
        .spawn()
        .0;
        let scan = pipeline.scan_ref(KEY);
        let (to_pipeline, inbox) = mpsc::channel(QUEUE_POINTS);
        tokio::spawn(pipeline.analyse(inbox, recorder));

        // Ball centres round a circle in the plane of profile r300, more than both queues hold.
        let count = QUEUE_POINTS + RECORDER_QUEUE + 500;
        let raws: Vec<RawPoint> = (0..count)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / count as f64;
                let normal = [0.0, t.cos(), t.sin()];
                RawPoint {
                    centre: [300.0, 1000.0 * normal[1], 1000.0 * normal[2]],
                    normal,
                    quality: 1.0,
                }
            })
            .collect();
        let point = |i: usize| PipelineMsg::Point {
            key: KEY,
            raw: raws[i],
            received_us: i as u64,
        };
        let start = PipelineMsg::Start {
            key: KEY,
            machine: "cmm1".into(),
            ball_radius_mm: BALL,
            entry: Point3::from(raws[0].centre),
        };
        to_pipeline.send(start).await.unwrap();
        // The worker sends until a send has waited a second; a permit is reserved first, so no point is lost.
        let mut sent = 0;
        while sent < count {
            match tokio::time::timeout(Duration::from_secs(1), to_pipeline.reserve()).await {
                Ok(permit) => {
                    permit.unwrap().send(point(sent));
                    sent += 1;
                }
                Err(_) => break,
            }
        }
        // Taken while the disk stalls: the pipeline's queue, the recorder's, the point the disk is writing and
        // the one the analysis waits to hand on; nothing else is held.
        assert_eq!(sent, QUEUE_POINTS + RECORDER_QUEUE + 2);
        assert!(disk.written.lock().unwrap().is_empty());

        disk.release();
        for i in sent..count {
            to_pipeline.send(point(i)).await.unwrap();
        }
        to_pipeline
            .send(PipelineMsg::End { key: KEY })
            .await
            .unwrap();
        let done = async {
            loop {
                if let Event::ProfileDone { points, .. } = watch.recv().await.unwrap() {
                    return points;
                }
            }
        };
        let announced = tokio::time::timeout(Duration::from_secs(60), done)
            .await
            .expect("the profile is announced done once its scan is written");
        assert_eq!(announced, count);
        assert!(*disk.written.lock().unwrap() == raws);
        assert!(disk.dir.read_scan(&scan).unwrap().points == raws);
    }
}
