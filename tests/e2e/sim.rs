//! A running simulator (`zeroset sim`, the real binary) and the station's I++ client on its pseudo-terminals.

use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};
use std::time::Duration;

use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::transport::open_pty;
use zeroset_sim::config::{PartSpec, SimConfig};
use zeroset_sim::part::propeller::{Propeller, PropellerSpec};
use zeroset_sim::simulator::parse_announcement;

use crate::support::{config, repo};

/// The simulator runs this many times faster than real time in the tests.
pub const TIME_SCALE: f64 = 100.0;

/// A simulator process, killed when dropped.
pub struct Sim {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    machines: Vec<(String, String)>,
}

impl Sim {
    /// Starts `zeroset sim` with a configuration from config/sims/ and waits for its `machine NAME PATH` lines.
    pub fn start(name: &str) -> Sim {
        Sim::launch(name, &[])
    }

    /// Like [`Sim::start`], with a link DIR/NAME to each machine's pseudo-terminal (what a station file names).
    pub fn start_linked(name: &str, link_dir: &Path) -> Sim {
        Sim::launch(name, &["--link-dir", &link_dir.display().to_string()])
    }

    fn launch(name: &str, extra: &[&str]) -> Sim {
        let path = config(&format!("sims/{name}"));
        let expected = SimConfig::load(path.as_ref())
            .expect("the config loads")
            .machines
            .len();
        let mut child = Command::new(env!("CARGO_BIN_EXE_zeroset"))
            .args([
                "sim",
                "--config",
                &path,
                "--time-scale",
                &TIME_SCALE.to_string(),
            ])
            .args(extra)
            .current_dir(repo())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .expect("zeroset sim starts");
        let stdin = child.stdin.take().expect("piped");
        let mut stdout = BufReader::new(child.stdout.take().expect("piped"));
        let machines = (0..expected)
            .map(|_| {
                let mut line = String::new();
                stdout.read_line(&mut line).expect("a line");
                parse_announcement(&line).unwrap_or_else(|| panic!("unexpected: {line:?}"))
            })
            .collect();
        Sim {
            child,
            stdin,
            stdout,
            machines,
        }
    }

    /// The names of the simulated machines, in the configuration's order.
    pub fn machines(&self) -> Vec<String> {
        self.machines.iter().map(|(name, _)| name.clone()).collect()
    }

    pub fn path(&self, machine: &str) -> &str {
        &self
            .machines
            .iter()
            .find(|(name, _)| name == machine)
            .expect("a configured machine")
            .1
    }

    /// Sends a control line (e.g. `fault cmm1 estop`) and returns the simulator's answer.
    pub fn control(&mut self, line: &str) -> String {
        writeln!(self.stdin, "{line}").expect("the simulator reads its stdin");
        let mut answer = String::new();
        self.stdout.read_line(&mut answer).expect("an answer");
        answer.trim().to_string()
    }

    /// Kills the simulator (as a controller switched off): its lines close, its links are left dangling.
    pub fn kill(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }

    /// The transcript of a machine's line (the simulator's default: zeroset-sim-MACHINE-PID.log in the temp dir).
    pub fn transcript(&self, machine: &str) -> std::path::PathBuf {
        std::env::temp_dir().join(format!("zeroset-sim-{machine}-{}.log", self.child.id()))
    }

    /// The station's client on a machine's pseudo-terminal.
    pub fn client(&self, machine: &str, config: ClientConfig) -> Client {
        let port = open_pty(self.path(machine)).expect("the pty opens");
        Client::new(machine, port, config)
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Timeouts short enough for tests, long enough for the simulator at TIME_SCALE.
pub fn quick() -> ClientConfig {
    ClientConfig {
        ack_timeout: Duration::from_secs(5),
        reply_timeout: Duration::from_secs(10),
    }
}

/// The simulator's own analytic propeller, for checking what the probe reported.
pub fn propeller() -> Propeller {
    Propeller::new(propeller_spec("propeller.toml")).expect("a valid propeller")
}

/// The propeller of config/sims/`sim_config` as configured, errors and all.
pub fn propeller_spec(sim_config: &str) -> PropellerSpec {
    let loaded =
        SimConfig::load(config(&format!("sims/{sim_config}")).as_ref()).expect("the config loads");
    let PartSpec::Propeller(spec) = &loaded.parts["propeller"] else {
        panic!("{sim_config} holds a propeller");
    };
    spec.clone()
}
