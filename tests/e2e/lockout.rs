//! Only an operator's `zeroset clear` lifts a lockout: after an emergency stop, a collision, a lost line or a
//! machine's alarm, `zeroset abort` ends the job without clearing or moving the machine, no new job starts, and
//! the simulator's transcript (what the machine received) holds no motion and no ClearAllErrors from the fault to
//! the clear. After the clear the station works again.

use std::path::Path;
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use zeroset::api::Event;

use crate::daemon::{job_over, Station, A_JOB_S};

/// Commands that move the probe or lift a lockout.
const MOTION_OR_CLEAR: [&str; 7] = [
    "GoTo(",
    "PtMeas(",
    "ScanOnCurve(",
    "ScanInPlaneEndIsSphere(",
    "Home(",
    "ChangeTool(",
    "ClearAllErrors(",
];

fn now_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap()
        .as_secs_f64()
}

/// The transcript's entries: seconds since the epoch, direction (`<` received, `>` sent, `#` event), text.
fn transcript_entries(transcript: &Path) -> Vec<(f64, char, String)> {
    let text = std::fs::read_to_string(transcript).expect("the simulator's transcript");
    text.lines()
        .filter_map(|line| {
            let (time, rest) = line.split_once(' ')?;
            let mut chars = rest.chars();
            let direction = chars.next()?;
            Some((
                time.parse().ok()?,
                direction,
                chars.as_str().trim_start().to_string(),
            ))
        })
        .collect()
}

/// When the machine stopped after `from`: its first error line (an E-stop's `E0000 !`, a collision's or a
/// failed scan's `!`), or its line going dead.
fn stopped_at(entries: &[(f64, char, String)], from: f64) -> f64 {
    entries
        .iter()
        .find(|(time, direction, text)| {
            *time >= from
                && ((*direction == '>' && text.contains("! Error("))
                    || (*direction == '#' && text.contains("fault Disconnect")))
        })
        .map(|(time, _, _)| *time)
        .expect("the machine stopped")
}

/// A station whose client gives up on a silent line after 3 s (the default waits minutes for homing).
pub fn station() -> Station {
    Station::start_edited("propeller.toml", "station.toml", |table| {
        let machines = table["machines"].as_array_mut().unwrap();
        for machine in machines {
            let machine = machine.as_table_mut().unwrap();
            machine.insert("ack_timeout_s".into(), 3.0.into());
            machine.insert("reply_timeout_s".into(), 3.0.into());
        }
    })
    .with_taught_reference()
}

