//! What `zeroset status` says of an idle machine is what the machine is: the daemon watches each machine while no
//! job runs, so an emergency stop, a lost line or a missing port shows at once, with what to do, and a single
//! `zeroset clear` opens the line again and clears the machine.

use std::time::{Duration, Instant};

use crate::daemon::Station;
use crate::sim::Sim;

/// Waits up to `seconds` for `zeroset status` to contain `wanted`; returns the last status. The watch looks every
/// second; the generous bound is for a CI machine running every test at once.
fn status_until(station: &Station, seconds: u64, wanted: &str) -> String {
    let deadline = Instant::now() + Duration::from_secs(seconds);
    loop {
        let status = station.cli_ok(&["status"]);
        if status.contains(wanted) || Instant::now() > deadline {
            return status;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn an_emergency_stop_and_a_lost_simulator_show_in_status_and_one_clear_recovers_each() {
    let mut station = Station::start("propeller.toml");
    let status = status_until(&station, 10, "machine cmm1: idle");
    assert!(status.contains("machine cmm1: idle"), "{status}");

    // An emergency stop pressed while no job runs.
    assert_eq!(
        station.sim.control("fault cmm1 estop"),
        "ok fault cmm1 estop"
    );
    let status = status_until(&station, 30, "emergency stop");
    assert!(
        status.contains("machine cmm1: locked out (emergency stop)")
            && status.contains("while idle")
            && status.contains("zeroset clear"),
        "{status}"
    );
    let cleared = station.cli_ok(&["clear"]);
    assert!(cleared.contains("machines clear"), "{cleared}");
    assert!(
        station.cli_ok(&["status"]).contains("machine cmm1: idle"),
        "cleared"
    );

    // The controller goes away: its line closes under the idle daemon.
    station.sim.kill();
    let status = status_until(&station, 30, "locked out (disconnected)");
    assert!(
        status.contains("machine cmm1: locked out (disconnected)")
            && status.contains("its line was lost while idle"),
        "{status}"
    );
    let refused = station.cli(&["clear"]);
    assert!(
        !refused.success && refused.stderr.contains("cmm1"),
        "no machine to clear: {}",
        refused.stderr
    );
    // It comes back on the same port: one clear is enough.
    station.sim = Sim::start_linked("propeller.toml", &station.root.path().join("ports"));
    let cleared = station.cli_ok(&["clear"]);
    assert!(cleared.contains("machines clear"), "{cleared}");
    assert!(
        station.cli_ok(&["status"]).contains("machine cmm1: idle"),
        "cleared"
    );

    // The log an operator reads: each command and its outcome, the faults seen, and no terminal colour codes in
    // a log file.
    let log = std::fs::read_to_string(station.daemon_log()).unwrap();
    let lines: Vec<serde_json::Value> = log
        .lines()
        .map(|line| serde_json::from_str(line).expect("one JSON object per line"))
        .collect();
    let said = |message: &str, command: &str| {
        lines
            .iter()
            .filter(|l| l["fields"]["message"] == message && l["fields"]["command"] == command)
            .count()
    };
    assert_eq!(said("operator command", "clear"), 3, "{log}");
    assert_eq!(said("operator command done", "clear"), 2, "{log}");
    assert_eq!(said("operator command refused", "clear"), 1, "{log}");
    assert!(
        lines
            .iter()
            .any(|l| l["fields"]["message"] == "machine fault while idle"
                && l["fields"]["kind"] == "emergency stop"),
        "{log}"
    );
    let stderr = std::fs::read_to_string(station.root.path().join("daemon-1.stderr")).unwrap();
    assert!(
        !stderr.contains('\x1b'),
        "no ANSI codes in a log file: {stderr}"
    );
    assert!(stderr.contains("operator command"), "{stderr}");
}

#[test]
fn a_port_that_does_not_exist_shows_in_status_before_any_job() {
    let station = Station::start_edited("propeller.toml", "station.toml", |table| {
        let machines = table["machines"].as_array_mut().unwrap();
        machines[0]
            .as_table_mut()
            .unwrap()
            .insert("port".into(), "/dev/ttyUSB7-not-here".into());
    });
    let status = status_until(&station, 30, "port missing");
    assert!(
        status.contains("machine cmm1: locked out (port missing)")
            && status.contains("/dev/ttyUSB7-not-here"),
        "{status}"
    );
    let refused = station.cli(&["teach", "propeller"]);
    assert!(
        !refused.success
            && refused.stderr.contains("cmm1")
            && refused.stderr.contains("zeroset clear"),
        "{}",
        refused.stderr
    );
}
