//! A machine worker: the one task that drives one CMM. It takes scan orders one at a time and executes each
//! scan's planned motion (`motion`) exactly: the approach, the scan with its points streamed to the job's
//! pipeline as they arrive, and the planned lift-off and way out. Anything that goes wrong ends the order with a
//! typed error naming the machine, sends nothing more, and leaves the machine alone until the operator clears it.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use futures::{FutureExt, StreamExt};
use nalgebra::{Point3, Vector3};
use tokio::sync::{broadcast, mpsc, oneshot};
use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::machine::{
    Error as MachineError, ErrorKind, Event, InPlaneScan, Machine, MoveReportRate, MoveReports,
    ScanStream, Speeds, Xyz,
};
use zeroset_drivers::transport::SerialConfig;
use zeroset_drivers::transport::{open_pty, open_serial};
use zeroset_drivers::wire::EventTag;

use super::core::Input;
use super::escape::{check_way_out, extend_by_trail, plan_escape, EscapeModel, ScanPath};
use super::gaps::find_gap;
use super::motion::{Scan, ScanMotion};
use super::not_found::{where_not_found, SURFACE_NOT_FOUND};
use super::pipeline::PipelineMsg;
use super::DaemonMsg;
use crate::analysis::RawPoint;
use crate::api::{FaultKind, MachineFault};
use crate::config::{MachineEntry, ProbeSettings, Safety};
use crate::geometry::sweep::mesh::MeshPart;
use watch::locks_motion;

/// I++ error 0008, "Protocol error": what a controller answers to StartSession while it holds a session, and to
/// other commands on a session it no longer holds.
const PROTOCOL_ERROR: u16 = 8;
/// A position this far below the clearance height still counts as at it (the rounding of a reported position), mm.
const AT_HEIGHT_TOLERANCE_MM: f64 = 1e-3;
/// How often a teach scan's trail reports the ball centre: the I++ floor, 2 mm of travel at 20 mm/s.
const TRAIL_INTERVAL: Duration = Duration::from_millis(100);

/// What a worker is asked to do.
pub enum Order {
    /// Scan one profile by its planned motion, every point to the job's pipeline.
    Scan {
        motion: Box<ScanMotion>,
        /// The taught part model (none when teaching): the lift-off from where the scan really ended is checked
        /// against it, and against the scan's known path, before it is sent.
        part: Option<Arc<MeshPart>>,
        pipeline: mpsc::Sender<PipelineMsg>,
    },
    /// Clear the machine's errors (reconnecting a lost link, re-opening its session) and take the probe clear of
    /// the part by a way out planned from where it is and checked against what is known of the part.
    Clear {
        escape: EscapeModel,
        reply: oneshot::Sender<Result<(), WorkerError>>,
    },
}

/// The daemon's side of a worker.
#[derive(Clone)]
pub struct WorkerHandle {
    pub name: String,
    pub orders: mpsc::Sender<Order>,
    /// The machine's link, to abort a scan from outside the worker.
    link: Arc<Mutex<Option<Link>>>,
    /// Set by an abort, cleared by the next clear: the worker sends no motion while it is set, so an abort that
    /// finds no link yet (a fresh daemon's first order) still stops the order.
    aborted: Arc<AtomicBool>,
}

/// A machine as the worker drives it: the I++ client on a line, or a mock in the tests.
pub type Link = Arc<dyn Machine>;

/// Opens a machine's link (again, after it was lost).
pub type Connector = Box<dyn Fn() -> Result<Link, WorkerError> + Send + Sync>;

impl WorkerHandle {
    /// Stops all motion now (I++ `AbortE` jumps the machine's queue); the running order ends with an error and
    /// the machine stays locked out until `zeroset clear`.
    pub async fn abort(&self) {
        self.aborted.store(true, Ordering::SeqCst);
        let client = self.link.lock().expect("not poisoned").clone();
        if let Some(client) = client {
            if let Err(error) = client.abort().await {
                tracing::warn!(machine = %self.name, %error, "abort failed");
            }
        }
    }
}

