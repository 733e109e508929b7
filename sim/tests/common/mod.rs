//! Runs the real `zeroset-sim` binary and talks I++ DME to it through the drivers' ClientCodec, over the
//! pseudo-terminal (opened from the client side in raw mode) or TCP.

#![allow(dead_code)] // each test file uses its own share of these helpers

pub mod nist;
pub mod shape;

use std::fs::{File, OpenOptions};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::os::fd::AsFd;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::time::{Duration, Instant};

use bytes::BytesMut;
use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
use tokio_util::codec::{Decoder, Encoder};
use zeroset_drivers::codec::ClientCodec;
use zeroset_drivers::wire::{Command as WireCommand, LineError, Response, ResponseKind};
use zeroset_sim::config::{PartSpec, SimConfig};

/// How long any one reply may take in these tests (the simulator runs 100x faster than real time).
pub const REPLY: Duration = Duration::from_secs(10);

pub fn config_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../config/sims")
        .join(name)
}

/// A running simulator, killed when dropped.
pub struct Sim {
    child: Child,
    stdin: Option<ChildStdin>,
    stdout: BufReader<ChildStdout>,
    /// (name, path) per machine, as announced.
    pub machines: Vec<(String, String)>,
}

impl Sim {
    /// Starts the simulator with a pipe on its standard input, for [`Sim::control`].
    pub fn start(config: &Path, time_scale: f64) -> Sim {
        Sim::launch(config, time_scale, Stdio::piped())
    }

    /// Starts the simulator with `/dev/null` as standard input, as a shell starts a background job.
    pub fn start_without_stdin(config: &Path, time_scale: f64) -> Sim {
        Sim::launch(config, time_scale, Stdio::null())
    }

    fn launch(config: &Path, time_scale: f64, stdin: Stdio) -> Sim {
        let expected = SimConfig::load(config).unwrap().machines.len();
        let mut child = Command::new(env!("CARGO_BIN_EXE_zeroset-sim"))
            .arg("--config")
            .arg(config)
            .arg("--time-scale")
            .arg(time_scale.to_string())
            .stdin(stdin)
            .stdout(Stdio::piped())
            .spawn()
            .expect("the simulator starts");
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let machines = (0..expected)
            .map(|_| {
                let mut line = String::new();
                stdout.read_line(&mut line).unwrap();
                zeroset_sim::simulator::parse_announcement(&line)
                    .unwrap_or_else(|| panic!("announcement {line:?}"))
            })
            .collect();
        Sim {
            stdin: child.stdin.take(),
            child,
            stdout,
            machines,
        }
    }

    pub fn path(&self, machine: &str) -> &str {
        &self
            .machines
            .iter()
            .find(|(name, _)| name == machine)
            .unwrap()
            .1
    }

    /// Sends a control line and waits for its answer.
    pub fn control(&mut self, line: &str) -> String {
        let stdin = self.stdin.as_mut().unwrap();
        writeln!(stdin, "{line}").unwrap();
        stdin.flush().unwrap();
        let mut answer = String::new();
        self.stdout.read_line(&mut answer).unwrap();
        answer.trim().to_owned()
    }

    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Whether the process is still running.
    pub fn running(&mut self) -> bool {
        self.child.try_wait().unwrap().is_none()
    }

    /// Sends SIGTERM and returns the exit status.
    pub fn stop(self) -> std::process::ExitStatus {
        let pid = nix::unistd::Pid::from_raw(self.pid() as i32);
        nix::sys::signal::kill(pid, nix::sys::signal::Signal::SIGTERM).unwrap();
        self.wait()
    }

    /// Waits for the simulator to end by itself.
    pub fn wait(mut self) -> std::process::ExitStatus {
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                return status;
            }
            assert!(Instant::now() < deadline, "the simulator did not stop");
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

enum Line {
    Pty(File),
    Tcp(TcpStream),
}

/// An I++ client on a blocking line: the ClientCodec over a byte buffer.
pub struct Client {
    line: Line,
    codec: ClientCodec,
    buf: BytesMut,
}

impl Client {
    /// Opens a pty slave (raw mode) or `tcp:HOST:PORT`.
    pub fn open(path: &str) -> Client {
        let line = match path.strip_prefix("tcp:") {
            Some(address) => Line::Tcp(TcpStream::connect(address).unwrap()),
            None => {
                let file = OpenOptions::new()
                    .read(true)
                    .write(true)
                    .custom_flags(nix::libc::O_NOCTTY)
                    .open(path)
                    .unwrap();
                let mut termios = tcgetattr(file.as_fd()).unwrap();
                cfmakeraw(&mut termios);
                tcsetattr(file.as_fd(), SetArg::TCSANOW, &termios).unwrap();
                Line::Pty(file)
            }
        };
        Client {
            line,
            codec: ClientCodec::default(),
            buf: BytesMut::new(),
        }
    }

