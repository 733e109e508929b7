//! The lines themselves: reconnecting to a pty, two machines at once, loopback TCP with baud-rate pacing,
//! the transcript, and configuration errors.

mod common;

use std::process::Command;
use std::time::{Duration, Instant};

use common::{config_path, Client, Sim};

#[test]
fn a_client_can_close_the_pty_and_reopen_it() {
    let sim = Sim::start(&config_path("propeller.toml"), 100.0);
    let path = sim.path("cmm1").to_owned();
    let mut first = Client::open(&path);
    first.ready();
    drop(first);
    std::thread::sleep(Duration::from_millis(50));
    let mut second = Client::open(&path);
    // Closing the line ended the session, as closing a TCP connection does; the machine stays homed.
    let outside = second.transact("00004 IsHomed()");
    assert!(outside[1].contains("0008"), "{outside:?}");
    assert_eq!(
        second.transact("00005 StartSession()"),
        ["00005 &", "00005 %"]
    );
    assert_eq!(second.transact("00006 IsHomed()")[1], "00006 # IsHomed(1)");
    drop(second);
    // A close and reopen quicker than the simulator looks is indistinguishable from an open line (a pty
    // master only sees the slave's state when it polls); a client that reconnects sooner and wants a
    // fresh session sends EndSession before StartSession, as spec 6.3.1 provides.
    std::thread::sleep(Duration::from_millis(50));
    let mut third = Client::open(&path);
    assert_eq!(
        third.transact("00007 StartSession()"),
        ["00007 &", "00007 %"]
    );
}

#[test]
fn two_machines_serve_two_ptys_independently() {
    let sim = Sim::start(&config_path("two-machines.toml"), 100.0);
    let names: Vec<&str> = sim.machines.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["cmm1", "cmm2"]);
    assert_ne!(sim.path("cmm1"), sim.path("cmm2"));
    let mut one = Client::open(sim.path("cmm1"));
    let mut two = Client::open(sim.path("cmm2"));
    one.transact("00001 StartSession()");
    two.transact("00001 StartSession()");
    // Both move at once: each machine has its own task and its own clock of motion.
    one.send("00002 Home()");
    two.send("00002 GoTo(X(10))");
    let homed: Vec<String> = (0..2)
        .map(|_| one.response(common::REPLY).unwrap().to_string())
        .collect();
    assert_eq!(homed, ["00002 &", "00002 %"]);
    let refused: Vec<String> = (0..3)
        .map(|_| two.response(common::REPLY).unwrap().to_string())
        .collect();
    assert!(
        refused[1].contains("0507"),
        "cmm2 is not homed: {refused:?}"
    );
    assert_eq!(one.transact("00003 IsHomed()")[1], "00003 # IsHomed(1)");
}

#[test]
fn tcp_on_loopback_with_baud_rate_pacing_and_a_transcript() {
    let dir = tempfile::tempdir().unwrap();
    let transcript = dir.path().join("cmm1.log");
    let text = std::fs::read_to_string(config_path("propeller.toml"))
        .unwrap()
        .replace(
            "port = \"pty\"",
            &format!(
                "port = \"tcp\"\ntcp_port = 0\nbaud = 9600\ntranscript = {:?}",
                transcript
            ),
        );
    let config = dir.path().join("tcp.toml");
    std::fs::write(&config, text).unwrap();
    let sim = Sim::start(&config, 1.0);
    let address = sim.path("cmm1").to_owned();
    assert!(address.starts_with("tcp:127.0.0.1:"), "{address}");
    let mut client = Client::open(&address);
    client.transact("00001 StartSession()");
    let sent = Instant::now();
    let reply = client.transact("00002 GetDMEVersion()");
    // 9 + 31 + 9 bytes at 10 bits per byte and 9600 baud: 51 ms.
    assert!(
        sent.elapsed() >= Duration::from_millis(45),
        "{:?}",
        sent.elapsed()
    );
    assert_eq!(reply[1], "00002 # DMEVersion(\"1.4.3\")");
    drop(client);
    assert!(sim.stop().success());
    let log = std::fs::read_to_string(&transcript).unwrap();
    assert!(log.contains(" < 00002 GetDMEVersion()"), "{log}");
    assert!(log.contains(" > 00002 # DMEVersion(\"1.4.3\")"), "{log}");
}

#[test]
fn configuration_errors_name_the_key_and_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(config_path("propeller.toml"))
        .unwrap()
        .replace("seed = 1", "seed = 1\nspeed_of_light = 3");
    std::fs::write(&config, text).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_zeroset-sim"))
        .arg("--config")
        .arg(&config)
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("speed_of_light") && stderr.contains("bad.toml"),
        "{stderr}"
    );
    assert!(output.stdout.is_empty(), "no machine announced");
}

#[test]
fn sigterm_stops_the_simulator() {
    let sim = Sim::start(&config_path("propeller.toml"), 100.0);
    assert!(sim.stop().success());
}

#[test]
fn the_simulator_keeps_serving_without_standard_input() {
    // `zeroset sim ... &` in a script: standard input is /dev/null, read to its end at once.
    let mut sim = Sim::start_without_stdin(&config_path("propeller.toml"), 100.0);
    std::thread::sleep(Duration::from_millis(500));
    assert!(
        sim.running(),
        "the simulator exited at the end of its stdin"
    );
    let mut client = Client::open(sim.path("cmm1"));
    client.ready();
    assert_eq!(
        client.transact("00004 GetDMEVersion()")[1],
        "00004 # DMEVersion(\"1.4.3\")"
    );
    drop(client);
    assert!(sim.running());
    assert!(sim.stop().success());
}
