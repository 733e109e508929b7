//! A machine worker: the one task that drives one CMM. It takes scan orders one at a time, moves the probe to the
//! scan's entry at the clearance height, streams the scan's points to the job's pipeline as they arrive, and
//! leaves the part the way it came. Anything that goes wrong ends the order with an error that names the machine
//! and leaves the machine alone until the operator clears it.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use futures::StreamExt;
use nalgebra::{Point3, Vector3};
use tokio::sync::{broadcast, mpsc, oneshot};
use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::machine::{
    CurveScan, Error as MachineError, Event, InPlaneScan, Machine, ScanStream, Speeds, Xyz,
};
use zeroset_drivers::transport::SerialConfig;
use zeroset_drivers::transport::{open_pty, open_serial};

use super::escape::{way_out, KnownPath};

/// I++ error 0008, "Protocol error": what a controller answers to StartSession while it holds a session.
const PROTOCOL_ERROR: u16 = 8;
use super::pipeline::PipelineMsg;
use super::DaemonMsg;
use crate::analysis::RawPoint;
use crate::config::{MachineEntry, ProbeSettings, Safety};
use crate::plan::ProfileKey;

/// What a worker is asked to do.
pub enum Order {
    Scan(ScanOrder),
    /// Clear the machine's errors (reconnecting a lost link) and take the probe clear of the part, using `path`
    /// and its margin (mm) when the worker has no path of its own (after a daemon restart: the partial scan on
    /// disk).
    Clear {
        path: Option<(KnownPath, f64)>,
        reply: oneshot::Sender<Result<(), String>>,
    },
}

/// One profile to scan.
pub struct ScanOrder {
    pub key: ProfileKey,
    pub scan: Scan,
    /// The surface known before the scan (the nominal curve, or the teach's start point) and its entry.
    pub path: KnownPath,
    /// How far off the known surface the probe travels when entering and leaving, mm.
    pub margin_mm: f64,
    pub pipeline: mpsc::Sender<PipelineMsg>,
}

pub enum Scan {
    /// The master's profile, shape unknown.
    InPlane(InPlaneScan),
    /// A profile along its taught nominal curve.
    Curve(CurveScan),
}

/// The daemon's side of a worker.
#[derive(Clone)]
pub struct WorkerHandle {
    pub name: String,
    pub orders: mpsc::Sender<Order>,
    /// The machine's link, to abort a scan from outside the worker.
    link: Arc<Mutex<Option<Link>>>,
}

/// A machine as the worker drives it: the I++ client on a line, or a mock in the tests.
pub type Link = Arc<dyn Machine>;

/// Opens a machine's link (again, after it was lost).
pub type Connector = Box<dyn Fn() -> Result<Link, WorkerError> + Send + Sync>;

impl WorkerHandle {
    /// Stops all motion now (I++ `AbortE` jumps the machine's queue); the running order ends with an error.
    pub async fn abort(&self) {
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
    spawn_on(name, line_connector(entry), probe, safety, daemon)
}

/// Starts the worker of the machine named `name`, reached through `connect`.
pub fn spawn_on(
    name: String,
    connect: Connector,
    probe: ProbeSettings,
    safety: Safety,
    daemon: mpsc::Sender<DaemonMsg>,
) -> WorkerHandle {
    let (orders, inbox) = mpsc::channel(4);
    let link = Arc::new(Mutex::new(None));
    let handle = WorkerHandle {
        name: name.clone(),
        orders,
        link: link.clone(),
    };
    let worker = Worker {
        name,
        connect,
        probe,
        safety,
        link,
        alarms: None,
        session: false,
        ball_radius: None,
        path: None,
        margin_mm: 0.0,
    };
    tokio::spawn(worker.run(inbox, daemon));
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
    /// What the machine reported outside the commands (an emergency stop, an alarm) since the link opened.
    alarms: Option<broadcast::Receiver<Event>>,
    /// Whether this worker holds an I++ session on the current link.
    session: bool,
    /// The active tool's ball radius once the machine is set up for this station.
    ball_radius: Option<f64>,
    /// The surface around the probe as far as the station knows it: the last scan's.
    path: Option<KnownPath>,
    margin_mm: f64,
}

/// How a scan order ended.
pub type ScanResult = Result<(), WorkerError>;

/// Why an order failed: what the operator reads, and whether the machine needs clearing.
#[derive(Debug, Clone)]
pub struct WorkerError {
    pub message: String,
}

impl From<MachineError> for WorkerError {
    fn from(error: MachineError) -> Self {
        WorkerError {
            message: error.to_string(),
        }
    }
}

impl Worker {
    async fn run(mut self, mut inbox: mpsc::Receiver<Order>, daemon: mpsc::Sender<DaemonMsg>) {
        while let Some(order) = inbox.recv().await {
            match order {
                Order::Scan(order) => {
                    let key = order.key;
                    // Alarms from before this order were reported with the order they stopped.
                    self.alarms();
                    let result = self.scan(order).await.map_err(|e| self.with_alarms(e));
                    if result.is_err() {
                        // Set up again after any failure: a lost link, a restarted controller, a tool change.
                        self.ball_radius = None;
                    }
                    let report = DaemonMsg::ScanEnded {
                        machine: self.name.clone(),
                        key,
                        result,
                    };
                    if daemon.send(report).await.is_err() {
                        return;
                    }
                }
                Order::Clear { path, reply } => {
                    if let (None, Some((path, margin))) = (&self.path, path) {
                        self.path = Some(path);
                        self.margin_mm = margin;
                    }
                    self.alarms();
                    let _ = reply.send(self.clear().await.map_err(|e| e.message));
                }
            }
        }
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
        *self.link.lock().expect("not poisoned") = Some(client.clone());
        Ok(client)
    }

