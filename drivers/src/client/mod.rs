//! The I++ DME client: [`Machine`], [`Scanning`] and [`MoveReporting`] over any byte stream (TCP, a
//! serial line, a pseudo-terminal). One task owns the link (see `actor`); [`Client`] is a cheap handle
//! that any number of tasks can clone and use at once.

mod actor;
mod calls;
pub(crate) mod replies;
mod role;

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Duration;

use async_trait::async_trait;
use futures::stream;
use tokio::io::{AsyncRead, AsyncWrite};
use tokio::sync::{broadcast, mpsc};

use crate::machine::{
    CurveScan, Error, ErrorKind, Event, InPlaneScan, Machine, MeasuredPoint, MoveReportRate,
    MoveReporting, MoveReports, ScanPoint, ScanStream, Scanning, Speeds, TransportError, Xyz,
};
use crate::wire::{Call, Data, EventTag, Tag, WireError};
use actor::{full_text, label, Actor, Reply, Request};

/// How long the client waits for the machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClientConfig {
    /// For a command's `&` after writing it, and for a write to complete.
    pub ack_timeout: Duration,
    /// For each later line of a transaction: the longest silence of a move or a scan. Longer than the
    /// slowest move the machine makes (homing a large CMM takes a minute or more).
    pub reply_timeout: Duration,
}

impl Default for ClientConfig {
    fn default() -> Self {
        ClientConfig {
            ack_timeout: Duration::from_secs(10),
            reply_timeout: Duration::from_secs(180),
        }
    }
}

/// A handle on one machine's link; clones share it.
#[derive(Clone)]
pub struct Client {
    machine: Arc<str>,
    requests: mpsc::UnboundedSender<Request>,
    events: broadcast::Sender<Event>,
}

/// How many events a slow subscriber may fall behind before it misses some (it is told it did).
const EVENT_BACKLOG: usize = 256;

impl Client {
    /// Starts the task that serves `machine` (the name errors and logs use) over `transport`. Must be
    /// called inside a tokio runtime. The task ends when the link closes or fails, or when every
    /// handle is dropped and nothing is in progress; event receivers then report the channel closed.
    pub fn new<T>(machine: &str, transport: T, config: ClientConfig) -> Client
    where
        T: AsyncRead + AsyncWrite + Unpin + Send + 'static,
    {
        let machine: Arc<str> = machine.into();
        let (requests, inbox) = mpsc::unbounded_channel();
        let (events, _) = broadcast::channel(EVENT_BACKLOG);
        let actor = Actor::new(machine.clone(), config, transport, inbox, events.clone());
        tokio::spawn(actor.run());
        Client {
            machine,
            requests,
            events,
        }
    }

    /// The machine's name.
    pub fn machine(&self) -> &str {
        &self.machine
    }

    /// Queues `call`; its replies arrive on the returned receiver.
    fn submit(&self, call: Call) -> (Origin, mpsc::UnboundedReceiver<Reply>) {
        let origin = Origin {
            machine: self.machine.clone(),
            command: label(&call),
            text: full_text(&call),
        };
        let (replies, receiver) = mpsc::unbounded_channel();
        // If the task is gone, `replies` is dropped with the request and the receiver reports it.
        let _ = self.requests.send(Request { call, replies });
        (origin, receiver)
    }

    /// Runs one transaction to its end; returns its data lines.
    async fn transact(&self, call: Call) -> Result<Vec<Data>, Error> {
        let (origin, mut replies) = self.submit(call);
        let mut data = Vec::new();
        loop {
            match replies.recv().await {
                Some(Reply::Acked(_)) => {}
                Some(Reply::Data(line)) => data.push(line),
                Some(Reply::Done(Ok(()))) => return Ok(data),
                Some(Reply::Done(Err(kind))) => return Err(origin.error(kind)),
                None => return Err(origin.disconnected()),
            }
        }
    }

    /// Runs a transaction and reads its data with `read`.
    async fn query<T>(
        &self,
        call: Call,
        read: impl FnOnce(&[Data]) -> Result<T, String>,
    ) -> Result<T, Error> {
        let origin = Origin {
            machine: self.machine.clone(),
            command: label(&call),
            text: full_text(&call),
        };
        let data = self.transact(call).await?;
        read(&data).map_err(|why| origin.bad_reply(why))
    }