/// Starts the worker of one machine on its serial line or pseudo-terminal.
pub fn spawn(
    entry: MachineEntry,
    probe: ProbeSettings,
    safety: Safety,
    daemon: mpsc::Sender<DaemonMsg>,
) -> WorkerHandle {
    let name = entry.name.clone();
    let watch = Some(watch::EVERY);
    spawn_on(name, line_connector(entry), probe, safety, watch, daemon)
}

/// Starts the worker of the machine named `name`, reached through `connect`; while idle it watches the machine
/// every `watch` (none: only orders wake it).
pub fn spawn_on(
    name: String,
    connect: Connector,
    probe: ProbeSettings,
    safety: Safety,
    watch: Option<Duration>,
    daemon: mpsc::Sender<DaemonMsg>,
) -> WorkerHandle {
    let (orders, inbox) = mpsc::channel(4);
    let link = Arc::new(Mutex::new(None));
    let aborted = Arc::new(AtomicBool::new(false));
    let handle = WorkerHandle {
        name: name.clone(),
        orders,
        link: link.clone(),
        aborted: aborted.clone(),
    };
    let worker = Worker {
        name,
        connect,
        probe,
        safety,
        link,
        aborted,
        alarms: None,
        session: false,
        ball_radius: None,
        path: None,
        trail: None,
        trail_refused: false,
        travel: None,
        fault: None,
        seen: false,
    };
    tokio::spawn(worker.run(inbox, watch, daemon));
    handle
}

/// The I++ client on the machine's configured line.
fn line_connector(entry: MachineEntry) -> Connector {
    Box::new(move || {
        let port = entry.port.to_string_lossy().into_owned();
        let config = ClientConfig {
            ack_timeout: Duration::from_secs_f64(entry.ack_timeout_s),
            reply_timeout: Duration::from_secs_f64(entry.reply_timeout_s),
        };
        let line = match entry.baud {
            Some(baud) => open_serial(&SerialConfig {
                path: port.clone(),
                baud,
            }),
            None => open_pty(&port),
        };
        let line = line.map_err(|e| WorkerError {
            kind: FaultKind::PortMissing,
            message: format!(
                "machine {}: cannot open its line {port}: {e}; check the cable and that the controller is on, then run `zeroset clear`",
                entry.name
            ),
        })?;
        Ok(Arc::new(Client::new(&entry.name, line, config)) as Link)
    })
}

struct Worker {
    name: String,
    connect: Connector,
    probe: ProbeSettings,
    safety: Safety,
    link: Arc<Mutex<Option<Link>>>,
    aborted: Arc<AtomicBool>,
    /// What the machine reported outside the commands (an emergency stop, an alarm) since the link opened.
    alarms: Option<broadcast::Receiver<Event>>,
    /// Whether this worker holds an I++ session on the current link.
    session: bool,
    /// The active tool's ball radius once the machine is set up for this station.
    ball_radius: Option<f64>,
    /// The surface around the probe as far as the station knows it: the last scan's.
    path: Option<ScanPath>,
    /// The move-report daemon of a teach scan that stopped, still running on the machine (it outlives an
    /// emergency stop and ClearAllErrors, and the machine takes one at a time): stopped by the next clear.
    trail: Option<EventTag>,
    /// The machine refused move reports on this link (a daemon a killed predecessor started, say): teach scans
    /// run without a trail until the link is opened again, rather than be refused the same way each time.
    trail_refused: bool,
    /// The ball centres the machine reported in a teach scan that stopped, with that scan's plan: with the position
    /// the probe is found at, they extend the known path past its last point for the way out (`escape::trail`).
    travel: Option<(InPlaneScan, Vec<Point3<f64>>)>,
    /// Why the machine may not move until the operator's clear: a failed order, or what the watch saw while idle.
    fault: Option<WorkerError>,
    /// Whether the watch has told the daemon the machine is ready (once, at its first healthy look).
    seen: bool,
}

/// How a scan order ended.
pub type ScanResult = Result<(), WorkerError>;

/// Why an order failed: its kind (what the daemon decides on) and what the operator reads.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct WorkerError {
    pub kind: FaultKind,
    pub message: String,
}

impl WorkerError {
    pub fn fault(&self) -> MachineFault {
        MachineFault {
            kind: self.kind,
            message: self.message.clone(),
        }
    }
}

