//! No point lost: a scan that lost a line of points on the way (the simulator's `drop-lines`) is not counted
//! complete; it is scanned again, and the report holds every profile with the point count of an uninterrupted
//! inspection, no point twice, and the rescan recorded.

use zeroset::api::Event;

use crate::daemon::job_over;
use crate::lockout::station;
use crate::station::{assert_no_repeated_points, point_counts};

#[test]
fn a_scan_that_lost_a_line_of_points_is_scanned_again_to_its_full_count() {
    let mut station = station();
    station.cli_ok(&["inspect", "propeller", "--serial", "SN-WHOLE"]);
    let (_, whole) = station.report("SN-WHOLE");
    // Lines lost early, midway and late in a profile's scan, in different profiles.
    for (serial, at) in [("SN-D1", 25), ("SN-D2", 120), ("SN-D3", 300)] {
        let mut watcher = station.watch();
        station.cli_ok(&["inspect", "propeller", "--serial", serial, "--detach"]);
        watcher.until(
            60,
            |e| matches!(e, Event::Point { index, .. } if *index == at),
        );
        assert_eq!(
            station.sim.control("fault cmm1 drop-lines 1"),
            "ok fault cmm1 drop-lines 1"
        );
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
    }
}
