//! The campaign's driver: inspections on the real station, faults injected at the planned moments, the
//! operator's part played as a person would (after a stop, wait for the line if it went dead and `zeroset
//! clear`; after a killed daemon, start it again and clear; when clear keeps failing, restart the daemon), and
//! the checks after every job.

use std::collections::{BTreeSet, HashSet};
use std::sync::mpsc::RecvTimeoutError;
use std::time::{Duration, Instant};

use zeroset::api::{Event, ScanRef};
use zeroset::report::PartReport;

use super::checks::{self, Counts};
use super::plan::{Fault, Kind, Moment, Planner};
use super::tally::Tally;
use super::transcript::TranscriptWatch;
use super::wire_log::WireLog;
use crate::daemon::{Station, Watcher};

const MACHINE: &str = "cmm1";
const PART: &str = "propeller";
/// The station's client gives up on a silent line after this long (the default waits minutes for homing).
const LINE_TIMEOUT_S: f64 = 3.0;
/// A running job that sends no event for this long is stuck.
const QUIET: Duration = Duration::from_secs(60);
/// Clears an operator tries (a second apart) before restarting the daemon, and after.
const CLEAR_TRIES: usize = 4;

pub(crate) struct Options {
    pub(crate) faults: usize,
    pub(crate) seed: u64,
}

/// Runs the campaign to its number of faults; every job is checked as it ends.
pub(crate) fn run(options: &Options) -> Tally {
    let mut tally = Tally {
        seed: options.seed,
        ..Tally::default()
    };
    let mut planner = Planner::new(options.seed);
    let mut rig = Rig::new(&mut tally);
    let started = Instant::now();
    let mut next = planner.next();
    let mut jobs = 0;
    while tally.injected_total() < options.faults {
        jobs += 1;
        let serial = format!("SN-C{jobs:04}");
        let mut job = Job {
            rig: &mut rig,
            tally: &mut tally,
            serial,
            faults: Vec::new(),
            done: HashSet::new(),
            since: 0,
            at: None,
            budget: options.faults,
        };
        let began = Instant::now();
        let end = job.run(&mut planner, &mut next);
        let line = format!(
            "{}: {end:?} after {:.1} s, faults: {}",
            job.serial,
            began.elapsed().as_secs_f64(),
            job.faults.join(", ")
        );
        eprintln!("{line}");
        if end == End::Stuck {
            rig.retire(&mut tally);
            rig = Rig::new(&mut tally);
        }
    }
    tally.elapsed = started.elapsed();
    rig.retire(&mut tally);
    tally
}

/// A station (simulator and daemon), what its machine's transcript showed so far, and the point counts of an
/// uninterrupted inspection on it.
struct Rig {
    station: Station,
    transcript: TranscriptWatch,
    whole: Counts,
    profiles: Vec<String>,
    /// The latest fault and when its dead line comes back, if it was a disconnect.
    last: Option<Fault>,
    line_back: Option<Instant>,
}

impl Rig {
    fn new(tally: &mut Tally) -> Rig {
        tally.stations += 1;
        let mut station = Station::quick(LINE_TIMEOUT_S);
        station.log_wire();
        let wire = WireLog::new(station.daemon_log(), MACHINE);
        let transcript = TranscriptWatch::new(station.sim.transcript(MACHINE), wire);
        station.inspected(&["inspect", PART, "--serial", "SN-WHOLE"]);
        let whole = checks::point_counts(&read_report(&station, "SN-WHOLE").expect("a report"));
        let profiles: BTreeSet<String> = whole.keys().map(|(_, p)| p.clone()).collect();
        let mut rig = Rig {
            station,
            transcript,
            whole,
            profiles: profiles.into_iter().collect(),
            last: None,
            line_back: None,
        };
        let found = rig.transcript.read_on();
        tally.violations.extend(
            found
                .into_iter()
                .map(|v| format!("uninterrupted inspection: {v}")),
        );
        rig
    }

    /// Done with this station: what its transcript showed is added to the tally.
    fn retire(&mut self, tally: &mut Tally) {
        let found = self.transcript.read_on();
        tally.violations.extend(found);
        for (kind, n) in self.transcript.fired() {
            *tally.fired.entry(*kind).or_default() += n;
        }
        tally
            .transcripts
            .push(self.transcript.path().display().to_string());
    }
}

#[derive(Debug, PartialEq, Eq)]
enum End {
    Finished,
    /// It could not go on (a clear the campaign cannot satisfy, e.g. a jog): the next job gets a fresh station.
    Stuck,
}

struct Job<'a> {
    rig: &'a mut Rig,
    tally: &'a mut Tally,
    serial: String,
    /// What went in, and when, for the violations' context.
    faults: Vec<String>,
    /// Profiles counted complete.
    done: HashSet<ScanRef>,
    /// Events towards the next fault's moment: points, or profiles done.
    since: usize,
    /// The scan under way and its latest point's index, None between scans: where a fault went in.
    at: Option<(ScanRef, usize)>,
    budget: usize,
}