impl From<MachineError> for WorkerError {
    fn from(error: MachineError) -> Self {
        let kind = match error.kind() {
            ErrorKind::Device(device) => FaultKind::Device {
                severity: device.severity(),
                code: device.code(),
            },
            ErrorKind::Transport(_) => FaultKind::Transport,
            ErrorKind::LockedOut { .. } => FaultKind::LockedOut,
            // A target that cannot be written (not finite) is a plan the station must not send.
            ErrorKind::InvalidArgument(_) => FaultKind::Refused,
        };
        WorkerError {
            kind,
            message: error.to_string(),
        }
    }
}

impl Worker {
    /// Takes orders one at a time; between them, every `watch`, looks at the machine (`watch`).
    async fn run(
        mut self,
        mut inbox: mpsc::Receiver<Order>,
        watch: Option<Duration>,
        daemon: mpsc::Sender<DaemonMsg>,
    ) {
        let mut ticks = watch.map(|every| {
            let mut ticks = tokio::time::interval(every);
            ticks.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
            ticks
        });
        loop {
            // What the machine raised comes before the next order: an order must not start on a machine that
            // has just been stopped.
            let wake = tokio::select! {
                biased;
                event = watch::next_event(&mut self.alarms), if ticks.is_some() => watch::Wake::Event(event),
                order = inbox.recv() => match order {
                    Some(order) => watch::Wake::Order(order),
                    None => return,
                },
                _ = watch::tick(&mut ticks) => watch::Wake::Tick,
            };
            let order = match wake {
                watch::Wake::Event(event) => {
                    self.on_event(event, &daemon).await;
                    continue;
                }
                watch::Wake::Tick => {
                    self.look(&daemon).await;
                    continue;
                }
                watch::Wake::Order(order) => order,
            };
            if !self.execute(order, &daemon).await {
                return;
            }
        }
    }

    /// Runs one order and reports how it ended; false once the daemon is gone.
    async fn execute(&mut self, order: Order, daemon: &mpsc::Sender<DaemonMsg>) -> bool {
        match order {
            Order::Scan {
                motion,
                part,
                pipeline,
            } => {
                let key = motion.key;
                let result = match self.standing_fault() {
                    Some(fault) => Err(fault),
                    None => self.scan(*motion, part.as_deref(), pipeline).await,
                };
                let result = result.map_err(|e| self.failed(e));
                let report = DaemonMsg::Input(Input::ScanEnded {
                    machine: self.name.clone(),
                    key,
                    result,
                });
                if daemon.send(report).await.is_err() {
                    return false;
                }
            }
            Order::Clear { escape, reply } => {
                // An operator's clear lifts an abort, as it lifts every lockout.
                self.aborted.store(false, Ordering::SeqCst);
                self.fault = None;
                self.alarms();
                let result = self.clear(&escape).await.map_err(|e| self.failed(e));
                let _ = reply.send(result);
            }
        }
        true
    }

    /// The fault that keeps the machine from moving before a clear, with any alarm raised since it was last
    /// looked at: a scan order meeting one ends with it, sending nothing.
    fn standing_fault(&mut self) -> Option<WorkerError> {
        if let Some((kind, message)) = self
            .alarms()
            .into_iter()
            .find(|(kind, _)| locks_motion(*kind))
        {
            self.fault.get_or_insert(WorkerError { kind, message });
        }
        self.fault.clone()
    }

    /// A failed order's error led by the alarms raised meanwhile (an emergency stop ends a scan with "transaction
    /// aborted", and the operator needs to read why, and the daemon to know it was an emergency stop); a lost
    /// link is forgotten, so that the next order opens it again. Every failed order passes here.
    fn failed(&mut self, error: WorkerError) -> WorkerError {
        if error.kind == FaultKind::Gap {
            // The machine did all it was asked: nothing to set up again.
            return error;
        }
        let alarms = self.alarms();
        if matches!(error.kind, FaultKind::Transport | FaultKind::PortMissing) {
            self.drop_link();
        }
        // Set up again after any failure: a lost link, a restarted controller, a tool change.
        self.ball_radius = None;
        let error = match alarms.first() {
            None => error,
            Some((first_kind, _)) => {
                let mut message: Vec<String> =
                    alarms.iter().map(|(_, text)| text.clone()).collect();
                message.push(error.message);
                WorkerError {
                    kind: *first_kind,
                    message: message.join("; "),
                }
            }
        };
        // Nothing moves until the operator's clear.
        self.fault.get_or_insert_with(|| error.clone());
        error
    }

