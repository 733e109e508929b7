//! What the operator, a script or a PLC sees: exit codes that tell pass from fail, abort and stop; every error once;
//! a closed pipe ending a command quietly; `watch` saying when there is no job; the exit codes documented.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::Child;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use zeroset::api::Event;

use crate::daemon::{job_over, Station, A_JOB_S};
use crate::support::{propeller_part_edited, repo, zeroset};

/// A command running in the background: its output lines as they come, its exit code at the end.
struct Background {
    child: Child,
    lines: mpsc::Receiver<String>,
    seen: Vec<String>,
    stderr: std::thread::JoinHandle<String>,
}

impl Background {
    fn new(mut child: Child) -> Background {
        let stdout = child.stdout.take().expect("piped");
        let mut stderr = child.stderr.take().expect("piped");
        let (send, lines) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { return };
                if send.send(line).is_err() {
                    return;
                }
            }
        });
        let stderr = std::thread::spawn(move || {
            let mut text = String::new();
            let _ = stderr.read_to_string(&mut text);
            text
        });
        Background {
            child,
            lines,
            seen: Vec::new(),
            stderr,
        }
    }

    /// Waits (seconds at most) for an output line containing `text`.
    fn until_line(&mut self, seconds: u64, text: &str) {
        let deadline = Instant::now() + Duration::from_secs(seconds);
        while !self.seen.iter().any(|l| l.contains(text)) {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.lines.recv_timeout(left) {
                Ok(line) => self.seen.push(line),
                Err(_) => panic!(
                    "no line {text:?} within {seconds} s; saw:\n{}",
                    self.seen.join("\n")
                ),
            }
        }
    }

    /// Waits (seconds at most) for the command's end: its exit code, all it wrote on stdout and on stderr.
    fn end(mut self, seconds: u64) -> (Option<i32>, String, String) {
        let deadline = Instant::now() + Duration::from_secs(seconds);
        let status = loop {
            if let Some(status) = self.child.try_wait().expect("waits") {
                break status;
            }
            if Instant::now() > deadline {
                let _ = self.child.kill();
                panic!(
                    "still running after {seconds} s; saw:\n{}",
                    self.seen.join("\n")
                );
            }
            std::thread::sleep(Duration::from_millis(50));
        };
        self.seen.extend(self.lines.iter());
        let stderr = self.stderr.join().expect("stderr read");
        (status.code(), self.seen.join("\n"), stderr)
    }
}

/// Runs `zeroset ARGS` with its standard output already closed (what `| head` leaves once it has its lines):
/// the exit code and what it wrote on standard error.
fn with_stdout_closed(
    station: &Station,
    args: &[&str],
    meanwhile: impl FnOnce(),
) -> (Option<i32>, String) {
    // The reading end is closed before the command starts: closing it after the spawn would race a quick
    // command that had already written all it had into the pipe's buffer and exited 0.
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let child = station.spawn_with_stdout(args, writer.into());
    meanwhile();
    let output = child.wait_with_output().expect("it ends");
    (
        output.status.code(),
        String::from_utf8_lossy(&output.stderr).into_owned(),
    )
}

/// config/parts/propeller.toml in `dir` with its tolerance band set to `lower_mm .. upper_mm`.
fn propeller_part(dir: &Path, lower_mm: f64, upper_mm: f64) {
    propeller_part_edited(dir, |part| {
        let tolerance = part["tolerance"].as_table_mut().unwrap();
        tolerance.insert("lower_mm".into(), lower_mm.into());
        tolerance.insert("upper_mm".into(), upper_mm.into());
    });
}