#[test]
fn after_a_fault_abort_moves_nothing_and_only_clear_lifts_the_lockout() {
    let mut station = station();
    let transcript = station.sim.transcript("cmm1");
    assert!(transcript.is_file(), "{transcript:?}");
    // Faults that stop the machine during a scan (E-stop, lost line, alarm) and at the move after it (collision).
    for (serial, fault) in [
        ("SN-L1", "estop"),
        ("SN-L2", "collision"),
        ("SN-L3", "disconnect 500"),
        ("SN-L4", "surface-not-found"),
    ] {
        let mut watcher = station.watch();
        station.cli_ok(&["inspect", "propeller", "--serial", serial, "--detach"]);
        watcher.until(30, |e| matches!(e, Event::Point { index: 20, .. }));
        let faulted_at = now_s();
        let answer = station.sim.control(&format!("fault cmm1 {fault}"));
        assert_eq!(answer, format!("ok fault cmm1 {fault}"));
        let stopped = watcher.until(30, |e| matches!(e, Event::JobStopped { .. }));
        let Event::JobStopped { reason, .. } = &stopped else {
            unreachable!()
        };
        let aborted = station.cli_ok(&["abort"]);
        assert!(
            aborted.contains("aborted") && aborted.contains("zeroset clear"),
            "{fault}: {aborted}"
        );
        watcher.until(5, |e| matches!(e, Event::JobAborted { .. }));
        std::thread::sleep(Duration::from_millis(1500));
        let status = station.cli_ok(&["status"]);
        assert!(
            status.contains("machine cmm1: locked out") && status.contains("aborted"),
            "{fault}: {status}"
        );
        let refused = station.cli(&["inspect", "propeller", "--serial", "SN-NEVER", "--detach"]);
        assert!(
            !refused.success && refused.stderr.contains("zeroset clear"),
            "{fault}: {}",
            refused.stderr
        );
        let cleared_at = now_s();
        let entries = transcript_entries(&transcript);
        let stop = stopped_at(&entries, faulted_at);
        let moved: Vec<&String> = entries
            .iter()
            .filter(|(time, direction, text)| {
                stop <= *time
                    && *time <= cleared_at
                    && *direction == '<'
                    && MOTION_OR_CLEAR.iter().any(|m| text.contains(m))
            })
            .map(|(_, _, text)| text)
            .collect();
        assert!(
            moved.is_empty(),
            "{fault} ({reason}): the machine received before `zeroset clear`: {moved:?}"
        );
        let cleared = station.cli_ok(&["clear"]);
        assert!(cleared.contains("machines clear"), "{fault}: {cleared}");
        let status = station.cli_ok(&["status"]);
        assert!(status.contains("machine cmm1: idle"), "{fault}: {status}");
        drop(watcher);
    }
    // The station works again: a whole inspection to its report.
    let mut watcher = station.watch();
    station.cli_ok(&["inspect", "propeller", "--serial", "SN-L5", "--detach"]);
    let end = watcher.until(A_JOB_S, job_over);
    assert!(matches!(end, Event::JobFinished { .. }), "{end:?}");
    station.kill_daemon();
}

#[test]
fn an_emergency_stop_anywhere_in_a_teach_scan_is_cleared_without_a_collision_and_the_teach_finishes(
) {
    // The way out is planned from where the probe stopped, past the last points the machine reported, not from
    // those points: it must never drive the ball into the blade (the simulator answers such a move with 2504).
    let mut station = station();
    let mut watcher = station.watch();
    station.cli_ok(&["teach", "propeller", "--detach"]);
    let mut stops = 0;
    // Stops early, midway and late in different profiles' scans: on the upper surface, round the edges, below.
    for index in [35, 170, 300] {
        watcher.until(
            120,
            |e| matches!(e, Event::Point { index: i, .. } if *i == index),
        );
        assert_eq!(
            station.sim.control("fault cmm1 estop"),
            "ok fault cmm1 estop"
        );
        watcher.until(30, |e| matches!(e, Event::JobStopped { .. }));
        let cleared = station.cli(&["clear"]);
        assert!(
            cleared.success && cleared.stdout.contains("continues"),
            "stop {index}: {}{}",
            cleared.stdout,
            cleared.stderr
        );
        stops += 1;
    }
    let end = watcher.until(240, job_over);
    assert!(matches!(end, Event::ReferenceSaved { .. }), "{end:?}");
    let transcript = std::fs::read_to_string(station.sim.transcript("cmm1")).unwrap();
    let collisions: Vec<&str> = transcript
        .lines()
        .filter(|l| l.contains("! Error(") && l.contains(", 2504,"))
        .collect();
    assert!(
        collisions.is_empty(),
        "a way out collided with the blade: {collisions:?}"
    );
    assert_eq!(stops, 3);
}

#[test]
fn a_clearance_height_inside_the_part_is_refused_before_anything_moves() {
    let station = Station::start_edited("propeller.toml", "station.toml", |table| {
        let safety = table["safety"].as_table_mut().unwrap();
        safety.insert("clearance_z_mm".into(), 10.0.into());
    });
    let run = station.cli(&["teach", "propeller"]);
    assert!(
        !run.success && run.stderr.contains("clearance_z_mm"),
        "{}{}",
        run.stdout,
        run.stderr
    );
    let sent = std::fs::read_to_string(station.sim.transcript("cmm1")).unwrap_or_default();
    assert!(
        !MOTION_OR_CLEAR.iter().any(|m| sent.contains(m)),
        "the machine was moved:\n{sent}"
    );
}
