//! A whole station for a test: the simulator (`zeroset sim`) with its machines linked into a temporary folder, a
//! station file pointing at them, and the real daemon (`zeroset daemon`) on its own socket; the CLI commands run
//! as the real binary against it.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Stdio};
use std::sync::{mpsc, OnceLock};
use std::time::{Duration, Instant};

use zeroset::api::{parse_line, Event, EventLine};
use zeroset::report::PartReport;

use crate::sim::Sim;
use crate::support::{config, repo, zeroset, Run};

pub struct Station {
    pub sim: Sim,
    pub root: tempfile::TempDir,
    pub station_file: PathBuf,
    daemon: Option<Child>,
    daemons_started: usize,
    /// The daemon's log filter (`ZEROSET_LOG`), when not its default.
    log_filter: Option<&'static str>,
}

impl Station {
    /// The simulator of config/sims/`sim_config` and a daemon driving all its machines, set up as
    /// config/station.toml (the propeller's station).
    pub fn start(sim_config: &str) -> Station {
        Station::start_as(sim_config, "station.toml")
    }

    /// The simulator of config/sims/`sim_config` and a daemon set up as config/`station_config`, its machines
    /// those of the simulator.
    pub fn start_as(sim_config: &str, station_config: &str) -> Station {
        Station::start_edited(sim_config, station_config, |_| {})
    }

    /// Like [`Station::start_as`], with the station file changed by `edit` before the daemon reads it (e.g.
    /// shorter timeouts).
    pub fn start_edited(
        sim_config: &str,
        station_config: &str,
        edit: impl FnOnce(&mut toml::Table),
    ) -> Station {
        let root = tempfile::tempdir().expect("a temporary folder");
        let ports = root.path().join("ports");
        let sim = Sim::start_linked(sim_config, &ports);
        let text = zeroset::cli::demo::station_for_simulator(
            Path::new(&config(station_config)),
            &sim.machines(),
            &ports,
            root.path(),
        )
        .expect("a station file");
        let mut table: toml::Table = toml::from_str(&text).expect("the station file is TOML");
        edit(&mut table);
        let text = toml::to_string(&table).expect("TOML");
        let station_file = root.path().join("station.toml");
        std::fs::write(&station_file, text).expect("the station file is written");
        let mut station = Station {
            sim,
            root,
            station_file,
            daemon: None,
            daemons_started: 0,
            log_filter: None,
        };
        station.start_daemon();
        station
    }

    /// The propeller's station, taught, whose client gives up on a silent line after `seconds` (the default waits
    /// minutes for homing): a lost line stops the job soon enough for a test.
    pub fn quick(seconds: f64) -> Station {
        Station::start_edited("propeller.toml", "station.toml", |table| {
            let machines = table["machines"].as_array_mut().unwrap();
            for machine in machines {
                let machine = machine.as_table_mut().unwrap();
                machine.insert("ack_timeout_s".into(), seconds.into());
                machine.insert("reply_timeout_s".into(), seconds.into());
            }
        })
        .with_taught_reference()
    }

    /// How the daemon ended if it is no longer running of its own accord (a crash), with the end of what it
    /// wrote on its standard error; None while it runs (or after [`Station::kill_daemon`]).
    pub fn daemon_ended(&mut self) -> Option<String> {
        let status = self.daemon.as_mut()?.try_wait().ok().flatten()?;
        self.daemon = None;
        let log = self
            .root
            .path()
            .join(format!("daemon-{}.stderr", self.daemons_started));
        let text = std::fs::read_to_string(log).unwrap_or_default();
        let tail: Vec<&str> = text.lines().rev().take(5).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        Some(format!("{status}: {}", tail.join(" | ")))
    }

    pub fn start_daemon(&mut self) {
        self.daemons_started += 1;
        let log = std::fs::File::create(
            self.root
                .path()
                .join(format!("daemon-{}.stderr", self.daemons_started)),
        )
        .expect("a log file");
        let mut command = Command::new(env!("CARGO_BIN_EXE_zeroset"));
        command
            .args(["daemon", "--config"])
            .arg(&self.station_file)
            .current_dir(repo())
            .stderr(log);
        if let Some(filter) = self.log_filter {
            command.env("ZEROSET_LOG", filter);
        }
        let child = command.spawn().expect("the daemon starts");
        self.daemon = Some(child);
        zeroset::cli::demo::wait_for_socket(&self.socket()).expect("the daemon starts serving");
    }