#[test]
fn inspect_exits_4_for_a_failing_part_and_0_for_a_passing_one_and_watch_waits_for_a_job() {
    let parts = tempfile::tempdir().unwrap();
    propeller_part(parts.path(), -0.1, 0.1);
    let folder = parts.path().display().to_string();
    let station = Station::start_edited("propeller.toml", "station.toml", |table| {
        table.insert("parts".into(), folder.into());
    })
    .with_taught_reference();

    // No job yet: `watch` says so, waits, and shows the next job to its end.
    let mut watch = Background::new(station.spawn(&["watch"]));
    watch.until_line(10, "no job is running; waiting for the next one");
    // Blades B and C lie 0.4 to 1.0 mm off blade A: outside +-0.1 mm.
    let run = station.cli(&["inspect", "propeller", "--serial", "SN-FAIL"]);
    assert_eq!(run.code, Some(4), "{}\n{}", run.stdout, run.stderr);
    let worst: f64 = run
        .stderr
        .split("points outside the tolerance, worst ")
        .nth(1)
        .and_then(|rest| rest.split(" mm").next())
        .and_then(|number| number.parse().ok())
        .unwrap_or_else(|| panic!("no worst deviation in: {}", run.stderr));
    assert!(
        run.stderr
            .starts_with("part propeller serial SN-FAIL: FAIL, ")
            && worst.abs() > 0.4,
        "{}",
        run.stderr
    );
    assert!(run.stdout.contains("report: "), "{}", run.stdout);
    let (code, shown, _) = watch.end(30);
    assert_eq!(code, Some(0));
    assert!(
        shown.contains("(inspect propeller serial SN-FAIL): 3 instances x 5 profiles"),
        "{shown}"
    );
    // The job is over: a new watcher waits for the next one again.
    let mut watch = Background::new(station.spawn(&["watch"]));
    watch.until_line(10, "no job is running; waiting for the next one");
    drop(watch);

    // A part file whose name is not its file's is refused, naming both: a configuration error (exit code 3).
    std::fs::copy(
        parts.path().join("propeller.toml"),
        parts.path().join("blade.toml"),
    )
    .unwrap();
    let run = station.cli(&["teach", "blade"]);
    assert_eq!(run.code, Some(3), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("name = \"propeller\" but the file is named blade.toml"),
        "{}",
        run.stderr
    );
    // So is a part file that is not TOML, and a part with no file, each named.
    std::fs::write(
        parts.path().join("broken.toml"),
        "name = \"broken\"\ninstances = [\n",
    )
    .unwrap();
    for part in ["broken", "missing"] {
        let run = station.cli(&["inspect", part, "--serial", "SN-X"]);
        assert_eq!(run.code, Some(3), "{part}: {}", run.stderr);
        assert!(
            run.stderr.starts_with(&format!(
                "error: {}",
                parts.path().join(format!("{part}.toml")).display()
            )),
            "{part}: {}",
            run.stderr
        );
    }

    propeller_part(parts.path(), -1.5, 1.5);
    let run = station.cli(&["inspect", "propeller", "--serial", "SN-PASS"]);
    assert_eq!(run.code, Some(0), "{}\n{}", run.stdout, run.stderr);
    assert!(
        run.stdout.contains("part propeller serial SN-PASS: PASS"),
        "{}",
        run.stdout
    );

    // A closed standard output ends a command quietly, with the code of a program cut off by `| head`.
    for args in [
        &["report", "--trend"][..],
        &["report", "--export", "csv"],
        &["status"],
        &["watch"],
    ] {
        let (code, stderr) = with_stdout_closed(&station, args, || {});
        assert_eq!(code, Some(141), "zeroset {args:?}: {stderr}");
        assert_eq!(stderr, "", "zeroset {args:?}");
    }
    let (code, stderr) = with_stdout_closed(&station, &["watch", "--events"], || {
        std::thread::sleep(Duration::from_millis(300));
        station.cli_ok(&["inspect", "propeller", "--serial", "SN-PIPE", "--detach"]);
    });
    assert_eq!(code, Some(141), "{stderr}");
    // Only the word that no job was running (on standard error, as standard output holds events only).
    assert_eq!(
        stderr.trim(),
        "no job is running; waiting for the next one (Ctrl-C to stop)"
    );
}

