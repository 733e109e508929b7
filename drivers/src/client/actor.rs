//! The task that owns the link to one machine. Callers hand it requests through a channel; it alone
//! writes commands and reads replies, so the protocol's ordering rules live in one place:
//! - one normal command in flight: the next is written only after the previous one's `&`;
//! - fast-queue (E-tag) commands are written at once, ahead of queued normal ones;
//! - after `AbortE` nothing is written until it completes (spec 6.3.1.5);
//! - motion is refused from an error of severity 2 or more (or an abort) until `ClearAllErrors`
//!   succeeds;
//! - every transaction has a deadline for its next line.

use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::Arc;

use futures::{SinkExt, StreamExt};
use tokio::io::{AsyncRead, AsyncWrite};
use tokio::sync::{broadcast, mpsc};
use tokio::time::{sleep_until, timeout, Instant};
use tokio_util::codec::Framed;

use super::role::{is_fast, Role};
use super::ClientConfig;
use crate::codec::{ClientCodec, EncodeError};
use crate::machine::{ErrorKind, Event, TransportError};
use crate::wire::{
    Call, Command, CommandTag, Data, DeviceError, EventTag, LineError, Response, ResponseKind, Tag,
    WireError,
};

/// A command to send and where its replies go.
pub(crate) struct Request {
    pub(crate) call: Call,
    pub(crate) replies: mpsc::UnboundedSender<Reply>,
}

/// What the caller of a request hears. Unbounded, because a CMM does not wait for a slow reader: the
/// link must keep being read so that an emergency stop is never stuck behind scan data.
#[derive(Debug)]
pub(crate) enum Reply {
    /// `&`, with the tag the command went out with.
    Acked(Tag),
    Data(Data),
    /// The transaction is over (`%`, or it failed). For a daemon, data may still follow.
    Done(Result<(), ErrorKind>),
}

/// A transaction written and not yet complete.
struct Open {
    label: String,
    role: Role,
    replies: mpsc::UnboundedSender<Reply>,
    acked: bool,
    /// The first error of severity 2 or more; the transaction fails with it at its `%`.
    failure: Option<DeviceError>,
    deadline: Instant,
    /// The lockout count when the command was written: a `ClearAllErrors` lifts only the lockouts
    /// that happened before it.
    locks_before: u64,
}

/// A daemon whose data keeps coming after its transaction completed.
struct Daemon {
    label: String,
    replies: mpsc::UnboundedSender<Reply>,
}

pub(crate) struct Actor<T> {
    machine: Arc<str>,
    config: ClientConfig,
    link: Framed<T, ClientCodec>,
    requests: mpsc::UnboundedReceiver<Request>,
    events: broadcast::Sender<Event>,
    /// Normal commands waiting for the previous one's `&`.
    queue: VecDeque<Request>,
    /// Fast-queue commands, written as soon as no abort is in progress.
    fast: VecDeque<Request>,
    /// The normal command written and not yet acknowledged.
    awaiting_ack: Option<Tag>,
    /// The `AbortE` written and not yet complete.
    aborting: Option<Tag>,
    open: HashMap<Tag, Open>,
    daemons: HashMap<Tag, Daemon>,
    /// Tags of transactions that failed on the client's side (timeout, garbled line): their late
    /// lines are dropped rather than reported as strays.
    abandoned: HashSet<Tag>,
    /// Why motion is refused, if it is.
    lockout: Option<String>,
    /// How many times a lockout was set, to tell which ones a `ClearAllErrors` covered.
    locks: u64,
    last_tag: u32,
    last_event_tag: u16,
    /// Every client handle is gone: finish the open transactions, then stop.
    orphaned: bool,
}

impl<T: AsyncRead + AsyncWrite + Unpin> Actor<T> {
    pub(crate) fn new(
        machine: Arc<str>,
        config: ClientConfig,
        transport: T,
        requests: mpsc::UnboundedReceiver<Request>,
        events: broadcast::Sender<Event>,
    ) -> Self {
        Actor {
            machine,
            config,
            link: Framed::new(transport, ClientCodec::default()),
            requests,
            events,
            queue: VecDeque::new(),
            fast: VecDeque::new(),
            awaiting_ack: None,
            aborting: None,
            open: HashMap::new(),
            daemons: HashMap::new(),
            abandoned: HashSet::new(),
            lockout: None,
            locks: 0,
            last_tag: 0,
            last_event_tag: 0,
            orphaned: false,
        }
    }

