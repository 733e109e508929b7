//! One machine's task: it owns the machine's line, feeds the controller the lines it reads, sends the lines
//! the controller produces when they are due (paced at the baud rate if one is set), applies faults and
//! keeps the transcript.

use std::collections::VecDeque;
use std::io;
use std::time::Duration;

use bytes::BytesMut;
use tokio::sync::{mpsc, watch};
use tokio::time::Instant;
use tokio_util::codec::{Decoder, Encoder};
use zeroset_drivers::codec::ServerCodec;
use zeroset_drivers::wire::{Response, ResponseKind, Tag};

use crate::faults::{Fault, ScheduledFault};
use crate::link::{Link, Read};
use crate::protocol::motion::Armed;
use crate::protocol::Controller;
use crate::transcript::Transcript;

/// Bits per byte on a serial line: start, 8 data, stop.
const BITS_PER_BYTE: f64 = 10.0;

/// What the `garbage` fault puts on the line: bytes no I++ line may hold, then CR LF so that the client
/// can find the next line.
const GARBAGE: &[u8] = b"\xFF\xFE\x00\x1B[0m#!garbage\x07\r\n";

/// Machine time: seconds since start, scaled.
#[derive(Debug, Clone, Copy)]
pub struct Clock {
    epoch: Instant,
    scale: f64,
}

impl Clock {
    pub fn new(scale: f64) -> Self {
        Clock {
            epoch: Instant::now(),
            scale,
        }
    }

    /// Machine time now.
    pub fn now(&self) -> f64 {
        self.machine(Instant::now())
    }

    fn machine(&self, wall: Instant) -> f64 {
        wall.duration_since(self.epoch).as_secs_f64() * self.scale
    }

    fn wall(&self, machine: f64) -> Instant {
        self.epoch + Duration::from_secs_f64((machine / self.scale).max(0.0))
    }

    fn wall_span(&self, machine_seconds: f64) -> Duration {
        Duration::from_secs_f64(machine_seconds / self.scale)
    }
}

/// A line waiting to go out.
struct Outgoing {
    due: Instant,
    bytes: Vec<u8>,
}

/// What happened on the line.
enum LinkEvent {
    Connected,
    Read(Read),
}

/// One machine and its line.
pub struct Machine {
    pub name: String,
    pub controller: Controller,
    pub link: Link,
    pub transcript: Transcript,
    pub clock: Clock,
    pub baud: Option<u32>,
    pub scheduled: Vec<ScheduledFault>,
    pub faults: mpsc::Receiver<Fault>,
}

/// The task's changing state beside the controller.
struct Line {
    codec: ServerCodec,
    input: BytesMut,
    connected: bool,
    /// A `disconnect` fault: deaf and mute until then.
    dead_until: Option<Instant>,
    outbox: VecDeque<Outgoing>,
    /// When the paced line has finished sending the previous line.
    free_at: Instant,
    drop_lines: u32,
    delay_next: Option<Duration>,
    delaying: Option<(Tag, Duration)>,
    commands: u64,
}

impl Machine {
    /// Serves until `shutdown` turns true.
    pub async fn serve(mut self, mut shutdown: watch::Receiver<bool>) -> io::Result<()> {
        let mut line = Line {
            codec: ServerCodec::default(),
            input: BytesMut::new(),
            connected: false,
            dead_until: None,
            outbox: VecDeque::new(),
            free_at: Instant::now(),
            drop_lines: 0,
            delay_next: None,
            delaying: None,
            commands: 0,
        };
        let address = self.link.address()?;
        self.transcript
            .event(&format!("machine {} serving on {address}", self.name));
        loop {
            let wake = self.next_wake(&line);
            let dead = line.dead_until.is_some();
            let listening = line.connected || !dead;
            tokio::select! {
                biased;
                _ = shutdown.changed() => return Ok(()),
                Some(fault) = self.faults.recv() => self.apply(fault, &mut line),
                event = link_event(&mut self.link, line.connected, &mut line.input), if listening => {
                    match event? {
                        LinkEvent::Connected => {
                            line.connected = true;
                            self.transcript.event("client connected");
                        }
                        LinkEvent::Read(Read::Bytes(_)) if dead => line.input.clear(),
                        LinkEvent::Read(Read::Bytes(_)) => self.take_input(&mut line),
                        LinkEvent::Read(Read::Closed) => {
                            self.transcript.event("client closed the line: session ended");
                            self.drop_client(&mut line);
                        }
                    }
                }
                _ = tokio::time::sleep_until(wake) => {}
            }
            let now = Instant::now();
            if line.dead_until.is_some_and(|until| until <= now) {
                line.dead_until = None;
                self.transcript.event("line alive again");
            }
            let armed = self.controller.armed();
            let due = self.controller.poll(self.clock.machine(now));
            self.note_fired(armed);
            self.queue(due, &mut line);
            self.send_due(&mut line).await?;
        }
    }

    /// The earliest of: the controller's next line, the next line to send, the end of a dead spell.
    fn next_wake(&self, line: &Line) -> Instant {
        let far = Instant::now() + Duration::from_secs(3600);
        let controller = self.controller.next_deadline().map(|t| self.clock.wall(t));
        let outbox = line.outbox.front().map(|o| o.due.max(line.free_at));
        [controller, outbox, line.dead_until]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(far)
    }