    fn client(&self) -> Option<Link> {
        self.link.lock().expect("not poisoned").clone()
    }

    /// The machine's link, opened if it is not.
    fn connect(&mut self) -> Result<Link, WorkerError> {
        if let Some(client) = self.client() {
            return Ok(client);
        }
        let client = (self.connect)()?;
        self.alarms = Some(client.events());
        self.session = false;
        *self.link.lock().expect("not poisoned") = Some(client.clone());
        Ok(client)
    }

    /// The alarms the machine raised (an emergency stop, a collision) since they were last read.
    fn alarms(&mut self) -> Vec<(FaultKind, String)> {
        let mut alarms = Vec::new();
        if let Some(receiver) = self.alarms.as_mut() {
            while let Ok(event) = receiver.try_recv() {
                if let Event::Unsolicited(alarm) = event {
                    let kind = FaultKind::Device {
                        severity: alarm.severity(),
                        code: alarm.code(),
                    };
                    let text = format!(
                        "machine {}: the machine raised error {:04} (severity {}): {}",
                        self.name,
                        alarm.code(),
                        alarm.severity(),
                        alarm.text()
                    );
                    alarms.push((kind, text));
                }
            }
        }
        alarms
    }

    /// Starts a session on the link unless this worker holds one. A controller may still hold the session of a
    /// daemon that was killed (it answers StartSession with a protocol error): that session is ended and a new
    /// one started, which also clears the machine's errors.
    async fn open_session(&mut self, client: &Link) -> Result<(), WorkerError> {
        if self.session {
            return Ok(());
        }
        match client.start_session().await {
            Ok(()) => {}
            Err(error) if is_protocol_error(&error) => {
                tracing::warn!(machine = %self.name, "taking over a session left open on the machine");
                let _ = client.end_session().await;
                client.start_session().await?;
            }
            Err(error) => return Err(error.into()),
        }
        self.session = true;
        Ok(())
    }

    /// Session, homing, tool and speeds: what the station needs before the first motion. Returns the ball radius.
    async fn prepare(&mut self) -> Result<(Link, f64), WorkerError> {
        let client = self.connect()?;
        if let Some(radius) = self.ball_radius {
            return Ok((client, radius));
        }
        self.open_session(&client).await?;
        if !client.is_homed().await? {
            // Homing moves every axis: only from above the part.
            self.require_clearance_height(&client, "homing").await?;
            client.home().await?;
        }
        client.change_tool(&self.probe.tool).await?;
        let speeds = Speeds {
            travel: self.probe.travel_mm_s,
            probing: self.probe.probing_mm_s,
            scanning: self.probe.scanning_mm_s,
        };
        client.set_speeds(speeds).await?;
        let radius = client.tool_radius().await?;
        if !(radius > 0.0 && radius <= self.safety.max_ball_radius_mm) {
            return Err(WorkerError {
                kind: FaultKind::Refused,
                message: format!(
                    "machine {}: tool {} has a ball radius of {radius} mm, outside (0, {}] mm allowed by the station's safety settings; qualify or change the tool",
                    self.name, self.probe.tool, self.safety.max_ball_radius_mm
                ),
            });
        }
        self.ball_radius = Some(radius);
        Ok((client, radius))
    }

    async fn position(&self, client: &Link) -> Result<Point3<f64>, WorkerError> {
        let here = client.position().await?;
        Ok(Point3::new(here.x, here.y, here.z))
    }