    /// Serves requests until the link fails or closes, or every handle is dropped and nothing is open.
    pub(crate) async fn run(mut self) {
        let fault = loop {
            if let Err(fault) = self.write_ready().await {
                break fault;
            }
            if self.orphaned && self.open.is_empty() && self.queue.is_empty() {
                return;
            }
            let deadline = self.open.values().map(|open| open.deadline).min();
            tokio::select! {
                request = self.requests.recv(), if !self.orphaned => match request {
                    Some(request) => self.accept(request),
                    None => self.orphaned = true,
                },
                line = self.link.next() => match line {
                    Some(Ok(Ok(response))) => self.on_response(response),
                    Some(Ok(Err(garbled))) => self.on_garbled(garbled),
                    Some(Err(error)) => break TransportError::from(error),
                    None => break TransportError::Disconnected,
                },
                () = sleep_until(deadline.unwrap_or_else(Instant::now)), if deadline.is_some() => {
                    self.on_deadlines();
                }
            }
        };
        self.fail_everything(fault);
    }

    fn accept(&mut self, request: Request) {
        if is_fast(&request.call) {
            self.fast.push_back(request);
        } else {
            self.queue.push_back(request);
        }
    }

    /// Writes every command the ordering rules allow now.
    async fn write_ready(&mut self) -> Result<(), TransportError> {
        while self.aborting.is_none() {
            let next = match self.fast.pop_front() {
                Some(request) => request,
                None if self.awaiting_ack.is_none() => match self.queue.pop_front() {
                    Some(request) => request,
                    None => break,
                },
                None => break,
            };
            self.write(next).await?;
        }
        Ok(())
    }

    async fn write(&mut self, request: Request) -> Result<(), TransportError> {
        let role = Role::of(&request.call);
        let label = label(&request.call);
        if role == Role::Motion {
            if let Some(cause) = &self.lockout {
                let refusal = ErrorKind::LockedOut {
                    cause: cause.clone(),
                };
                let _ = request.replies.send(Reply::Done(Err(refusal)));
                return Ok(());
            }
        }
        let fast = is_fast(&request.call);
        let tag = self.next_tag(fast);
        let command = match Command::new(tag, request.call.name, request.call.args) {
            Ok(command) => command,
            Err(problem) => {
                let _ = request
                    .replies
                    .send(Reply::Done(Err(ErrorKind::InvalidArgument(problem))));
                return Ok(());
            }
        };
        tracing::debug!(machine = %self.machine, "> {command}");
        // A peer that stops reading must not wedge the task that watches for emergency stops.
        match timeout(self.config.ack_timeout, self.link.send(&command)).await {
            Err(_) => {
                self.fail_one(&request.replies, self.timeout("write to the link"));
                return Err(self.timeout("write to the link"));
            }
            Ok(Err(EncodeError::LineTooLong { len })) => {
                let problem = WireError::LineTooLong {
                    len,
                    max: crate::codec::MAX_LINE_LEN,
                };
                let _ = request
                    .replies
                    .send(Reply::Done(Err(ErrorKind::InvalidArgument(problem))));
                return Ok(());
            }
            Ok(Err(EncodeError::Io(error))) => {
                let fault = TransportError::from(error);
                self.fail_one(&request.replies, fault.clone());
                return Err(fault);
            }
            Ok(Ok(())) => {}
        }
        if !fast {
            self.awaiting_ack = Some(tag);
        }
        if role == Role::Abort {
            self.aborting = Some(tag);
            self.lock("an abort".to_owned());
        }
        let open = Open {
            label,
            role,
            replies: request.replies,
            acked: false,
            failure: None,
            deadline: Instant::now() + self.config.ack_timeout,
            locks_before: self.locks,
        };
        self.open.insert(tag, open);
        Ok(())
    }

    fn on_response(&mut self, response: Response) {
        tracing::debug!(machine = %self.machine, "< {response}");
        let tag = response.tag();
        if tag == Tag::Unsolicited {
            return self.on_unsolicited(response.into_kind());
        }
        if self.open.contains_key(&tag) {
            return self.on_transaction_line(tag, response.into_kind());
        }
        if self.daemons.contains_key(&tag) {
            return self.on_daemon_line(tag, response.into_kind());
        }
        if self.abandoned.contains(&tag) {
            if *response.kind() == ResponseKind::Complete {
                self.abandoned.remove(&tag);
            }
            return;
        }
        self.publish(Event::Stray(response));
    }