    /// Transcribes and decodes the complete lines read so far.
    fn take_input(&mut self, line: &mut Line) {
        let mut start = 0;
        while let Some(end) = line.input[start..]
            .windows(2)
            .position(|w| w == b"\r\n")
            .map(|p| start + p + 2)
        {
            self.transcript.received(&line.input[start..end]);
            start = end;
        }
        loop {
            let item = match line.codec.decode(&mut line.input) {
                Ok(Some(item)) => item,
                Ok(None) => break,
                Err(error) => {
                    self.transcript.event(&format!("read error: {error}"));
                    line.input.clear();
                    break;
                }
            };
            let now = self.clock.machine(Instant::now());
            let replies = match item {
                Ok(command) => {
                    line.commands += 1;
                    if let Some(delay) = line.delay_next.take() {
                        line.delaying = Some((command.tag(), delay));
                    }
                    let armed = self.controller.armed();
                    let replies = self.controller.receive(command, now);
                    self.note_fired(armed);
                    replies
                }
                Err(error) => {
                    self.transcript.event(&format!("bad line: {error}"));
                    self.controller.bad_line(&error)
                }
            };
            self.queue(replies, line);
            let count = line.commands;
            let firing: Vec<Fault> = self
                .scheduled
                .iter()
                .filter(|s| s.after_commands == count)
                .map(|s| s.fault)
                .collect();
            for fault in firing {
                self.apply(fault, line);
            }
        }
    }

    /// Notes in the transcript each armed fault that a motion command took since `before`: the moment it fired,
    /// which may come before its error line and after a second arming (a campaign matches errors to firings).
    fn note_fired(&mut self, before: Armed) {
        let now = self.controller.armed();
        for (was, is, fault) in [
            (before.collision, now.collision, "Collision"),
            (before.no_touch, now.no_touch, "NoTouch"),
            (
                before.surface_not_found,
                now.surface_not_found,
                "SurfaceNotFound",
            ),
        ] {
            if was && !is {
                self.transcript.event(&format!("fired {fault}"));
            }
        }
    }

    /// Puts lines in the outbox, applying the dropped-line and late-reply faults.
    fn queue(&mut self, responses: Vec<Response>, line: &mut Line) {
        let now = Instant::now();
        for response in responses {
            if line.dead_until.is_some() || !line.connected {
                continue;
            }
            let mut bytes = BytesMut::new();
            line.codec
                .encode(&response, &mut bytes)
                .expect("the controller's lines are far below the length limit");
            if line.drop_lines > 0 {
                line.drop_lines -= 1;
                self.transcript.event(&format!("dropped: {response}"));
                continue;
            }
            let mut due = now;
            if let Some((tag, delay)) = line.delaying {
                if response.tag() == tag {
                    due = now + delay;
                    if matches!(response.kind(), ResponseKind::Complete) {
                        line.delaying = None;
                    }
                }
            }
            // The line is first in, first out: nothing overtakes a late reply.
            if let Some(last) = line.outbox.back() {
                due = due.max(last.due);
            }
            line.outbox.push_back(Outgoing {
                due,
                bytes: bytes.to_vec(),
            });
        }
    }

    /// Sends the lines that are due, each taking its time on a paced line.
    async fn send_due(&mut self, line: &mut Line) -> io::Result<()> {
        loop {
            let now = Instant::now();
            let Some(next) = line.outbox.front() else {
                return Ok(());
            };
            if next.due > now || line.free_at > now {
                return Ok(());
            }
            let outgoing = line.outbox.pop_front().expect("checked above");
            if !self.link.write(&outgoing.bytes).await? {
                self.transcript.event("client gone while sending");
                self.drop_client(line);
                return Ok(());
            }
            self.transcript.sent(&outgoing.bytes);
            if let Some(baud) = self.baud {
                let seconds = outgoing.bytes.len() as f64 * BITS_PER_BYTE / f64::from(baud);
                line.free_at = now + self.clock.wall_span(seconds);
            }
        }
    }

    /// The client is gone: the session ends, nothing more is sent to it.
    fn drop_client(&mut self, line: &mut Line) {
        self.controller
            .disconnect(self.clock.machine(Instant::now()));
        line.outbox.clear();
        line.input.clear();
        line.connected = false;
        line.delaying = None;
    }

    fn apply(&mut self, fault: Fault, line: &mut Line) {
        self.transcript.event(&format!("fault {fault:?}"));
        let now = self.clock.machine(Instant::now());
        match fault {
            Fault::Garbage => {
                if line.connected && line.dead_until.is_none() {
                    let due = line.outbox.back().map_or(Instant::now(), |o| o.due);
                    line.outbox.push_back(Outgoing {
                        due,
                        bytes: GARBAGE.to_vec(),
                    });
                }
            }
            Fault::DropLines { count } => line.drop_lines += count,
            Fault::Delay { ms } => line.delay_next = Some(Duration::from_millis(ms)),
            Fault::Disconnect { ms } => {
                self.link.hang_up();
                self.drop_client(line);
                // A pty stays open on the client's side; the line is dead instead until the time is up.
                line.connected = matches!(self.link, Link::Pty(_));
                line.dead_until = Some(Instant::now() + Duration::from_millis(ms));
            }
            Fault::Estop => {
                let lines = self.controller.emergency_stop(now);
                self.queue(lines, line);
            }
            Fault::Collision => self.controller.arm(Armed {
                collision: true,
                ..Armed::default()
            }),
            Fault::NoTouch => self.controller.arm(Armed {
                no_touch: true,
                ..Armed::default()
            }),
            Fault::SurfaceNotFound => self.controller.arm(Armed {
                surface_not_found: true,
                ..Armed::default()
            }),
        }
    }
}

/// Waits for a client if there is none, else for bytes from it.
async fn link_event(
    link: &mut Link,
    connected: bool,
    input: &mut BytesMut,
) -> io::Result<LinkEvent> {
    if connected {
        Ok(LinkEvent::Read(link.read(input).await?))
    } else {
        link.connected().await?;
        Ok(LinkEvent::Connected)
    }
}
