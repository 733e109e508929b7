//! The whole simulator: opens every configured machine's line, links each pseudo-terminal into the link
//! folder if one is given, prints `machine NAME PATH` for each, then serves them (one task per machine)
//! until SIGINT or SIGTERM. Standard input, while open, is the fault channel: `fault MACHINE KIND [ARG]`
//! per line (see faults.rs), answered on standard output with `ok fault MACHINE KIND` or `error: WHY`.
//! Its end (or no standard input at all) leaves the machines serving, with only the configured faults.

use std::collections::HashMap;
use std::io::{self, Write};
use std::path::Path;
use std::sync::Arc;

use tokio::io::{AsyncBufReadExt, BufReader};
use tokio::signal::unix::{signal, SignalKind};
use tokio::sync::{mpsc, watch};

use crate::config::{PortKind, SimConfig};
use crate::faults::FaultRequest;
use crate::link::{Link, PtyLinks};
use crate::machine::{Clock, Machine};
use crate::protocol::Controller;
use crate::transcript::Transcript;

/// Why the simulator could not run.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("machine {machine}: {what}: {source}")]
    Machine {
        machine: String,
        what: &'static str,
        source: io::Error,
    },
    #[error("{0}")]
    Io(#[from] io::Error),
    #[error("{0}")]
    Part(String),
}

/// Runs the configured machines; `time_scale` overrides the file's. With `link_dir`, each pty machine's
/// path is also linked as `link_dir/NAME` (the announcement still gives the real path) until the run ends.
pub async fn run(
    config: SimConfig,
    time_scale: Option<f64>,
    link_dir: Option<&Path>,
) -> Result<(), RunError> {
    let clock = Clock::new(time_scale.unwrap_or(config.time_scale));
    let (stop, shutdown) = watch::channel(false);
    let mut senders = HashMap::new();
    let mut tasks = Vec::new();
    let mut announce = String::new();
    // Dropped on every way out of this function, which removes the links.
    let mut links = PtyLinks::default();
    for machine in &config.machines {
        let failed = |what| {
            let machine = machine.name.clone();
            move |source| RunError::Machine {
                machine,
                what,
                source,
            }
        };
        let part = config.parts[&machine.part]
            .build()
            .map_err(RunError::Part)?;
        let link = match machine.port {
            PortKind::Pty => Link::pty().map_err(failed("opening a pseudo-terminal"))?,
            PortKind::Tcp => Link::tcp(machine.tcp_port.unwrap_or(0))
                .await
                .map_err(failed("listening on 127.0.0.1"))?,
        };
        let transcript_path = machine
            .transcript
            .clone()
            .unwrap_or_else(|| Transcript::default_path(&machine.name));
        let transcript =
            Transcript::create(&transcript_path).map_err(failed("creating the transcript"))?;
        let address = link.address().map_err(failed("reading the address"))?;
        if let (Some(dir), PortKind::Pty) = (link_dir, machine.port) {
            links
                .link(dir, &machine.name, &address)
                .map_err(failed("linking its pseudo-terminal into --link-dir"))?;
        }
        announce.push_str(&announcement(&machine.name, &address));
        let (faults_in, faults) = mpsc::channel(16);
        senders.insert(machine.name.clone(), faults_in);
        let task = Machine {
            name: machine.name.clone(),
            controller: Controller::new(machine, part).with_clock(Arc::new(move || clock.now())),
            link,
            transcript,
            clock,
            baud: machine.baud,
            scheduled: machine.faults.clone(),
            faults,
        };
        tasks.push(tokio::spawn(task.serve(shutdown.clone())));
    }
    // Handlers first: a client may signal as soon as it has read the announcement.
    let mut terminate = signal(SignalKind::terminate())?;
    let mut interrupt = signal(SignalKind::interrupt())?;
    print_flushed(&announce)?;

    let mut stdin = BufReader::new(tokio::io::stdin()).lines();
    // A simulator started in the background (`zeroset sim ... &`, stdin /dev/null or closed) must keep
    // serving: the end of standard input only ends the fault channel, and only a signal stops the machines.
    let mut stdin_open = true;
    loop {
        tokio::select! {
            _ = terminate.recv() => break,
            _ = interrupt.recv() => break,
            line = stdin.next_line(), if stdin_open => {
                let line = match line {
                    Ok(Some(line)) => line,
                    Ok(None) => {
                        stdin_open = false;
                        continue;
                    }
                    Err(e) => {
                        // Not fatal either: the machines do not need the fault channel.
                        eprintln!("zeroset-sim: standard input: {e}; only configured faults from now on");
                        stdin_open = false;
                        continue;
                    }
                };
                if line.trim().is_empty() {
                    continue;
                }
                let reply = match FaultRequest::parse(&line) {
                    Ok(request) => match senders.get(&request.machine) {
                        Some(sender) => match sender.send(request.fault).await {
                            Ok(()) => format!("ok {}\n", line.trim()),
                            Err(_) => format!("error: machine {} has stopped\n", request.machine),
                        },
                        None => format!("error: no machine named {:?}\n", request.machine),
                    },
                    Err(problem) => format!("error: {problem}\n"),
                };
                print_flushed(&reply)?;
            }
        }
    }
    // Receivers may be gone already if a task failed; its error is reported below.
    let _ = stop.send(true);
    for (task, machine) in tasks.into_iter().zip(&config.machines) {
        task.await
            .map_err(|e| RunError::Io(io::Error::other(e)))?
            .map_err(|source| RunError::Machine {
                machine: machine.name.clone(),
                what: "serving",
                source,
            })?;
    }
    Ok(())
}

/// The line that tells a client where a machine is served: `machine NAME PATH`.
pub fn announcement(machine: &str, address: &str) -> String {
    format!("machine {machine} {address}\n")
}

/// Reads an announcement line back: the machine's name and where it is served.
pub fn parse_announcement(line: &str) -> Option<(String, String)> {
    match line.split_whitespace().collect::<Vec<_>>().as_slice() {
        ["machine", name, address] => Some((name.to_string(), address.to_string())),
        _ => None,
    }
}

fn print_flushed(text: &str) -> io::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn announcements_read_back() {
        let line = announcement("cmm1", "/dev/pts/7");
        assert_eq!(line, "machine cmm1 /dev/pts/7\n");
        assert_eq!(
            parse_announcement(&line),
            Some(("cmm1".into(), "/dev/pts/7".into()))
        );
        assert_eq!(parse_announcement("ok fault cmm1 estop"), None);
    }
}