    /// Refuses to move unless the probe is at or above the clearance height, where free travel is planned.
    async fn require_clearance_height(
        &self,
        client: &Link,
        before: &str,
    ) -> Result<Point3<f64>, WorkerError> {
        let here = self.position(client).await?;
        if here.z < self.safety.clearance_z_mm - AT_HEIGHT_TOLERANCE_MM {
            return Err(WorkerError {
                kind: FaultKind::Refused,
                message: format!(
                    "machine {}: the probe is at ({:.3}, {:.3}, {:.3}) mm, below the clearance height z = {} mm, \
                     before {before}: nothing was moved; run `zeroset clear` to take it clear of the part",
                    self.name, here.x, here.y, here.z, self.safety.clearance_z_mm
                ),
            });
        }
        Ok(here)
    }

    /// The machine's errors cleared on its link (opened if need be): on a new link starting a session does it; a
    /// session the machine no longer holds is opened again.
    async fn clear_errors(&mut self) -> Result<Link, WorkerError> {
        let client = self.connect()?;
        if !self.session {
            // A new session starts with the machine's errors cleared (the spec's StartSession), and
            // ClearAllErrors says so on the wire: no motion goes out after an error without it.
            self.open_session(&client).await?;
            client.clear_all_errors().await?;
            return Ok(client);
        }
        match client.clear_all_errors().await {
            Ok(()) => {}
            Err(error) if is_protocol_error(&error) => {
                // The machine no longer holds this worker's session (it was restarted, or its line dropped and
                // came back): start over on it.
                tracing::warn!(machine = %self.name, "the machine lost the session; opening it again");
                self.session = false;
                self.open_session(&client).await?;
            }
            Err(error) => return Err(error.into()),
        }
        Ok(client)
    }

    /// Forgets a link that failed, so that the next use opens it again.
    fn drop_link(&mut self) {
        *self.link.lock().expect("not poisoned") = None;
        self.alarms = None;
        self.session = false;
        // A daemon lives in its session: stopping one a new session does not hold would be an error (0513).
        self.trail = None;
        self.trail_refused = false;
    }

    /// Clears the machine's errors (on a new link, starting a session does; a session the machine no longer
    /// holds is opened again) and takes the probe clear of the part by a way out checked against the model.
    async fn clear(&mut self, model: &EscapeModel) -> Result<(), WorkerError> {
        // A link that died unseen (the controller restarted) is opened again, in the same clear.
        let client = match self.clear_errors().await {
            Err(error) if error.kind == FaultKind::Transport => {
                tracing::warn!(machine = %self.name, %error, "the link was lost; opening it again to clear");
                self.drop_link();
                self.clear_errors().await?
            }
            result => result?,
        };
        self.stop_trail(&client).await?;
        // The way out first, with the tool the machine has on: changing it moves the head, so the station sets
        // the machine up (`prepare`) only once the probe is at the clearance height.
        self.ball_radius = None;
        let here = self.position(&client).await?;
        if here.z < self.safety.clearance_z_mm - AT_HEIGHT_TOLERANCE_MM {
            self.leave_the_part(&client, here, model).await?;
        }
        self.path = None;
        self.travel = None;
        self.prepare().await?;
        Ok(())
    }