#[test]
fn an_abort_and_a_stop_on_a_fault_end_inspect_with_their_codes() {
    let mut station = Station::start("propeller.toml").with_taught_reference();
    let mut watcher = station.watch();
    let of = |serial: &'static str| move |e: &Event| matches!(e, Event::Point { job, index: 20, .. } if job.contains(serial));

    let inspect = Background::new(station.spawn(&["inspect", "propeller", "--serial", "SN-A"]));
    watcher.until(30, of("SN-A"));
    station.cli_ok(&["abort"]);
    let (code, _, stderr) = inspect.end(30);
    assert_eq!(code, Some(5), "{stderr}");
    assert!(
        stderr.starts_with("error: job propeller-SN-A-") && stderr.contains("was aborted"),
        "{stderr}"
    );
    station.cli_ok(&["clear"]);

    let inspect = Background::new(station.spawn(&["inspect", "propeller", "--serial", "SN-S"]));
    watcher.until(30, of("SN-S"));
    assert_eq!(
        station.sim.control("fault cmm1 estop"),
        "ok fault cmm1 estop"
    );
    let (code, shown, stderr) = inspect.end(30);
    assert_eq!(code, Some(6), "{shown}\n{stderr}");
    assert!(
        stderr.contains("stopped: ")
            && stderr.contains("zeroset clear")
            && stderr.contains("zeroset watch"),
        "{stderr}"
    );
    assert!(shown.contains("STOPPED: "), "{shown}");
    // The job was stopped, not ended: cleared, it runs to its end.
    let cleared = station.cli_ok(&["clear"]);
    assert!(cleared.contains("continues"), "{cleared}");
    let over = watcher.until(A_JOB_S, job_over);
    assert!(matches!(over, Event::JobFinished { .. }), "{over:?}");
}

#[test]
fn usage_and_configuration_errors_have_their_codes_and_say_it_once() {
    let run = zeroset(&["report", "--trend", "--last", "0"]);
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.contains("'--last <LAST>': must be at least 1")
            && !run.stderr.contains("no inspection"),
        "{}",
        run.stderr
    );
    let out = tempfile::tempdir().unwrap();
    let model = out.path().join("model.json").display().to_string();
    let points = "config/profiles/seed003-profile3-blade-a.csv";
    let run = zeroset(&[
        "fit", "ip", "--points", points, "--degree", "0", "--out", &model,
    ]);
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("'--degree <DEGREE>': degree 0 is not supported; give 1 to 16")
            && !run.stderr.contains(".csv"),
        "the option is at fault, not the file: {}",
        run.stderr
    );
    assert_eq!(zeroset(&["inspect", "propeller"]).code, Some(2));

    let station = out.path().join("station.toml");
    std::fs::write(&station, "bogus = 1\n").unwrap();
    let file = station.display().to_string();
    let run = zeroset(&["status", "--config", &file]);
    assert_eq!(run.code, Some(3), "{}", run.stderr);
    assert_eq!(
        run.stderr.matches("unknown field `bogus`").count(),
        1,
        "{}",
        run.stderr
    );
    assert_eq!(run.stderr.matches("error: ").count(), 1, "{}", run.stderr);
    assert!(
        run.stderr
            .starts_with(&format!("error: {file}: TOML parse error")),
        "{}",
        run.stderr
    );
    let missing = out.path().join("none.toml").display().to_string();
    let run = zeroset(&["daemon", "--config", &missing]);
    assert_eq!(run.code, Some(3), "{}", run.stderr);
    assert_eq!(
        run.stderr.matches("No such file").count(),
        1,
        "{}",
        run.stderr
    );
}

#[test]
fn the_exit_codes_are_the_same_in_help_and_the_readme() {
    let help = crate::support::zeroset_ok(&["--help"]);
    let codes: Vec<&str> = help
        .split("Exit codes:\n")
        .nth(1)
        .expect("--help lists the exit codes")
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .collect();
    assert_eq!(codes.len(), 8, "{help}");
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    for code in codes {
        assert!(
            readme.lines().any(|l| l == code),
            "README.md lacks the exit code line {code:?}"
        );
    }
}

/// The sample point file for `zeroset fit supershape` is the ellipsoid that the fit's own test recovers.
#[test]
fn the_sample_supershape_points_are_the_tested_ellipsoid() {
    let dir = tempfile::tempdir().unwrap();
    let made = dir.path().join("ellipsoid.csv");
    crate::fit_and_deviate::ellipsoid_csv(&made, 2000, 0.0);
    let shipped = repo().join("config/points/ellipsoid-40-30-20.csv");
    assert_eq!(
        std::fs::read_to_string(shipped).unwrap(),
        std::fs::read_to_string(made).unwrap()
    );
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    assert!(readme.contains("zeroset fit supershape --points config/points/ellipsoid-40-30-20.csv"));
}