    /// Sends a command whose data streams (a scan, a daemon); returns once it is acknowledged, with
    /// its tag and the rest of its replies.
    async fn start(&self, call: Call) -> Result<(Tag, Origin, Replies), Error> {
        let (origin, mut replies) = self.submit(call);
        match replies.recv().await {
            Some(Reply::Acked(tag)) => Ok((tag, origin, replies)),
            Some(Reply::Done(Err(kind))) => Err(origin.error(kind)),
            Some(other) => Err(origin.bad_reply(format!("{other:?} before the acknowledgement"))),
            None => Err(origin.disconnected()),
        }
    }

    fn call(&self, call: Result<Call, WireError>, what: &str) -> Result<Call, Error> {
        call.map_err(|problem| {
            let origin = Origin {
                machine: self.machine.clone(),
                command: what.to_owned(),
                text: what.into(),
            };
            origin.error(ErrorKind::InvalidArgument(problem))
        })
    }

    /// Sets the scan report format, sends the `hints`, then starts `scan` (the order of spec 11.2.8).
    async fn scan(&self, hints: Vec<Call>, scan: Call) -> Result<ScanStream, Error> {
        self.transact(calls::on_scan_report()).await?;
        for hint in hints {
            self.transact(hint).await?;
        }
        let (_, origin, replies) = self.start(scan).await?;
        Ok(scan_stream(origin, replies))
    }
}

type Replies = mpsc::UnboundedReceiver<Reply>;

/// Which machine and command an error belongs to.
#[derive(Clone)]
struct Origin {
    machine: Arc<str>,
    /// As the operator's message names it (`label`).
    command: String,
    /// All of it, for the log.
    text: Arc<str>,
}

impl Origin {
    fn error(&self, kind: ErrorKind) -> Error {
        tracing::warn!(machine = %self.machine, command = %self.text, error = %kind, "machine command failed");
        Error::new(self.machine.clone(), self.command.clone(), kind)
    }

    fn bad_reply(&self, why: String) -> Error {
        self.error(ErrorKind::Transport(TransportError::BadReply(why)))
    }

    fn disconnected(&self) -> Error {
        self.error(ErrorKind::Transport(TransportError::Disconnected))
    }
}

/// The scan's points as its data lines arrive; ends at `%` or after an error item.
fn scan_stream(origin: Origin, replies: Replies) -> ScanStream {
    let state = (origin, replies, VecDeque::<ScanPoint>::new(), false);
    ScanStream::new(stream::unfold(
        state,
        |(origin, mut replies, mut points, mut ended)| async move {
            loop {
                if let Some(point) = points.pop_front() {
                    return Some((Ok(point), (origin, replies, points, ended)));
                }
                if ended {
                    return None;
                }
                let failure = match replies.recv().await {
                    Some(Reply::Data(line)) => match replies::scan_points(&line) {
                        Ok(more) => {
                            points.extend(more);
                            continue;
                        }
                        Err(why) => origin.bad_reply(why),
                    },
                    Some(Reply::Acked(_)) => continue,
                    Some(Reply::Done(Ok(()))) => return None,
                    Some(Reply::Done(Err(kind))) => origin.error(kind),
                    None => origin.disconnected(),
                };
                ended = true;
                return Some((Err(failure), (origin, replies, points, ended)));
            }
        },
    ))
}

/// A daemon's positions; ends when the daemon is stopped, or after an error item.
fn move_reports(daemon: EventTag, origin: Origin, replies: Replies) -> MoveReports {
    let positions = stream::unfold(Some((origin, replies)), |state| async move {
        let (origin, mut replies) = state?;
        loop {
            let item = match replies.recv().await? {
                Reply::Data(line) => {
                    replies::position(&[line]).map_err(|why| origin.bad_reply(why))
                }
                Reply::Acked(_) | Reply::Done(Ok(())) => continue,
                Reply::Done(Err(kind)) => Err(origin.error(kind)),
            };
            let next = item.is_ok().then_some((origin, replies));
            return Some((item, next));
        }
    });
    MoveReports::new(daemon, positions)
}

#[async_trait]
impl Machine for Client {
    fn events(&self) -> broadcast::Receiver<Event> {
        self.events.subscribe()
    }