    /// Takes the probe from `here`, below the clearance height, up to it by a way out checked against what is
    /// known of the part, with the ball the machine has on.
    async fn leave_the_part(
        &mut self,
        client: &Link,
        here: Point3<f64>,
        model: &EscapeModel,
    ) -> Result<(), WorkerError> {
        let radius = client.tool_radius().await?;
        if !(radius > 0.0 && radius <= self.safety.max_ball_radius_mm) {
            return Err(WorkerError {
                kind: FaultKind::Refused,
                message: format!(
                    "machine {}: its active tool has a ball radius of {radius} mm, outside (0, {}] mm, so no way out \
                     can be checked; jog the probe above z = {} mm with the machine's pendant, then run `zeroset clear`",
                    self.name, self.safety.max_ball_radius_mm, self.safety.clearance_z_mm
                ),
            });
        }
        // The scan the worker was on, else the job's scans nearest first (after a restart the worker knows none):
        // the first whose way out is proven is taken; each is checked against its own path and the part model.
        let mut candidates: Vec<&ScanPath> = model.paths.iter().collect();
        candidates.sort_by(|a, b| {
            a.distance_mm(&here, radius)
                .total_cmp(&b.distance_mm(&here, radius))
        });
        let own = self.path.clone().map(|mut scan| {
            if let Some((plan, travel)) = &self.travel {
                let trail: Vec<Point3<f64>> = travel.iter().copied().chain([here]).collect();
                let added = extend_by_trail(&mut scan.path, &trail, plan, radius);
                tracing::info!(machine = %self.name, scan = %scan.name, reports = travel.len(), added, "the known path extended past the last scan point by the positions the machine reported and the one it is at");
            }
            scan
        });
        let candidates: Vec<&ScanPath> = own.iter().chain(candidates).collect();
        let mut refusal = None;
        let mut moves = None;
        for scan in &candidates {
            match plan_escape(
                here,
                Some((&scan.path, scan.margin_mm)),
                radius,
                &self.safety,
                model,
            ) {
                Ok(found) => {
                    moves = Some(found);
                    break;
                }
                Err(error) => {
                    refusal
                        .get_or_insert(format!("{error} (the nearest scan known: {})", scan.name));
                }
            }
        }
        let moves = match moves {
            Some(moves) => moves,
            // Off every known scan: straight up, if the part model proves it free.
            None => plan_escape(here, None, radius, &self.safety, model).map_err(|e| WorkerError {
                kind: FaultKind::Refused,
                message: format!(
                    "machine {}: {}; jog the probe above z = {} mm with the machine's pendant, then run `zeroset clear`",
                    self.name,
                    refusal.unwrap_or_else(|| e.to_string()),
                    self.safety.clearance_z_mm
                ),
            })?,
        };
        for target in moves {
            client.go_to(xyz(&target)).await?;
        }
        Ok(())
    }

    async fn scan(
        &mut self,
        motion: ScanMotion,
        part: Option<&MeshPart>,
        pipeline: mpsc::Sender<PipelineMsg>,
    ) -> ScanResult {
        // Nothing moves, the set-up's tool change included, unless the probe is at the clearance height.
        let client = self.connect()?;
        self.open_session(&client).await?;
        self.require_clearance_height(&client, &format!("the approach to {}", motion.name))
            .await?;
        let (client, radius) = self.prepare().await?;
        // From the descent on, the probe is near the part: a way out after a stop follows this scan's path.
        self.path = Some(ScanPath {
            name: motion.name.clone(),
            path: motion.path.clone(),
            margin_mm: motion.margin_mm,
        });
        self.travel = None;
        for target in &motion.approach {
            self.not_aborted()?;
            client.go_to(xyz(target)).await?;
        }
        let scanning = client.scanning().ok_or_else(|| WorkerError {
            kind: FaultKind::Refused,
            message: format!(
                "machine {}: its probe cannot scan; this station needs a scanning probe",
                self.name
            ),
        })?;
        // The pipeline opens the profile's partial file while the machine starts the scan, not while the first
        // points wait (opening a file costs most of a millisecond).
        let start = PipelineMsg::Start {
            key: motion.key,
            machine: self.name.clone(),
            ball_radius_mm: radius,
            entry: motion.path.surface[motion.path.entry],
        };
        if pipeline.send(start).await.is_err() {
            return Err(self.pipeline_gone());
        }
        let trail = match &motion.scan {
            Scan::InPlane(plan) => self.start_trail(&client, plan, &motion.name).await,
            Scan::Curve(_) => None,
        };
        self.not_aborted()?;
        let started = match &motion.scan {
            Scan::InPlane(plan) => scanning.scan_in_plane(plan.clone()).await,
            Scan::Curve(plan) => scanning.scan_on_curve(plan.clone()).await,
        };
        let streamed = match started {
            Ok(stream) => self.stream(stream, trail, &motion, &pipeline, radius).await,
            Err(error) => Err(error.into()),
        };
        // A scan that ended well may still have lost a line of points on the way: then it is kept as a cut scan,
        // not counted, and scanned again.
        let gap = streamed
            .as_ref()
            .ok()
            .and_then(|centres| find_gap(&motion, centres, radius));
        let end = match (&streamed, &gap) {
            (Ok(_), None) => PipelineMsg::End { key: motion.key },
            _ => PipelineMsg::Cut { key: motion.key },
        };
        if pipeline.send(end).await.is_err() {
            return Err(self.pipeline_gone());
        }
        streamed?;
        self.stop_trail(&client).await?;
        self.retract(&client, &motion, radius, part).await?;
        match gap {
            None => Ok(()),
            Some(gap) => Err(WorkerError {
                kind: FaultKind::Gap,
                message: format!(
                    "machine {}: the scan of {} is not whole: {gap}",
                    self.name, motion.name
                ),
            }),
        }
    }

