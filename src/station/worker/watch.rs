//! The worker's watch over an idle machine: the machine's state is observed, not assumed. Between orders the
//! worker keeps the link open and listens to it (an emergency stop, an alarm, the line closing arrive
//! unsolicited), and every [`EVERY`] it opens the link if it is not open (a port that is missing is seen before a
//! job needs it) and asks the machine whether it is in error (GetErrStatusE, answered ahead of any queue), so a
//! line that went dead is seen too. What it finds locks the machine out until the operator's `zeroset clear`,
//! as a failed order does.

use std::time::Duration;

use tokio::sync::{broadcast, mpsc};
use zeroset_drivers::machine::Event;

use super::{is_protocol_error, Order, Worker, WorkerError};
use crate::api::FaultKind;
use crate::station::core::Input;
use crate::station::DaemonMsg;

/// How often an idle machine is looked at.
pub(super) const EVERY: Duration = Duration::from_secs(1);

/// What woke the worker.
pub(super) enum Wake {
    Order(Order),
    Event(Option<Event>),
    Tick,
}

/// The next event on the link (`None`: some were missed, or the link's events ended); never, without a link.
pub(super) async fn next_event(events: &mut Option<broadcast::Receiver<Event>>) -> Option<Event> {
    let Some(receiver) = events.as_mut() else {
        return std::future::pending().await;
    };
    match receiver.recv().await {
        Ok(event) => Some(event),
        Err(broadcast::error::RecvError::Lagged(_)) => None,
        Err(broadcast::error::RecvError::Closed) => {
            *events = None;
            None
        }
    }
}

/// The next look at the machine; never, without a watch.
pub(super) async fn tick(ticks: &mut Option<tokio::time::Interval>) {
    match ticks.as_mut() {
        Some(ticks) => {
            ticks.tick().await;
        }
        None => std::future::pending().await,
    }
}

/// Whether a fault of this kind stops the machine's motion (an alarm of severity 2 or more does).
pub(super) fn locks_motion(kind: FaultKind) -> bool {
    match kind {
        FaultKind::Device { severity, .. } => severity >= 2,
        _ => true,
    }
}

impl Worker {
    /// An event on the idle link: an alarm that stops motion, or the line closing, locks the machine out.
    pub(super) async fn on_event(
        &mut self,
        event: Option<Event>,
        daemon: &mpsc::Sender<DaemonMsg>,
    ) {
        let fault = match event {
            Some(Event::Unsolicited(alarm)) if alarm.severity() >= 2 => WorkerError {
                kind: FaultKind::Device {
                    severity: alarm.severity(),
                    code: alarm.code(),
                },
                message: format!(
                    "machine {}: the machine raised error {:04} (severity {}) while idle: {}",
                    self.name,
                    alarm.code(),
                    alarm.severity(),
                    alarm.text()
                ),
            },
            Some(Event::Disconnected(error)) => WorkerError {
                kind: FaultKind::Transport,
                message: format!(
                    "machine {}: its line was lost while idle ({error}); check the cable and that the controller \
                     is on",
                    self.name
                ),
            },
            Some(Event::BadLine(error)) => {
                tracing::warn!(machine = %self.name, %error, "a garbled line from an idle machine");
                return;
            }
            _ => return,
        };
        self.observe(fault, daemon).await;
    }

    /// A look at the idle machine: its link opened if it is not, then whether it reports an error state.
    pub(super) async fn look(&mut self, daemon: &mpsc::Sender<DaemonMsg>) {
        if self.fault.is_some() && self.client().is_some() {
            // Locked out already, with a link for the operator's clear: nothing more to learn.
            return;
        }
        let client = match self.connect() {
            Ok(client) => client,
            Err(error) => return self.observe(error, daemon).await,
        };
        if self.fault.is_some() {
            return;
        }
        if !self.session {
            match client.start_session().await {
                Ok(()) => self.session = true,
                // The machine holds the session of a daemon that was killed: the next order takes it over (which
                // clears the machine's errors, so only an order the operator asked for does it). That session
                // still answers GetErrStatusE, so the look goes on: a machine that is never looked at is blind.
                Err(error) if is_protocol_error(&error) => {}
                Err(error) => return self.observe(error.into(), daemon).await,
            }
        }
        match client.in_error().await {
            Ok(false) => self.tell_seen(daemon).await,
            Ok(true) => {
                let fault = WorkerError {
                    kind: FaultKind::LockedOut,
                    message: format!(
                        "machine {}: the machine reports an error state while idle (an emergency stop or an alarm); \
                         release the emergency stop or remove the alarm's cause",
                        self.name
                    ),
                };
                self.observe(fault, daemon).await;
            }
            Err(error) => self.observe(error.into(), daemon).await,
        }
    }

    /// The first healthy look tells the daemon the machine is ready (it is not called idle before).
    async fn tell_seen(&mut self, daemon: &mpsc::Sender<DaemonMsg>) {
        if std::mem::replace(&mut self.seen, true) {
            return;
        }
        let _ = daemon
            .send(DaemonMsg::Input(Input::Seen {
                machine: self.name.clone(),
            }))
            .await;
    }

    /// Locks the machine out for `fault` (once, until a clear) and tells the daemon.
    async fn observe(&mut self, fault: WorkerError, daemon: &mpsc::Sender<DaemonMsg>) {
        let first = self.fault.is_none();
        let fault = self.failed(fault);
        if !first {
            return;
        }
        tracing::error!(machine = %self.name, kind = %fault.kind, error = %fault.message, "machine fault while idle");
        let _ = daemon
            .send(DaemonMsg::Input(Input::Observed {
                machine: self.name.clone(),
                fault,
            }))
            .await;
    }
}
