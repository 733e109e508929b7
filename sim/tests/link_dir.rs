//! `--link-dir`: the real binary links DIR/NAME to each machine's pseudo-terminal before it announces it, the
//! station's own client talks I++ over the link, and the links go when the simulator stops.

mod common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::Duration;

use common::config_path;
use nix::sys::signal::{kill, Signal};
use nix::unistd::Pid;
use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::machine::Machine;
use zeroset_drivers::transport::open_pty;
use zeroset_sim::config::SimConfig;
use zeroset_sim::simulator::parse_announcement;

/// The simulator process, killed if the test fails before it stops it.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The station's client on the pty behind `link`, through one session.
async fn session_over(link: &Path, machine: &str) {
    let port = open_pty(link.to_str().unwrap()).expect("the link opens as a pty");
    let config = ClientConfig {
        ack_timeout: Duration::from_secs(5),
        reply_timeout: Duration::from_secs(10),
    };
    let client = Client::new(machine, port, config);
    client
        .start_session()
        .await
        .expect("StartSession over the link");
    client
        .end_session()
        .await
        .expect("EndSession over the link");
}

/// Starts the simulator on `config` with `--link-dir ports`; returns it with its announced machines.
fn start(config: &str, ports: &Path) -> (Running, Vec<(String, String)>) {
    let expected = SimConfig::load(&config_path(config))
        .unwrap()
        .machines
        .len();
    let child = Command::new(env!("CARGO_BIN_EXE_zeroset-sim"))
        .arg("--config")
        .arg(config_path(config))
        .args(["--time-scale", "100", "--link-dir"])
        .arg(ports)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the simulator starts");
    let mut sim = Running(child);
    let mut stdout = BufReader::new(sim.0.stdout.take().unwrap());
    let announced = (0..expected)
        .map(|_| {
            let mut line = String::new();
            stdout.read_line(&mut line).unwrap();
            parse_announcement(&line).unwrap_or_else(|| panic!("announcement {line:?}"))
        })
        .collect();
    (sim, announced)
}

#[tokio::test(flavor = "current_thread")]
async fn machines_are_reached_through_their_links_which_go_when_the_simulator_stops() {
    let dir = tempfile::tempdir().unwrap();
    // cmm1's link is one a killed simulator left behind; cmm2 has none yet.
    let ports = dir.path().join("ports");
    std::fs::create_dir(&ports).unwrap();
    std::os::unix::fs::symlink("/dev/pts/no-such-terminal", ports.join("cmm1")).unwrap();

    let (mut sim, announced) = start("two-machines.toml", &ports);
    assert_eq!(announced.len(), 2);
    for (machine, pty) in &announced {
        assert!(
            pty.starts_with("/dev/pts/"),
            "the announcement gives the real path: {pty}"
        );
        let link = ports.join(machine);
        assert_eq!(
            std::fs::read_link(&link).unwrap(),
            PathBuf::from(pty),
            "{machine}'s link, made before the announcement"
        );
        session_over(&link, machine).await;
    }

    // The end of its standard input does not stop the simulator; SIGTERM does, and removes the links.
    let pid = Pid::from_raw(i32::try_from(sim.0.id()).unwrap());
    kill(pid, Signal::SIGTERM).unwrap();
    let status = sim.0.wait().unwrap();
    assert!(status.success(), "{status}");
    for (machine, _) in &announced {
        assert!(
            std::fs::symlink_metadata(ports.join(machine)).is_err(),
            "{machine}'s link is removed on exit"
        );
    }
}

#[test]
fn the_folder_is_made_and_sigterm_removes_the_link() {
    let dir = tempfile::tempdir().unwrap();
    let ports = dir.path().join("run/zeroset");
    let (mut sim, announced) = start("nut.toml", &ports);
    let link = ports.join(&announced[0].0);
    assert_eq!(
        std::fs::read_link(&link).unwrap(),
        PathBuf::from(&announced[0].1)
    );
    let pid = Pid::from_raw(i32::try_from(sim.0.id()).unwrap());
    kill(pid, Signal::SIGTERM).unwrap();
    let status = sim.0.wait().unwrap();
    assert!(status.success(), "{status}");
    assert!(
        std::fs::symlink_metadata(&link).is_err(),
        "the link is removed on SIGTERM"
    );
}