    fn on_unsolicited(&mut self, kind: ResponseKind) {
        match kind {
            ResponseKind::Error(error) => {
                if error.severity() >= 2 {
                    self.lock(format!(
                        "the machine's unsolicited error {:04} ({})",
                        error.code(),
                        error.text()
                    ));
                }
                self.publish(Event::Unsolicited(error));
            }
            ResponseKind::Data(data) => self.publish(Event::UnsolicitedData(data)),
            // `Response::new` keeps & and % off E0000.
            ResponseKind::Ack | ResponseKind::Complete => {
                unreachable!("E0000 never acknowledges or completes")
            }
        }
    }

    fn on_transaction_line(&mut self, tag: Tag, kind: ResponseKind) {
        let reply_timeout = self.config.reply_timeout;
        let open = self.open.get_mut(&tag).expect("checked by the caller");
        open.deadline = Instant::now() + reply_timeout;
        match kind {
            ResponseKind::Ack => {
                open.acked = true;
                let _ = open.replies.send(Reply::Acked(tag));
                if self.awaiting_ack == Some(tag) {
                    self.awaiting_ack = None;
                }
            }
            ResponseKind::Data(data) => {
                let _ = open.replies.send(Reply::Data(data));
            }
            ResponseKind::Error(error) if error.severity() < 2 => {
                let command = open.label.clone();
                self.publish(Event::Warning { command, error });
            }
            ResponseKind::Error(error) => {
                let cause = format!(
                    "error {:04} ({}) on {}",
                    error.code(),
                    error.text(),
                    open.label
                );
                open.failure.get_or_insert(error);
                self.lock(cause);
            }
            ResponseKind::Complete => {
                let open = self.open.remove(&tag).expect("checked by the caller");
                self.forget_in_flight(tag);
                self.complete(tag, open);
            }
        }
    }

    fn complete(&mut self, tag: Tag, open: Open) {
        if let Some(error) = open.failure {
            let _ = open
                .replies
                .send(Reply::Done(Err(ErrorKind::Device(error))));
            return;
        }
        match open.role {
            Role::ClearsErrors if self.locks == open.locks_before => self.lockout = None,
            Role::StartsDaemon => {
                let daemon = Daemon {
                    label: open.label,
                    replies: open.replies.clone(),
                };
                self.daemons.insert(tag, daemon);
            }
            Role::StopsDaemon(daemon) => {
                self.daemons.remove(&daemon);
            }
            Role::EndsSession => self.daemons.clear(),
            _ => {}
        }
        let _ = open.replies.send(Reply::Done(Ok(())));
    }

    fn on_daemon_line(&mut self, tag: Tag, kind: ResponseKind) {
        let daemon = &self.daemons[&tag];
        match kind {
            ResponseKind::Data(data) => {
                let _ = daemon.replies.send(Reply::Data(data));
            }
            ResponseKind::Error(error) if error.severity() < 2 => {
                let command = daemon.label.clone();
                self.publish(Event::Warning { command, error });
            }
            ResponseKind::Error(error) => {
                let daemon = self.daemons.remove(&tag).expect("looked up above");
                let cause = format!(
                    "error {:04} ({}) on {}",
                    error.code(),
                    error.text(),
                    daemon.label
                );
                let _ = daemon
                    .replies
                    .send(Reply::Done(Err(ErrorKind::Device(error))));
                self.lock(cause);
            }
            ResponseKind::Ack | ResponseKind::Complete => {
                let line = Response::new(tag, kind).expect("an ack or complete line is valid");
                self.publish(Event::Stray(line));
            }
        }
    }

    /// A garbled line may have been any transaction's reply, so none of them can be trusted.
    fn on_garbled(&mut self, garbled: LineError) {
        tracing::debug!(machine = %self.machine, "< garbled: {garbled}");
        let fault = TransportError::BadLine(garbled.clone());
        for (tag, open) in std::mem::take(&mut self.open) {
            self.forget_in_flight(tag);
            self.abandoned.insert(tag);
            self.fail_one(&open.replies, fault.clone());
        }
        self.publish(Event::BadLine(garbled));
    }