    /// The alarms the machine raised (an emergency stop, a collision) since they were last read.
    fn alarms(&mut self) -> Vec<String> {
        let mut alarms = Vec::new();
        if let Some(receiver) = self.alarms.as_mut() {
            while let Ok(event) = receiver.try_recv() {
                if let Event::Unsolicited(alarm) = event {
                    alarms.push(format!(
                        "the machine raised error {:04} (severity {}): {}",
                        alarm.code(),
                        alarm.severity(),
                        alarm.text()
                    ));
                }
            }
        }
        alarms
    }

    /// A failed order's error led by the alarms raised meanwhile: an emergency stop ends a scan with "transaction
    /// aborted", and the operator needs to read why.
    fn with_alarms(&mut self, error: WorkerError) -> WorkerError {
        let mut parts = self.alarms();
        parts.push(error.message);
        WorkerError {
            message: parts.join("; "),
        }
    }

    /// Forgets a link that failed, so that the next order opens it again and starts over on it.
    fn drop_link_if_lost(&mut self, error: &MachineError) {
        if error.transport_error().is_some() {
            *self.link.lock().expect("not poisoned") = None;
            self.alarms = None;
            self.session = false;
            self.ball_radius = None;
        }
    }

    /// A failed machine command as the order's error, the link forgotten if it was the link that failed.
    fn fail(&mut self, error: MachineError) -> WorkerError {
        self.drop_link_if_lost(&error);
        error.into()
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
            Err(error)
                if error
                    .device_error()
                    .is_some_and(|e| e.code() == PROTOCOL_ERROR) =>
            {
                tracing::warn!(machine = %self.name, "taking over a session left open on the machine");
                let _ = client.end_session().await;
                client.start_session().await.map_err(|e| self.fail(e))?;
            }
            Err(error) => return Err(self.fail(error)),
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
        if !client.is_homed().await.map_err(|e| self.fail(e))? {
            self.leave(&client).await?;
            client.home().await.map_err(|e| self.fail(e))?;
        }
        client
            .change_tool(&self.probe.tool)
            .await
            .map_err(|e| self.fail(e))?;
        let speeds = Speeds {
            travel: self.probe.travel_mm_s,
            probing: self.probe.probing_mm_s,
            scanning: self.probe.scanning_mm_s,
        };
        client.set_speeds(speeds).await.map_err(|e| self.fail(e))?;
        let radius = client.tool_radius().await.map_err(|e| self.fail(e))?;
        if !(radius > 0.0 && radius <= self.safety.max_ball_radius_mm) {
            return Err(WorkerError {
                message: format!(
                    "machine {}: tool {} has a ball radius of {radius} mm, outside (0, {}] mm allowed by the station's safety settings; qualify or change the tool",
                    self.name, self.probe.tool, self.safety.max_ball_radius_mm
                ),
            });
        }
        self.ball_radius = Some(radius);
        Ok((client, radius))
    }

    /// Takes the probe from wherever it is to the clearance height without crossing the part.
    async fn leave(&self, client: &Link) -> Result<Point3<f64>, WorkerError> {
        let here = client.position().await?;
        let here = Point3::new(here.x, here.y, here.z);
        let radius = self.ball_radius.unwrap_or(self.safety.max_ball_radius_mm);
        let moves = way_out(
            here,
            self.path.as_ref(),
            radius,
            self.margin_mm,
            self.safety.clearance_z_mm,
        )
        .map_err(|e| WorkerError {
            message: format!(
                "machine {}: {e}; jog the probe above z = {} mm with the machine's pendant, then run `zeroset clear`",
                self.name, self.safety.clearance_z_mm
            ),
        })?;
        let mut at = here;
        for target in moves {
            client.go_to(xyz(&target)).await?;
            at = target;
        }
        Ok(at)
    }