    /// Gives this station the propeller's reference, taught once for all the tests that only inspect (teaching
    /// is the slow part; the simulated propeller is the same in every simulator).
    pub fn with_taught_reference(self) -> Station {
        static TAUGHT: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
        let (_, taught) = TAUGHT.get_or_init(|| {
            let teacher = Station::start("propeller.toml");
            let out = teacher.cli_ok(&["teach", "propeller"]);
            assert!(out.contains("reference saved"), "{out}");
            let keep = tempfile::tempdir().expect("a temporary folder");
            let file = keep.path().join("propeller.json");
            std::fs::copy(teacher.reference(), &file).expect("the reference is copied");
            (keep, file)
        });
        std::fs::create_dir_all(self.data().join("references")).expect("a references folder");
        std::fs::copy(taught, self.reference()).expect("the reference is copied");
        self
    }

    pub fn reference(&self) -> PathBuf {
        self.reference_of("propeller")
    }

    pub fn reference_of(&self, part: &str) -> PathBuf {
        self.data().join("references").join(format!("{part}.json"))
    }

    /// `kill -9`: no chance to tidy up.
    /// From now on (the daemon restarted at once), the daemon logs every line it sends and reads, to
    /// [`Station::daemon_log`].
    pub fn log_wire(&mut self) {
        self.log_filter = Some("info,zeroset_drivers::client::actor=debug");
        self.kill_daemon();
        self.start_daemon();
    }

    /// The daemon's JSON log.
    pub fn daemon_log(&self) -> PathBuf {
        self.root.path().join("logs/zeroset-daemon.jsonl")
    }

    pub fn kill_daemon(&mut self) {
        let mut child = self.daemon.take().expect("a running daemon");
        child.kill().expect("SIGKILL");
        child.wait().expect("reaped");
    }

    pub fn socket(&self) -> PathBuf {
        self.root.path().join("zeroset.sock")
    }

    pub fn reports(&self) -> PathBuf {
        self.root.path().join("reports")
    }

    pub fn data(&self) -> PathBuf {
        self.root.path().join("data")
    }

    /// Runs `zeroset COMMAND ARGS --config STATION`.
    pub fn cli(&self, args: &[&str]) -> Run {
        let mut all: Vec<&str> = args.to_vec();
        let file = self.station_file.display().to_string();
        all.extend(["--config", &file]);
        zeroset(&all)
    }

    pub fn cli_ok(&self, args: &[&str]) -> String {
        let run = self.cli(args);
        assert!(
            run.success,
            "zeroset {args:?} failed:\n{}\n{}",
            run.stdout, run.stderr
        );
        run.stdout
    }

    /// Runs an inspection to its end, whatever the part's verdict: exit code 0 (within tolerance) or 4 (outside:
    /// the simulated propeller's blades B and C are); what it printed.
    pub fn inspected(&self, args: &[&str]) -> String {
        let run = self.cli(args);
        assert!(
            matches!(run.code, Some(0 | 4)),
            "zeroset {args:?} exited {:?}:\n{}\n{}",
            run.code,
            run.stdout,
            run.stderr
        );
        run.stdout
    }

    /// `zeroset ARGS --config STATION` in the background, its standard output and error piped.
    pub fn spawn(&self, args: &[&str]) -> Child {
        self.spawn_with_stdout(args, Stdio::piped())
    }

    /// `zeroset ARGS --config STATION` in the background writing to `stdout`, its standard error piped.
    pub fn spawn_with_stdout(&self, args: &[&str], stdout: Stdio) -> Child {
        Command::new(env!("CARGO_BIN_EXE_zeroset"))
            .args(args)
            .arg("--config")
            .arg(&self.station_file)
            .current_dir(repo())
            .stdout(stdout)
            .stderr(Stdio::piped())
            .spawn()
            .expect("zeroset starts")
    }