    async fn start_session(&self) -> Result<(), Error> {
        self.transact(calls::bare("StartSession")).await.map(drop)
    }

    async fn end_session(&self) -> Result<(), Error> {
        self.transact(calls::bare("EndSession")).await.map(drop)
    }

    async fn home(&self) -> Result<(), Error> {
        self.transact(calls::bare("Home")).await.map(drop)
    }

    async fn is_homed(&self) -> Result<bool, Error> {
        self.query(calls::bare("IsHomed"), |data| {
            replies::flag(data, "IsHomed")
        })
        .await
    }

    async fn change_tool(&self, name: &str) -> Result<(), Error> {
        let call = self.call(calls::change_tool(name), "ChangeTool")?;
        self.transact(call).await.map(drop)
    }

    async fn tool_radius(&self) -> Result<f64, Error> {
        // NIST's server echoes the full property path (`Tool.GoToPar.Speed(20)`); spec 6.3.13 writes
        // the bare name.
        self.query(calls::get_tool_radius(), |data| {
            replies::number(data, &["Tool.AvrRadius", "AvrRadius"])
        })
        .await
    }

    async fn set_speeds(&self, speeds: Speeds) -> Result<(), Error> {
        let call = self.call(calls::set_speeds(speeds), "SetProp")?;
        self.transact(call).await.map(drop)
    }

    async fn position(&self) -> Result<Xyz, Error> {
        self.query(calls::get_position(), replies::position).await
    }

    async fn go_to(&self, target: Xyz) -> Result<(), Error> {
        let call = self.call(calls::go_to(target), "GoTo")?;
        self.transact(call).await.map(drop)
    }

    async fn pt_meas(&self, nominal: Xyz, normal: Xyz) -> Result<MeasuredPoint, Error> {
        let call = self.call(calls::pt_meas(nominal, normal), "PtMeas")?;
        self.transact(calls::on_pt_meas_report()).await?;
        self.query(call, replies::measured_point).await
    }

    async fn abort(&self) -> Result<(), Error> {
        self.transact(calls::bare("AbortE")).await.map(drop)
    }

    async fn clear_all_errors(&self) -> Result<(), Error> {
        self.transact(calls::bare("ClearAllErrors")).await.map(drop)
    }

    async fn in_error(&self) -> Result<bool, Error> {
        self.query(calls::bare("GetErrStatusE"), |data| {
            replies::flag(data, "ErrStatus")
        })
        .await
    }

    fn scanning(&self) -> Option<Arc<dyn Scanning>> {
        Some(Arc::new(self.clone()))
    }

    fn move_reporting(&self) -> Option<Arc<dyn MoveReporting>> {
        Some(Arc::new(self.clone()))
    }
}

#[async_trait]
impl Scanning for Client {
    async fn scan_in_plane(&self, plan: InPlaneScan) -> Result<ScanStream, Error> {
        let density = calls::scan_unknown_density(&plan)
            .map(|call| self.call(call, "ScanUnknownDensity"))
            .transpose()?;
        let scan = self.call(calls::scan_in_plane(&plan), "ScanInPlaneEndIsSphere")?;
        self.scan(density.into_iter().collect(), scan).await
    }

    async fn scan_on_curve(&self, plan: CurveScan) -> Result<ScanStream, Error> {
        let hint = self.call(calls::scan_on_curve_hint(&plan), "ScanOnCurveHint")?;
        let density = self.call(
            calls::scan_on_curve_density(plan.density),
            "ScanOnCurveDensity",
        )?;
        let scan = self.call(calls::scan_on_curve(&plan), "ScanOnCurve")?;
        self.scan(vec![hint, density], scan).await
    }
}

#[async_trait]
impl MoveReporting for Client {
    async fn start_move_reports(&self, rate: MoveReportRate) -> Result<MoveReports, Error> {
        let call = self.call(calls::on_move_report(rate), "OnMoveReportE")?;
        let (tag, origin, replies) = self.start(call).await?;
        let Tag::Event(daemon) = tag else {
            unreachable!("OnMoveReportE is a fast-queue command, so it has an event tag")
        };
        Ok(move_reports(daemon, origin, replies))
    }

    async fn stop_move_reports(&self, daemon: EventTag) -> Result<(), Error> {
        self.transact(calls::stop_daemon(daemon)).await.map(drop)
    }
}
