//! Live display of a job: a progress bar per instance (blade) with its running deviation statistics, a line per
//! finished profile, and the per-instance table at the end. Without a terminal (a log, a test) only the lines
//! are written.

use std::collections::HashMap;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::analysis::stats::{DeviationStats, RunningStats, Verdict};
use crate::api::{Event, InstanceSummary, JobInfo, JobKind};

/// How a followed job ended.
#[derive(Debug, Clone, PartialEq)]
pub enum JobEnd {
    Finished { passed: Option<bool> },
    Aborted,
    Failed(String),
}

/// The display of the job being watched.
pub struct Watch {
    /// Only this job's events are shown; the first job seen when `None`.
    job: Option<String>,
    bars: MultiProgress,
    instances: HashMap<String, InstanceBar>,
    profiles: usize,
    /// Follow the job without writing anything (when the events themselves are written instead).
    quiet: bool,
}

struct InstanceBar {
    bar: ProgressBar,
    stats: RunningStats,
    points: usize,
}

impl Watch {
    pub fn new(job: Option<String>, quiet: bool) -> Watch {
        let target = if console_is_terminal() && !quiet {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        };
        Watch {
            job,
            bars: MultiProgress::with_draw_target(target),
            instances: HashMap::new(),
            profiles: 0,
            quiet,
        }
    }

    /// Shows one event; returns how the job ended when this event ends it.
    pub fn show(&mut self, event: &Event) -> Option<JobEnd> {
        if let Some(id) = event_job(event) {
            match &self.job {
                Some(job) if job != id => return None,
                None => self.job = Some(id.to_string()),
                _ => {}
            }
        }
        match event {
            Event::JobStarted { job, done } => self.lay_out(job, done.len()),
            Event::ScanStarted { machine, scan, .. } => {
                if let Some(instance) = self.instances.get(&scan.instance) {
                    instance
                        .bar
                        .set_message(format!("scanning {} on {machine}", scan.profile));
                }
            }
            Event::Point {
                scan,
                deviation_mm,
                surface_mm,
                flagged,
                ..
            } => {
                if let Some(instance) = self.instances.get_mut(&scan.instance) {
                    instance.points += 1;
                    // As the daemon's statistics: flagged points are shown as points, not in the figures.
                    if let (Some(d), false) = (deviation_mm, flagged) {
                        instance.stats.push(*d, *surface_mm);
                    }
                    let running = instance
                        .stats
                        .summary()
                        .map(|s| format!(", mean {:+.4} mm, RMS {:.4} mm", s.mean_mm, s.rms_mm))
                        .unwrap_or_default();
                    instance.bar.set_message(format!(
                        "{} {} points{running}",
                        scan.profile, instance.points
                    ));
                }
            }
            Event::ProfileDone {
                machine,
                scan,
                points,
                stats,
                verdict,
                ..
            } => {
                if let Some(instance) = self.instances.get(&scan.instance) {
                    instance.bar.inc(1);
                }
                let stats = stats
                    .map(|s| format!(": {}", stats_line(&s)))
                    .unwrap_or_default();
                let verdict = verdict.as_ref().map(verdict_word).unwrap_or("");
                self.line(format!(
                    "{} {} done on {machine}, {points} points{stats} {verdict}",
                    scan.instance, scan.profile
                ));
            }
            Event::JobStopped {
                reason, next_step, ..
            } => self.line(format!("STOPPED: {reason}\n  next: {next_step}")),
            Event::JobResumed { job } => self.line(format!("job {job} resumed")),
            Event::ProfileRescanned {
                machine,
                scan,
                reason,
                ..
            } => self.line(format!(
                "{} {} on {machine} scanned again: {reason}",
                scan.instance, scan.profile
            )),
            Event::ReferenceSaved { path, profiles, .. } => {
                self.finish_bars();
                self.line(format!("reference saved: {}", path.display()));
                for fit in profiles {
                    let distance = match (fit.rms_mm, fit.max_mm) {
                        (Some(rms), Some(max)) => format!("fit RMS {rms:.4} mm, max {max:.4} mm"),
                        _ => "no fit distances kept by this reference kind".to_string(),
                    };
                    self.line(format!("  {}: {} points, {distance}", fit.profile, fit.points));
                }
                return Some(JobEnd::Finished { passed: None });
            }
            Event::JobFinished {
                report,
                instances,
                verdict,
                ..
            } => {
                self.finish_bars();
                self.line(instance_table(instances));
                if let Some(report) = report {
                    self.line(format!("report: {}", report.display()));
                    let html = report.join(crate::report::HTML_FILE);
                    self.line(format!("open in a browser: {}", html.display()));
                }
                return Some(JobEnd::Finished {
                    passed: verdict.as_ref().map(Verdict::passed),
                });
            }
            Event::JobAborted { job } => {
                self.finish_bars();
                self.line(format!("job {job} aborted"));
                return Some(JobEnd::Aborted);
            }
            Event::JobFailed { error, .. } => {
                self.finish_bars();
                self.line(format!("FAILED: {error}"));
                return Some(JobEnd::Failed(error.clone()));
            }
            Event::Lagged { missed } => self.line(format!(
                "(this display fell behind and missed {missed} events; the daemon and its report missed none)"
            )),
        }
        None
    }