    /// The planned lift-off and way out, sent only if the scan ended where the plan has it end and the lift-off
    /// from where it really ended (the one leg the set-up's sweep could not see) keeps clear of the scan's known
    /// surface (for a teach, the points just measured) and of the taught part model.
    async fn retract(
        &mut self,
        client: &Link,
        motion: &ScanMotion,
        radius: f64,
        part: Option<&MeshPart>,
    ) -> ScanResult {
        let here = self.position(client).await?;
        let off = (here - motion.end).norm();
        if off > motion.end_tolerance_mm {
            return Err(WorkerError {
                kind: FaultKind::Refused,
                message: format!(
                    "machine {}: the scan of {} ended at ({:.3}, {:.3}, {:.3}) mm, {off:.2} mm from its planned end \
                     (more than {:.2} mm), so its planned way out is not the move to make: nothing was moved; run \
                     `zeroset clear`",
                    self.name,
                    motion.name,
                    here.x,
                    here.y,
                    here.z,
                    motion.end_tolerance_mm
                ),
            });
        }
        let known = self.path.as_ref().map(|scan| &scan.path);
        check_way_out(here, &motion.retract, known, radius, &self.safety, part).map_err(|e| {
            WorkerError {
                kind: FaultKind::Refused,
                message: format!(
                    "machine {}: after the scan of {}, {e}: nothing was moved; run `zeroset clear`",
                    self.name, motion.name
                ),
            }
        })?;
        for target in &motion.retract {
            self.not_aborted()?;
            client.go_to(xyz(target)).await?;
        }
        self.path = None;
        Ok(())
    }

    /// Forwards the scan's points to the pipeline as they arrive, extending the known path with them when the
    /// profile's shape was unknown, and, should the scan stop, with the trail of positions the machine reported
    /// past them. Returns the ball centres, for the check that the scan is whole.
    async fn stream(
        &mut self,
        mut stream: ScanStream,
        mut reports: Option<MoveReports>,
        motion: &ScanMotion,
        pipeline: &mpsc::Sender<PipelineMsg>,
        radius: f64,
    ) -> Result<Vec<Point3<f64>>, WorkerError> {
        let teaching = matches!(motion.scan, Scan::InPlane(_));
        let mut centres = Vec::new();
        let mut trail = Vec::new();
        loop {
            let item = tokio::select! {
                biased;
                report = next_report(&mut reports) => {
                    match report {
                        Some(Ok(p)) => trail.push(Point3::new(p.x, p.y, p.z)),
                        _ => reports = None,
                    }
                    continue;
                }
                item = stream.next() => item,
            };
            let Some(item) = item else {
                break;
            };
            let received_us = super::clock::unix_us();
            let point = match item {
                Ok(point) => point,
                Err(error) => {
                    if let Scan::InPlane(plan) = &motion.scan {
                        self.follow_trail(reports.as_mut(), trail, plan);
                    }
                    let mut error = WorkerError::from(error);
                    if let (
                        Scan::Curve(plan),
                        FaultKind::Device {
                            code: SURFACE_NOT_FOUND,
                            ..
                        },
                    ) = (&motion.scan, error.kind)
                    {
                        error.message.push_str(&where_not_found(
                            plan,
                            &motion.edges,
                            centres.len(),
                            radius,
                        ));
                    }
                    return Err(error);
                }
            };
            let raw = RawPoint {
                centre: [point.centre.x, point.centre.y, point.centre.z],
                normal: [point.normal.x, point.normal.y, point.normal.z],
                quality: point.quality,
            };
            if teaching {
                if let Some(ScanPath { path, .. }) = self.path.as_mut() {
                    if let Some(normal) = Vector3::from(raw.normal).try_normalize(1e-9) {
                        path.surface
                            .push(Point3::from(raw.centre) - normal * radius);
                        path.normals.push(normal);
                    }
                }
            }
            centres.push(Point3::from(raw.centre));
            let message = PipelineMsg::Point {
                key: motion.key,
                raw,
                received_us,
            };
            if pipeline.send(message).await.is_err() {
                return Err(self.pipeline_gone());
            }
        }
        if teaching {
            if let Some(ScanPath { path, .. }) = self.path.as_mut() {
                path.closed = true;
            }
        }
        Ok(centres)
    }

