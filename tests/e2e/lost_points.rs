//! No point lost: a scan that lost a line of points on the way (the simulator's `drop-lines`) is not counted
//! complete; it is scanned again, and the report holds every profile with the point count of an uninterrupted
//! inspection, no point twice, and the rescan recorded.

use zeroset::api::Event;

use crate::daemon::{job_over, Station, Watcher, A_JOB_S};
use crate::lockout::station;
use crate::station::{assert_no_repeated_points, point_counts};

#[test]
fn a_scan_that_lost_a_line_of_points_is_scanned_again_to_its_full_count() {
    let mut station = station();
    station.inspected(&["inspect", "propeller", "--serial", "SN-WHOLE"]);
    let (_, whole) = station.report("SN-WHOLE");
    // Lines lost early, midway and late in a profile's scan, in different profiles.
    for (serial, at) in [("SN-D1", 25), ("SN-D2", 120), ("SN-D3", 300)] {
        let mut watcher = inspect_with_fault(&mut station, serial, at, "drop-lines 1");
        let mut rescans = 0;
        let end = loop {
            let event = watcher.until(120, |e| {
                job_over(e)
                    || matches!(e, Event::JobStopped { .. } | Event::ProfileRescanned { .. })
            });
            match event {
                Event::ProfileRescanned { .. } => rescans += 1,
                // The line lost was the scan's last (its completion): the link timed out; clear as an operator.
                Event::JobStopped { .. } => {
                    station.cli_ok(&["clear"]);
                }
                end => break end,
            }
        };
        assert!(
            matches!(end, Event::JobFinished { .. }),
            "{serial}: {end:?}"
        );
        let (_, report) = station.report(serial);
        assert_eq!(
            point_counts(&report),
            point_counts(&whole),
            "{serial}: every profile whole"
        );
        assert_no_repeated_points(&report);
        assert_eq!(
            report.rescans.len(),
            rescans,
            "{serial}: every rescan in the report"
        );
        eprintln!("{serial}: line lost after point {at}: {rescans} rescan(s)");
        // The history keeps the rescans too, against the profile rescanned.
        let csv = station.cli_ok(&["report", "--export", "csv"]);
        let rescans_in_history: usize = csv
            .lines()
            .filter(|line| line.starts_with(serial))
            .map(|line| line.rsplit(',').next().unwrap().parse::<usize>().unwrap())
            .sum();
        assert_eq!(rescans_in_history, rescans, "{serial}: {csv}");
    }
}

#[test]
fn a_report_that_cannot_be_written_waits_for_the_fix_and_is_written_from_the_scans() {
    let station = crate::daemon::Station::start("propeller.toml").with_taught_reference();
    // The part's reports folder is a file: the report cannot be written (a read-only folder stops nobody who
    // runs as root, as CI does).
    std::fs::create_dir_all(station.reports()).unwrap();
    let blocked = station.reports().join("propeller");
    std::fs::write(&blocked, "not a folder").unwrap();
    let mut watcher = station.watch();
    station.cli_ok(&["inspect", "propeller", "--serial", "SN-RO", "--detach"]);
    let stopped = watcher.until(120, |e| {
        job_over(e) || matches!(e, Event::JobStopped { .. })
    });
    let Event::JobStopped {
        reason, next_step, ..
    } = stopped
    else {
        panic!("{stopped:?}")
    };
    assert!(reason.contains("every profile is on disk"), "{reason}");
    assert!(next_step.contains("zeroset clear"), "{next_step}");
    std::fs::remove_file(&blocked).unwrap();
    let seen = watcher.events().len();
    station.cli_ok(&["clear"]);
    let end = watcher.until(A_JOB_S, job_over);
    assert!(matches!(end, Event::JobFinished { .. }), "{end:?}");
    let rescanned = watcher.events()[seen..]
        .iter()
        .filter(|e| matches!(e, Event::ScanStarted { .. }))
        .count();
    assert_eq!(rescanned, 0, "the report is written from the scans on disk");
    let (dir, report) = station.report("SN-RO");
    assert!(dir.join("report.json").is_file());
    assert_eq!(report.instances.len(), 3);
}

#[test]
fn a_complete_scan_file_cut_short_on_disk_is_scanned_again_at_restart_and_no_other() {
    let mut station = station();
    station.inspected(&["inspect", "propeller", "--serial", "SN-WHOLE"]);
    let (_, whole) = station.report("SN-WHOLE");
    let mut watcher = station.watch();
    station.cli_ok(&["inspect", "propeller", "--serial", "SN-T", "--detach"]);
    let mut done = Vec::new();
    let mut job = String::new();
    watcher.until(60, |e| {
        if let Event::ProfileDone { scan, job: id, .. } = e {
            done.push(scan.clone());
            job = id.clone();
        }
        done.len() >= 3 && matches!(e, Event::Point { index: 30, .. })
    });
    drop(watcher);
    station.kill_daemon();
    let spoiled = &done[1];
    let file = station
        .data()
        .join("jobs")
        .join(&job)
        .join("scans")
        .join(format!("{}-{}.json", spoiled.instance, spoiled.profile));
    let bytes = std::fs::read(&file).unwrap();
    std::fs::write(&file, &bytes[..bytes.len() / 3]).unwrap();
    station.start_daemon();
    let mut watcher = station.watch();
    station.cli_ok(&["clear"]);
    let end = watcher.until(A_JOB_S, job_over);
    assert!(matches!(end, Event::JobFinished { .. }), "{end:?}");
    let scanned: Vec<_> = watcher
        .events()
        .into_iter()
        .filter_map(|e| match e {
            Event::ScanStarted { scan, .. } => Some(scan),
            _ => None,
        })
        .collect();
    assert!(
        scanned.contains(spoiled),
        "{spoiled:?} scanned again: {scanned:?}"
    );
    for good in done.iter().filter(|d| *d != spoiled) {
        assert!(
            !scanned.contains(good),
            "{good:?} was whole on disk but scanned again"
        );
    }
    let (_, report) = station.report("SN-T");
    assert_eq!(point_counts(&report), point_counts(&whole));
    assert_no_repeated_points(&report);
}