    /// Clears the machine's errors (on a new link, starting a session does) and takes the probe clear of the part.
    async fn clear(&mut self) -> Result<(), WorkerError> {
        let client = self.connect()?;
        if self.session {
            client.clear_all_errors().await.map_err(|e| self.fail(e))?;
        } else {
            self.open_session(&client).await?;
        }
        self.ball_radius = None;
        let (client, _) = self.prepare().await?;
        self.leave(&client).await?;
        Ok(())
    }

    async fn scan(&mut self, order: ScanOrder) -> ScanResult {
        let (client, radius) = self.prepare().await?;
        let moved = async {
            self.leave(&client).await?;
            let entry = order.path.entry_offset(radius, order.margin_mm);
            client
                .go_to(Xyz::new(entry.x, entry.y, self.safety.clearance_z_mm))
                .await?;
            client.go_to(xyz(&entry)).await?;
            Ok::<_, WorkerError>(())
        };
        moved.await?;
        // From the entry on, the probe is near the part: its way out is along this scan's path.
        self.path = Some(order.path.clone());
        self.margin_mm = order.margin_mm;
        let scanning = client.scanning().ok_or_else(|| WorkerError {
            message: format!(
                "machine {}: its probe cannot scan; this station needs a scanning probe",
                self.name
            ),
        })?;
        // The pipeline opens the profile's partial file while the machine starts the scan, not while the first
        // points wait (opening a file costs most of a millisecond).
        let pipeline = order.pipeline.clone();
        let start = PipelineMsg::Start {
            key: order.key,
            machine: self.name.clone(),
            ball_radius_mm: radius,
            entry: order.path.surface[order.path.entry],
        };
        if pipeline.send(start).await.is_err() {
            return Err(self.pipeline_gone());
        }
        let started = match &order.scan {
            Scan::InPlane(plan) => scanning.scan_in_plane(plan.clone()).await,
            Scan::Curve(plan) => scanning.scan_on_curve(plan.clone()).await,
        };
        let stream = match started {
            Ok(stream) => stream,
            Err(error) => {
                let _ = pipeline.send(PipelineMsg::Cut { key: order.key }).await;
                return Err(self.fail(error));
            }
        };
        let streamed = self.stream(stream, &order, radius).await;
        let end = match &streamed {
            Ok(()) => PipelineMsg::End { key: order.key },
            Err(_) => PipelineMsg::Cut { key: order.key },
        };
        if pipeline.send(end).await.is_err() {
            return Err(self.pipeline_gone());
        }
        streamed?;
        self.leave(&client).await?;
        Ok(())
    }

    /// Forwards the scan's points to the pipeline as they arrive, extending the known path with them when the
    /// profile's shape was unknown.
    async fn stream(
        &mut self,
        mut stream: ScanStream,
        order: &ScanOrder,
        radius: f64,
    ) -> ScanResult {
        let teaching = matches!(order.scan, Scan::InPlane(_));
        while let Some(item) = stream.next().await {
            let received_us = super::clock::unix_us();
            let point = match item {
                Ok(point) => point,
                Err(error) => return Err(self.fail(error)),
            };
            let raw = RawPoint {
                centre: [point.centre.x, point.centre.y, point.centre.z],
                normal: [point.normal.x, point.normal.y, point.normal.z],
                quality: point.quality,
            };
            if teaching {
                if let Some(path) = self.path.as_mut() {
                    let normal = Vector3::from(raw.normal);
                    path.surface
                        .push(Point3::from(raw.centre) - normal * radius);
                    path.normals.push(normal);
                }
            }
            let message = PipelineMsg::Point {
                key: order.key,
                raw,
                received_us,
            };
            if order.pipeline.send(message).await.is_err() {
                return Err(self.pipeline_gone());
            }
        }
        if teaching {
            if let Some(path) = self.path.as_mut() {
                path.closed = true;
            }
        }
        Ok(())
    }

    fn pipeline_gone(&self) -> WorkerError {
        WorkerError {
            message: format!(
                "machine {}: the job's analysis stopped; the scan was not recorded",
                self.name
            ),
        }
    }
}

fn xyz(p: &Point3<f64>) -> Xyz {
    Xyz::new(p.x, p.y, p.z)
}

#[cfg(test)]
mod tests;