    fn lay_out(&mut self, job: &JobInfo, done: usize) {
        self.finish_bars();
        self.profiles = job.profiles.len();
        let what = match job.kind {
            JobKind::Teach => format!("teach {}", job.part),
            JobKind::Inspect => format!(
                "inspect {} serial {}",
                job.part,
                job.serial.as_deref().unwrap_or("?")
            ),
        };
        self.line(format!(
            "job {} ({what}): {} instances x {} profiles on {}; deviations in mm, tolerance {:+.3} .. {:+.3} mm{}",
            job.id,
            job.instances.len(),
            job.profiles.len(),
            job.machines.join(", "),
            job.tolerance_mm[0],
            job.tolerance_mm[1],
            if done > 0 { format!(", {done} profiles already done") } else { String::new() }
        ));
        let style =
            ProgressStyle::with_template("{prefix:>10} [{bar:20}] {pos}/{len} profiles {msg}")
                .expect("a valid template")
                .progress_chars("=> ");
        for name in &job.instances {
            let bar = self.bars.add(ProgressBar::new(self.profiles as u64));
            bar.set_style(style.clone());
            bar.set_prefix(format!("instance {name}"));
            self.instances.insert(
                name.clone(),
                InstanceBar {
                    bar,
                    stats: RunningStats::default(),
                    points: 0,
                },
            );
        }
    }

    fn finish_bars(&mut self) {
        for (_, instance) in self.instances.drain() {
            instance.bar.finish_and_clear();
        }
    }

    fn line(&self, text: String) {
        if self.quiet {
            return;
        }
        if self.bars.is_hidden() {
            println!("{text}");
        } else {
            let _ = self.bars.println(text);
        }
    }
}

fn console_is_terminal() -> bool {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal()
}

fn event_job(event: &Event) -> Option<&str> {
    match event {
        Event::JobStarted { job, .. } => Some(&job.id),
        Event::ScanStarted { job, .. }
        | Event::Point { job, .. }
        | Event::ProfileDone { job, .. }
        | Event::ProfileRescanned { job, .. }
        | Event::JobStopped { job, .. }
        | Event::JobResumed { job }
        | Event::ReferenceSaved { job, .. }
        | Event::JobFinished { job, .. }
        | Event::JobAborted { job }
        | Event::JobFailed { job, .. } => Some(job),
        Event::Lagged { .. } => None,
    }
}

fn stats_line(s: &DeviationStats) -> String {
    format!(
        "mean {:+.4} mm, RMS {:.4} mm, min {:+.4} mm, max {:+.4} mm, worst {:+.4} mm at ({:.2}, {:.2}, {:.2}) mm",
        s.mean_mm, s.rms_mm, s.min_mm, s.max_mm, s.worst_mm, s.worst_at_mm[0], s.worst_at_mm[1], s.worst_at_mm[2]
    )
}

fn verdict_word(verdict: &Verdict) -> &'static str {
    if verdict.passed() {
        "PASS"
    } else {
        "FAIL"
    }
}

/// The per-instance table of an inspection.
pub fn instance_table(instances: &[InstanceSummary]) -> String {
    let mut table = format!(
        "{:<9} {:>7} {:>10} {:>9} {:>10} {:>10}  {}\n",
        "instance", "points", "mean mm", "RMS mm", "min mm", "max mm", "verdict"
    );
    for instance in instances {
        match &instance.stats {
            Some(s) => table.push_str(&format!(
                "{:<9} {:>7} {:>+10.4} {:>9.4} {:>+10.4} {:>+10.4}  {}\n",
                instance.instance,
                s.points,
                s.mean_mm,
                s.rms_mm,
                s.min_mm,
                s.max_mm,
                instance.verdict.as_ref().map(verdict_word).unwrap_or("-")
            )),
            None => table.push_str(&format!("{:<9} no points\n", instance.instance)),
        }
    }
    table.pop();
    table
}