/// Starts an inspection of `serial` watched, and injects `fault` into cmm1 once point `at` of a scan is seen.
fn inspect_with_fault(station: &mut Station, serial: &str, at: usize, fault: &str) -> Watcher {
    let mut watcher = station.watch();
    station.cli_ok(&["inspect", "propeller", "--serial", serial, "--detach"]);
    watcher.until(
        60,
        |e| matches!(e, Event::Point { index, .. } if *index == at),
    );
    assert_eq!(
        station.sim.control(&format!("fault cmm1 {fault}")),
        format!("ok fault cmm1 {fault}")
    );
    watcher
}

#[test]
fn a_lost_line_then_clear_reconnects_and_the_job_continues_whole() {
    let mut station = station();
    station.inspected(&["inspect", "propeller", "--serial", "SN-WHOLE"]);
    let (_, whole) = station.report("SN-WHOLE");
    let mut watcher = inspect_with_fault(&mut station, "SN-LINK", 50, "disconnect 1000");
    let stopped = watcher.until(30, |e| matches!(e, Event::JobStopped { .. }));
    let Event::JobStopped { reason, .. } = stopped else {
        unreachable!()
    };
    assert!(reason.contains("cmm1"), "{reason}");
    std::thread::sleep(std::time::Duration::from_millis(1200));
    let cleared = station.cli_ok(&["clear"]);
    assert!(cleared.contains("continues"), "{cleared}");
    let end = watcher.until(A_JOB_S, job_over);
    assert!(matches!(end, Event::JobFinished { .. }), "{end:?}");
    let (_, report) = station.report("SN-LINK");
    assert_eq!(point_counts(&report), point_counts(&whole));
    assert_no_repeated_points(&report);
}

#[test]
fn a_scan_that_loses_its_touch_partway_stops_and_after_the_clear_is_scanned_again_whole() {
    let mut station = station();
    station.inspected(&["inspect", "propeller", "--serial", "SN-WHOLE"]);
    let (_, whole) = station.report("SN-WHOLE");
    // Armed during one scan, the fault takes the next: that scan sends its first half, then 1003.
    let mut watcher = inspect_with_fault(&mut station, "SN-TOUCH", 20, "no-touch");
    let stopped = watcher.until(60, |e| matches!(e, Event::JobStopped { .. }));
    let Event::JobStopped {
        machine,
        scan,
        reason,
        next_step,
        ..
    } = &stopped
    else {
        unreachable!()
    };
    assert_eq!(machine.as_deref(), Some("cmm1"), "{stopped:?}");
    assert!(scan.is_some(), "the stop names the profile: {stopped:?}");
    assert!(reason.contains("1003"), "{reason}");
    assert!(next_step.contains("zeroset clear"), "{next_step}");
    let cleared = station.cli_ok(&["clear"]);
    assert!(cleared.contains("continues"), "{cleared}");
    let end = watcher.until(A_JOB_S, job_over);
    assert!(matches!(end, Event::JobFinished { .. }), "{end:?}");
    let (_, report) = station.report("SN-TOUCH");
    assert_eq!(point_counts(&report), point_counts(&whole));
    assert_no_repeated_points(&report);
    let transcript = std::fs::read_to_string(station.sim.transcript("cmm1")).unwrap();
    let lost: Vec<&str> = transcript
        .lines()
        .filter(|l| l.contains("! Error(") && l.contains(", 1003,"))
        .collect();
    assert_eq!(lost.len(), 1, "{lost:?}");
}

#[test]
fn a_teach_scan_that_loses_its_touch_partway_is_cleared_without_a_collision_and_the_teach_finishes()
{
    let mut station = station();
    let mut watcher = station.watch();
    station.cli_ok(&["teach", "propeller", "--detach"]);
    watcher.until(120, |e| matches!(e, Event::Point { index: 35, .. }));
    assert_eq!(
        station.sim.control("fault cmm1 no-touch"),
        "ok fault cmm1 no-touch"
    );
    let stopped = watcher.until(120, |e| matches!(e, Event::JobStopped { .. }));
    let Event::JobStopped { reason, scan, .. } = &stopped else {
        unreachable!()
    };
    assert!(reason.contains("1003") && scan.is_some(), "{stopped:?}");
    let cleared = station.cli(&["clear"]);
    assert!(
        cleared.success && cleared.stdout.contains("continues"),
        "{}{}",
        cleared.stdout,
        cleared.stderr
    );
    let end = watcher.until(240, job_over);
    assert!(matches!(end, Event::ReferenceSaved { .. }), "{end:?}");
    let transcript = std::fs::read_to_string(station.sim.transcript("cmm1")).unwrap();
    let errors: Vec<&str> = transcript
        .lines()
        .filter(|l| l.contains("! Error(") && (l.contains(", 2504,") || l.contains(", 1003,")))
        .collect();
    assert!(
        errors.len() == 1 && errors[0].contains(", 1003,"),
        "one lost touch and no collision on the way out: {errors:?}"
    );
}