    fn on_deadlines(&mut self) {
        let now = Instant::now();
        let expired: Vec<Tag> = self
            .open
            .iter()
            .filter(|(_, open)| open.deadline <= now)
            .map(|(tag, _)| *tag)
            .collect();
        for tag in expired {
            let open = self.open.remove(&tag).expect("listed above");
            let fault = if open.acked {
                TransportError::Timeout {
                    awaited: "next reply",
                    after: self.config.reply_timeout,
                }
            } else {
                self.timeout("acknowledgement (&)")
            };
            self.forget_in_flight(tag);
            self.abandoned.insert(tag);
            self.fail_one(&open.replies, fault);
        }
    }

    /// The link is gone: everything open, queued or still in the channel fails with `fault`.
    fn fail_everything(mut self, fault: TransportError) {
        tracing::debug!(machine = %self.machine, "link closed: {fault}");
        self.requests.close();
        let open = self.open.drain().map(|(_, open)| open.replies);
        let daemons = self.daemons.drain().map(|(_, daemon)| daemon.replies);
        let queued = self.queue.drain(..).chain(self.fast.drain(..));
        let waiting = std::iter::from_fn(|| self.requests.try_recv().ok());
        let replies: Vec<_> = open
            .chain(daemons)
            .chain(queued.chain(waiting).map(|request| request.replies))
            .collect();
        for reply in replies {
            let _ = reply.send(Reply::Done(Err(ErrorKind::Transport(fault.clone()))));
        }
        self.publish(Event::Disconnected(fault));
    }

    fn fail_one(&self, replies: &mpsc::UnboundedSender<Reply>, fault: TransportError) {
        let _ = replies.send(Reply::Done(Err(ErrorKind::Transport(fault))));
    }

    /// A transaction that ended, by any path, no longer holds up the queue.
    fn forget_in_flight(&mut self, tag: Tag) {
        if self.awaiting_ack == Some(tag) {
            self.awaiting_ack = None;
        }
        if self.aborting == Some(tag) {
            self.aborting = None;
        }
    }

    fn lock(&mut self, cause: String) {
        self.locks += 1;
        self.lockout.get_or_insert(cause);
    }

    fn timeout(&self, awaited: &'static str) -> TransportError {
        TransportError::Timeout {
            awaited,
            after: self.config.ack_timeout,
        }
    }

    fn publish(&self, event: Event) {
        // No subscriber is fine: the lockout does not depend on anyone listening.
        let _ = self.events.send(event);
    }

    /// The next free tag of the kind the command needs, skipping tags still in use.
    fn next_tag(&mut self, fast: bool) -> Tag {
        loop {
            let tag = if fast {
                self.last_event_tag = self.last_event_tag % 9_999 + 1;
                Tag::Event(EventTag::new(self.last_event_tag).expect("in 1-9999"))
            } else {
                self.last_tag = self.last_tag % 99_999 + 1;
                Tag::Command(CommandTag::new(self.last_tag).expect("in 1-99999"))
            };
            let in_use = self.open.contains_key(&tag)
                || self.daemons.contains_key(&tag)
                || self.abandoned.contains(&tag);
            if !in_use {
                return tag;
            }
        }
    }
}

/// The command as errors name it: its text, or when long (a curve scan's nominals) its name and how many
/// arguments it had, for an operator's message; the whole text goes to the log as a field ([`full_text`]).
pub(crate) fn label(call: &Call) -> String {
    const MAX: usize = 80;
    let text = call.to_string();
    if text.len() <= MAX {
        return text;
    }
    format!("{}(... {} arguments)", call.name, call.args.len())
}

/// The command's whole text, for the log.
pub(crate) fn full_text(call: &Call) -> Arc<str> {
    call.to_string().into()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{Arg, Name, Number};

    fn call(name: &str, count: usize) -> Call {
        let args = (0..count)
            .map(|i| Arg::Number(Number::from_f64(100.0 + i as f64 * 0.125).unwrap()))
            .collect();
        Call::new(Name::new(name).unwrap(), args)
    }

    #[test]
    fn a_long_command_is_named_by_its_name_and_argument_count_and_logged_whole() {
        let short = call("GoTo", 3);
        assert_eq!(label(&short), short.to_string());
        let scan = call("ScanOnCurve", 1200);
        assert_eq!(label(&scan), "ScanOnCurve(... 1200 arguments)");
        let whole = full_text(&scan);
        assert!(whole.len() > 5000 && whole.ends_with("249.875)"), "{whole}");
    }
}