impl Job<'_> {
    fn run(&mut self, planner: &mut Planner, next: &mut (Fault, Moment)) -> End {
        let mut watcher = self.rig.station.watch();
        if let Err(refused) = self.start() {
            return self.give_up(&refused);
        }
        loop {
            let event = match watcher.next(QUIET) {
                Ok(event) => event,
                Err(RecvTimeoutError::Timeout) => {
                    let status = self.rig.station.cli(&["status"]).stdout;
                    self.violation(format!(
                        "no event for {} s; status: {status}",
                        QUIET.as_secs()
                    ));
                    return self.give_up(&status);
                }
                Err(RecvTimeoutError::Disconnected) => {
                    // Nobody killed it: a crash.
                    let ended = self.rig.station.daemon_ended();
                    self.violation(format!("the daemon's event stream ended: {ended:?}"));
                    if ended.is_some() {
                        self.rig.station.start_daemon();
                    }
                    watcher = self.rig.station.watch();
                    match self.clear() {
                        Ok(()) => continue,
                        Err(last) => return self.give_up(&last),
                    }
                }
            };
            let due = match (&event, next.1) {
                (Event::Point { .. }, Moment::AfterPoints(n)) => {
                    self.since += 1;
                    self.since >= n
                }
                (Event::ProfileDone { .. }, Moment::AfterProfileDone { .. }) => true,
                _ => false,
            };
            match &event {
                Event::Point { scan, index, .. } => self.at = Some((scan.clone(), *index)),
                Event::ProfileDone { scan, .. } => {
                    self.at = None;
                    self.done.insert(scan.clone());
                }
                Event::ScanStarted { scan, .. } if self.done.contains(scan) => {
                    self.violation(format!(
                        "instance {} profile {} was complete and is scanned again",
                        scan.instance, scan.profile
                    ));
                }
                Event::JobStarted { done, .. } => {
                    let forgotten: Vec<ScanRef> = self
                        .done
                        .iter()
                        .filter(|s| !done.contains(s))
                        .cloned()
                        .collect();
                    for scan in forgotten {
                        self.violation(format!(
                            "instance {} profile {} was complete but the resumed job does not count it",
                            scan.instance, scan.profile
                        ));
                    }
                    self.done.extend(done.iter().cloned());
                }
                Event::ProfileRescanned { .. } => self.tally.gap_rescans += 1,
                Event::Lagged { missed } => self.tally.lagged += missed,
                Event::JobStopped { .. } => {
                    if let Some(last) = self.rig.last {
                        *self.tally.stops.entry(last.kind).or_default() += 1;
                    }
                    let gaps = checks::stop_message_gaps(&event);
                    if !gaps.is_empty() {
                        self.violation(format!(
                            "a stop does not name {}: {event:?}",
                            gaps.join(", ")
                        ));
                    }
                    if let Err(last) = self.clear() {
                        return self.give_up(&last);
                    }
                }
                Event::JobFinished { .. } => {
                    self.check_finished();
                    return End::Finished;
                }
                Event::JobAborted { .. }
                | Event::JobFailed { .. }
                | Event::ReferenceSaved { .. } => {
                    self.violation(format!("the inspection ended so: {event:?}"));
                    return self.give_up(&format!("{event:?}"));
                }
                _ => {}
            }
            if due && self.tally.injected_total() < self.budget {
                let (fault, moment) = *next;
                *next = planner.next();
                self.since = 0;
                if let Moment::AfterProfileDone { ms } = moment {
                    std::thread::sleep(Duration::from_millis(ms));
                }
                if let Some(replaced) = self.inject(fault, moment) {
                    watcher = replaced;
                    // A daemon killed as the report was written may have finished the job before it died.
                    if let Err(last) = self.clear() {
                        return self.give_up(&last);
                    }
                    if self.finished_unseen() {
                        self.check_finished();
                        return End::Finished;
                    }
                }
            }
        }
    }

    /// `zeroset inspect --detach`; a station left locked out by a fault that came after the last job's end is
    /// cleared first, as an operator would.
    fn start(&mut self) -> Result<(), String> {
        let serial = self.serial.clone();
        let args = ["inspect", PART, "--serial", &serial, "--detach"];
        let run = self.rig.station.cli(&args);
        if run.success {
            return Ok(());
        }
        if !run.stderr.contains("zeroset clear") {
            self.violation(format!("inspect refused: {}", run.stderr.trim()));
            return Err(run.stderr);
        }
        self.clear()?;
        let run = self.rig.station.cli(&args);
        if run.success {
            return Ok(());
        }
        self.violation(format!(
            "inspect refused after a clear: {}",
            run.stderr.trim()
        ));
        Err(run.stderr)
    }

    /// Puts a fault in; after a kill, the new daemon's watcher.
    fn inject(&mut self, fault: Fault, moment: Moment) -> Option<Watcher> {
        *self.tally.injected.entry(fault.kind).or_default() += 1;
        let place = match &self.at {
            Some((scan, index)) => {
                format!("in {} {} after point {index}", scan.instance, scan.profile)
            }
            None => "between scans".to_string(),
        };
        self.faults.push(format!("{fault} ({moment}, {place})"));
        self.rig.last = Some(fault);
        if let Some(line) = fault.control_line(MACHINE) {
            let answer = self.rig.station.sim.control(&line);
            if answer != format!("ok {line}") {
                self.violation(format!("the simulator answered {line:?} with {answer:?}"));
            }
            if fault.kind == Kind::Disconnect {
                let dead = Duration::from_millis(fault.arg.unwrap_or(0));
                self.rig.line_back = Some(Instant::now() + dead);
            }
            return None;
        }
        if let Some(ended) = self.rig.station.daemon_ended() {
            self.violation(format!("the daemon had ended before the kill: {ended}"));
        } else {
            self.rig.station.kill_daemon();
        }
        self.rig.station.start_daemon();
        Some(self.rig.station.watch())
    }

    /// The operator's clear: after a dead line is back; tried again a second later, and when it keeps failing,
    /// after restarting the daemon (all an operator can do short of a jog).
    fn clear(&mut self) -> Result<(), String> {
        if let Some(back) = self.rig.line_back.take() {
            std::thread::sleep(
                back.saturating_duration_since(Instant::now()) + Duration::from_millis(300),
            );
        }
        let mut last = String::new();
        for restarted in [false, true] {
            if restarted {
                if last.contains("jog") {
                    break;
                }
                self.violation(format!("clear failed {CLEAR_TRIES} times: {}", last.trim()));
                self.tally.restarts_to_clear += 1;
                self.rig.station.kill_daemon();
                self.rig.station.start_daemon();
            }
            for _ in 0..CLEAR_TRIES {
                self.tally.clears += 1;
                let run = self.rig.station.cli(&["clear"]);
                if run.success {
                    return Ok(());
                }
                last = run.stderr;
                self.tally.refused(&last);
                std::thread::sleep(Duration::from_secs(1));
            }
        }
        Err(last)
    }

    /// Whether the job ended with its report while the campaign was not watching (a kill as it finished).
    fn finished_unseen(&self) -> bool {
        let status = self.rig.station.cli(&["status"]).stdout;
        (status.contains("): finished") || status.contains("no job"))
            && read_report(&self.rig.station, &self.serial).is_ok()
    }

    /// The job cannot go on here: its last word must say on which machine, part and profile, and what to do.
    fn give_up(&mut self, last: &str) -> End {
        let status = self.rig.station.cli(&["status"]).stdout;
        let said = format!("{} | {}", status.trim(), last.trim());
        let gaps = checks::final_message_gaps(&said, MACHINE, PART, &self.rig.profiles);
        if !gaps.is_empty() {
            self.violation(format!(
                "its last word does not name {}: {said}",
                gaps.join(", ")
            ));
        }
        self.read_transcript();
        self.tally.jobs_stuck.push(format!(
            "{} ({}): {said}",
            self.serial,
            self.faults.join(", ")
        ));
        End::Stuck
    }

    /// The checks of a finished job: its report against the uninterrupted one, the history, the transcript, the
    /// daemon.
    fn check_finished(&mut self) {
        self.tally.jobs_finished += 1;
        match read_report(&self.rig.station, &self.serial) {
            Ok(report) => {
                let counts = checks::point_counts(&report);
                let mut found = checks::count_differences(
                    "report",
                    &counts,
                    &self.rig.whole,
                    "an uninterrupted inspection",
                );
                found.extend(checks::repeated_points(&report));
                let export = self
                    .rig
                    .station
                    .cli(&["report", "--export", "csv", "--last", "100000"]);
                let (history, doubled) = checks::history_counts(&export.stdout, &self.serial);
                found.extend(doubled);
                if !history.is_empty() {
                    let used = checks::statistic_counts(&report);
                    found.extend(checks::count_differences(
                        "history",
                        &history,
                        &used,
                        "the report",
                    ));
                }
                for violation in found {
                    self.violation(violation);
                }
            }
            Err(e) => self.violation(format!("finished with no report: {e}")),
        }
        self.read_transcript();
        if let Some(ended) = self.rig.station.daemon_ended() {
            self.violation(format!("the daemon crashed: {ended}"));
            self.rig.station.start_daemon();
        }
    }

    fn read_transcript(&mut self) {
        for violation in self.rig.transcript.read_on() {
            self.violation(violation);
        }
    }

    fn violation(&mut self, what: String) {
        // The job's latest faults: what led to it.
        let latest = &self.faults[self.faults.len().saturating_sub(3)..];
        let more = if self.faults.len() > 3 { "..., " } else { "" };
        let line = format!(
            "{} (after {more}{}): {what}",
            self.serial,
            latest.join(", ")
        );
        eprintln!("VIOLATION {line}");
        self.tally.violations.push(line);
    }
}

/// The newest report of the propeller `serial`.
fn read_report(station: &Station, serial: &str) -> Result<PartReport, String> {
    let folder = station.reports().join(PART).join(serial);
    let dir = std::fs::read_dir(&folder)
        .map_err(|e| format!("{}: {e}", folder.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .max()
        .ok_or_else(|| format!("{}: no report", folder.display()))?;
    zeroset::report::read_report(&dir).map_err(|e| e.to_string())
}