    /// `zeroset watch --events --follow` in the background; its events arrive on the receiver.
    pub fn watch(&self) -> Watcher {
        let mut child = Command::new(env!("CARGO_BIN_EXE_zeroset"))
            .args(["watch", "--events", "--follow", "--config"])
            .arg(&self.station_file)
            .current_dir(repo())
            .stdout(Stdio::piped())
            // A watcher says so when its daemon is killed, as some tests do on purpose.
            .stderr(Stdio::null())
            .spawn()
            .expect("zeroset watch starts");
        let stdout = child.stdout.take().expect("piped");
        let (lines, receiver) = mpsc::channel();
        std::thread::spawn(move || forward(stdout, lines));
        let watcher = Watcher {
            child,
            events: receiver,
            seen: Vec::new(),
        };
        // `watch` prints nothing before it subscribes; give it a moment so no early event is missed.
        std::thread::sleep(Duration::from_millis(300));
        watcher
    }

    /// The report of the newest inspection of the propeller `serial`.
    pub fn report(&self, serial: &str) -> (PathBuf, PartReport) {
        self.report_of("propeller", serial)
    }

    /// The report of the newest inspection of `part` `serial`.
    pub fn report_of(&self, part: &str, serial: &str) -> (PathBuf, PartReport) {
        let dir = std::fs::read_dir(self.reports().join(part).join(serial))
            .expect("a report folder for the serial")
            .map(|e| e.unwrap().path())
            .max()
            .expect("one report");
        let report = zeroset::report::read_report(&dir).expect("the report reads");
        (dir, report)
    }
}

impl Drop for Station {
    fn drop(&mut self) {
        if let Some(mut child) = self.daemon.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

fn forward(stdout: ChildStdout, lines: mpsc::Sender<String>) {
    for line in BufReader::new(stdout).lines() {
        let Ok(line) = line else { return };
        if lines.send(line).is_err() {
            return;
        }
    }
}

/// A running `zeroset watch --events`.
pub struct Watcher {
    child: Child,
    events: mpsc::Receiver<String>,
    /// Every line received so far.
    pub seen: Vec<String>,
}

impl Watcher {
    /// Waits for the first event that `wanted` accepts (seconds at most), keeping every line seen.
    pub fn until(&mut self, seconds: u64, mut wanted: impl FnMut(&Event) -> bool) -> Event {
        let deadline = Instant::now() + Duration::from_secs(seconds);
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let line = self.events.recv_timeout(left).unwrap_or_else(|_| {
                panic!("no such event within {seconds} s; saw:\n{}", self.tail())
            });
            self.seen.push(line.clone());
            let event = parse_line::<EventLine>(&line).expect("an event line").event;
            if wanted(&event) {
                return event;
            }
        }
    }

    /// The next event (kept in `seen`), or why none came: the time ran out, or the daemon went away.
    pub fn next(&mut self, timeout: Duration) -> Result<Event, mpsc::RecvTimeoutError> {
        let line = self.events.recv_timeout(timeout)?;
        self.seen.push(line.clone());
        Ok(parse_line::<EventLine>(&line).expect("an event line").event)
    }

    pub fn events(&self) -> Vec<Event> {
        self.seen
            .iter()
            .map(|l| parse_line::<EventLine>(l).expect("an event line").event)
            .collect()
    }

    fn tail(&self) -> String {
        let start = self.seen.len().saturating_sub(10);
        self.seen[start..].join("\n")
    }
}

impl Drop for Watcher {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The most, in seconds, a wait for the rest of a job may take: a whole inspection of the simulated propeller takes
/// about 25 s on an idle 2-core machine and over 30 s beside the rest of the suite. A bound against a hang, not a
/// timing test: the times the station promises are benched (BENCHMARKS.md).
pub const A_JOB_S: u64 = 180;

/// Whether an event ends a job.
pub fn job_over(event: &Event) -> bool {
    matches!(
        event,
        Event::ReferenceSaved { .. }
            | Event::JobFinished { .. }
            | Event::JobAborted { .. }
            | Event::JobFailed { .. }
    )
}