    /// Starts the ball-centre reports of a teach scan, the one record of its travel past the last point the
    /// machine sent should it stop (`escape::trail`). Without them the scan still runs: a stop then leaves a way
    /// out only within a few millimetres of the last point, and the clear says so.
    async fn start_trail(
        &mut self,
        client: &Link,
        plan: &InPlaneScan,
        scan: &str,
    ) -> Option<MoveReports> {
        if self.trail_refused {
            return None;
        }
        let Some(reporting) = client.move_reporting() else {
            tracing::warn!(machine = %self.name, scan, "the machine sends no move reports: a stop in this teach scan may leave the probe where no way out is known");
            return None;
        };
        let rate = MoveReportRate {
            interval: TRAIL_INTERVAL,
            distance: plan.spacing.max_distance(),
        };
        match reporting.start_move_reports(rate).await {
            Ok(reports) => {
                self.trail = Some(reports.daemon());
                Some(reports)
            }
            Err(error) => {
                self.trail_refused = true;
                tracing::warn!(machine = %self.name, scan, %error, "move reports refused: a stop in this teach scan may leave the probe where no way out is known");
                None
            }
        }
    }

    /// After a teach scan stopped: keeps the positions reported by now, for the way out the next clear plans.
    fn follow_trail(
        &mut self,
        reports: Option<&mut MoveReports>,
        mut trail: Vec<Point3<f64>>,
        plan: &InPlaneScan,
    ) {
        if let Some(reports) = reports {
            while let Some(Some(Ok(p))) = reports.next().now_or_never() {
                trail.push(Point3::new(p.x, p.y, p.z));
            }
        }
        self.travel = Some((plan.clone(), trail));
    }

    /// Stops the move reports a teach scan started (after a stop, once the errors are cleared: the machine
    /// refuses StopDaemon in error).
    async fn stop_trail(&mut self, client: &Link) -> Result<(), WorkerError> {
        let (Some(daemon), Some(reporting)) = (self.trail.take(), client.move_reporting()) else {
            return Ok(());
        };
        reporting.stop_move_reports(daemon).await.map_err(|error| {
            let error = WorkerError::from(error);
            WorkerError {
                message: format!(
                    "machine {}: its move reports could not be stopped ({}); nothing was moved; run `zeroset clear`",
                    self.name, error.message
                ),
                ..error
            }
        })
    }

    /// Refuses the next motion command after an operator's abort, until a clear.
    fn not_aborted(&self) -> Result<(), WorkerError> {
        if self.aborted.load(Ordering::SeqCst) {
            return Err(WorkerError {
                kind: FaultKind::Aborted,
                message: format!(
                    "machine {}: aborted by the operator; nothing more was sent",
                    self.name
                ),
            });
        }
        Ok(())
    }

    fn pipeline_gone(&self) -> WorkerError {
        WorkerError {
            kind: FaultKind::Station,
            message: format!(
                "machine {}: the job's analysis stopped; the scan was not recorded",
                self.name
            ),
        }
    }
}

/// The next move report, or never when there are none (a select's branch that stays silent).
async fn next_report(reports: &mut Option<MoveReports>) -> Option<Result<Xyz, MachineError>> {
    match reports {
        Some(reports) => reports.next().await,
        None => std::future::pending().await,
    }
}

fn is_protocol_error(error: &MachineError) -> bool {
    error
        .device_error()
        .is_some_and(|e| e.code() == PROTOCOL_ERROR)
}

fn xyz(p: &Point3<f64>) -> Xyz {
    Xyz::new(p.x, p.y, p.z)
}

mod watch;

#[cfg(test)]
mod tests;