    pub fn send(&mut self, line: &str) {
        let command: WireCommand = line.parse().unwrap_or_else(|e| panic!("{line}: {e}"));
        let mut out = BytesMut::new();
        self.codec.encode(&command, &mut out).unwrap();
        match &mut self.line {
            Line::Pty(file) => file.write_all(&out).unwrap(),
            Line::Tcp(stream) => stream.write_all(&out).unwrap(),
        }
    }

    /// The next decoded line, or `None` after `timeout`.
    pub fn next(&mut self, timeout: Duration) -> Option<Result<Response, LineError>> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(item) = self.codec.decode(&mut self.buf).unwrap() {
                return Some(item);
            }
            let left = deadline.checked_duration_since(Instant::now())?;
            let mut chunk = [0u8; 4096];
            let n = match &mut self.line {
                Line::Pty(file) => {
                    let millis = u16::try_from(left.as_millis().max(1)).unwrap_or(u16::MAX);
                    let mut fds = [PollFd::new(file.as_fd(), PollFlags::POLLIN)];
                    if poll(&mut fds, PollTimeout::from(millis)).unwrap() == 0 {
                        continue;
                    }
                    file.read(&mut chunk).unwrap()
                }
                Line::Tcp(stream) => {
                    stream
                        .set_read_timeout(Some(left.max(Duration::from_millis(1))))
                        .unwrap();
                    match stream.read(&mut chunk) {
                        Ok(n) => n,
                        Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => continue,
                        Err(e) if e.kind() == std::io::ErrorKind::TimedOut => continue,
                        Err(e) => panic!("{e}"),
                    }
                }
            };
            assert!(n > 0, "the simulator closed the line");
            self.buf.extend_from_slice(&chunk[..n]);
        }
    }

    /// The next valid line.
    pub fn response(&mut self, timeout: Duration) -> Option<Response> {
        self.next(timeout)
            .map(|item| item.unwrap_or_else(|e| panic!("bad line from the simulator: {e}")))
    }

    /// Sends `line` and collects every line up to its `%` (other tags' lines included).
    pub fn transact(&mut self, line: &str) -> Vec<String> {
        let tag = &line[..5];
        self.send(line);
        let mut lines = Vec::new();
        loop {
            let response = self
                .response(REPLY)
                .unwrap_or_else(|| panic!("no `%` for {line}; so far {lines:?}"));
            let text = response.to_string();
            let done = text.starts_with(tag) && matches!(response.kind(), ResponseKind::Complete);
            lines.push(text);
            if done {
                return lines;
            }
        }
    }

    /// Session, home and the 1 mm probe.
    pub fn ready(&mut self) {
        assert_eq!(
            self.transact("00001 StartSession()"),
            ["00001 &", "00001 %"]
        );
        assert_eq!(self.transact("00002 Home()"), ["00002 &", "00002 %"]);
        assert_eq!(
            self.transact("00003 ChangeTool(\"Probe1\")"),
            ["00003 &", "00003 %"]
        );
    }
}

/// The numbers of a scan's data lines.
pub fn scan_values(lines: &[String], tag: &str) -> Vec<f64> {
    lines
        .iter()
        .filter(|l| l.starts_with(&format!("{tag} # ")))
        .flat_map(|l| {
            l[8..]
                .split(", ")
                .map(|v| v.parse::<f64>().unwrap())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The propeller of a shipped config, as the simulator's own ground truth.
pub fn propeller(config: &str) -> zeroset_sim::part::propeller::Propeller {
    let config = SimConfig::load(&config_path(config)).unwrap();
    let PartSpec::Propeller(spec) = &config.parts["propeller"] else {
        panic!("not a propeller");
    };
    zeroset_sim::part::propeller::Propeller::new(spec.clone()).unwrap()
}
