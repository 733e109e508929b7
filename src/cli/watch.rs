//! Live display of a job: a progress bar per instance (blade) with its running deviation statistics, a line per
//! finished profile, and the per-instance table at the end. Without a terminal (a log, a test) only the lines
//! are written.

use std::collections::HashMap;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::analysis::section::{SectionBestFit, SectionParametersReport};
use crate::analysis::stats::{DeviationStats, RunningStats, Verdict};
use crate::analysis::tolerances::{failure_text, ParameterVerdict};
use crate::api::counted;
use crate::api::{Event, InstanceSummary, JobInfo, JobKind, ScanRef};

/// How a followed job ended, or stopped to wait for `zeroset clear`.
#[derive(Debug, Clone, PartialEq)]
pub enum JobEnd {
    /// The verdict of an inspection (`None` for a teach).
    Finished {
        verdict: Option<Verdict>,
    },
    Aborted {
        job: String,
    },
    Stopped {
        job: String,
        reason: String,
        next_step: String,
    },
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
    /// The deviation of the newest point previewed, mm.
    newest_mm: Option<f64>,
}

impl InstanceBar {
    /// The bar's message while `profile` is scanned: points so far, their running figures, the newest deviation.
    fn show_scanning(&self, profile: &str) {
        let running = self
            .stats
            .summary()
            .map(|s| format!(", mean {:+.4} mm, RMS {:.4} mm", s.mean_mm, s.rms_mm))
            .unwrap_or_default();
        let newest = self
            .newest_mm
            .map(|d| format!(", now {d:+.4} mm"))
            .unwrap_or_default();
        self.bar
            .set_message(format!("{profile} {} points{running}{newest}", self.points));
    }
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

    /// Shows one event; returns how the job ended (or stopped) when this event ends (or stops) it. Fails only when
    /// standard output is closed.
    pub fn show(&mut self, event: &Event) -> anyhow::Result<Option<JobEnd>> {
        if let Some(id) = event_job(event) {
            match &self.job {
                Some(job) if job != id => return Ok(None),
                None => self.job = Some(id.to_string()),
                _ => {}
            }
        }
        match event {
            Event::JobStarted { job, done } => self.lay_out(job, done)?,
            Event::ScanStarted { machine, scan, .. } => {
                if let Some(instance) = self.instances.get_mut(&scan.instance) {
                    instance.newest_mm = None;
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
                    instance.show_scanning(&scan.profile);
                }
            }
            Event::PointPreview {
                scan,
                deviation_mm,
                ..
            } => {
                // The newest point's deviation as it arrives; it is counted when its `Point` comes.
                if let Some(instance) = self.instances.get_mut(&scan.instance) {
                    instance.newest_mm = *deviation_mm;
                    instance.show_scanning(&scan.profile);
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
                ))?;
            }
            Event::SectionEvaluated {
                scan,
                best_fits,
                parameters,
                ..
            } => {
                if let Some(text) = section_line(best_fits, parameters.as_deref()) {
                    self.line(format!("{} {}: {text}", scan.instance, scan.profile))?;
                }
            }
            Event::JobStopped {
                job,
                reason,
                next_step,
                ..
            } => {
                self.line(format!("STOPPED: {reason}\n  next: {next_step}"))?;
                return Ok(Some(JobEnd::Stopped {
                    job: job.clone(),
                    reason: reason.clone(),
                    next_step: next_step.clone(),
                }));
            }
            Event::JobResumed { job } => self.line(format!("job {job} resumed"))?,
            Event::ProfileRescanned {
                machine,
                scan,
                reason,
                ..
            } => self.line(format!(
                "{} {} on {machine} scanned again: {reason}",
                scan.instance, scan.profile
            ))?,
            Event::ReferenceSaved { path, profiles, .. } => {
                self.finish_bars();
                self.line(format!("reference saved: {}", path.display()))?;
                for fit in profiles {
                    let distance = match (fit.rms_mm, fit.max_mm) {
                        (Some(rms), Some(max)) => format!("fit RMS {rms:.4} mm, max {max:.4} mm"),
                        _ => "no fit distances kept by this reference kind".to_string(),
                    };
                    self.line(format!("  {}: {} points, {distance}", fit.profile, fit.points))?;
                    for doubt in &fit.doubts {
                        self.line(format!("    warning: {doubt}"))?;
                    }
                }
                return Ok(Some(JobEnd::Finished { verdict: None }));
            }
            Event::JobFinished {
                report,
                instances,
                verdict,
                ..
            } => {
                self.finish_bars();
                self.line(instance_table(instances))?;
                if let Some(report) = report {
                    self.line(format!("report: {}", report.display()))?;
                    let html = report.join(crate::report::HTML_FILE);
                    self.line(format!("open in a browser: {}", html.display()))?;
                }
                return Ok(Some(JobEnd::Finished {
                    verdict: verdict.clone(),
                }));
            }
            Event::JobAborted { job } => {
                self.finish_bars();
                self.line(format!("job {job} aborted"))?;
                return Ok(Some(JobEnd::Aborted { job: job.clone() }));
            }
            Event::JobFailed { error, .. } => {
                self.finish_bars();
                self.line(format!("FAILED: {error}"))?;
                return Ok(Some(JobEnd::Failed(error.clone())));
            }
            Event::Lagged { missed } => self.line(format!(
                "(this display fell behind and missed {missed} events; the daemon and its report missed none)"
            ))?,
        }
        Ok(None)
    }

    /// A bar per instance, each already advanced by its profiles in `done` (on disk before a resume).
    fn lay_out(&mut self, job: &JobInfo, done: &[ScanRef]) -> anyhow::Result<()> {
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
            "job {} ({what}): {} x {} on {}; deviations in mm, tolerance {:+.3} .. {:+.3} mm{}",
            job.id,
            counted(job.instances.len(), "instance"),
            counted(job.profiles.len(), "profile"),
            job.machines.join(", "),
            job.tolerance_mm[0],
            job.tolerance_mm[1],
            if done.is_empty() {
                String::new()
            } else {
                format!(", {} already done", counted(done.len(), "profile"))
            }
        ))?;
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
                    newest_mm: None,
                },
            );
        }
        for scan in done {
            if let Some(instance) = self.instances.get(&scan.instance) {
                instance.bar.inc(1);
            }
        }
        Ok(())
    }

    fn finish_bars(&mut self) {
        for (_, instance) in self.instances.drain() {
            instance.bar.finish_and_clear();
        }
    }

    fn line(&self, text: String) -> anyhow::Result<()> {
        if self.quiet {
            return Ok(());
        }
        if self.bars.is_hidden() {
            outln!("{text}")
        } else {
            // Above the bars on the terminal (standard error); a terminal that went away ends nothing here.
            let _ = self.bars.println(text);
            Ok(())
        }
    }
}

/// "1 instance", "3 instances".
fn console_is_terminal() -> bool {
    use std::io::IsTerminal;
    std::io::stderr().is_terminal()
}

/// A section's evaluation in a line: where its least-squares fit puts it, then its parameters off nominal.
fn section_line(
    best_fits: &[SectionBestFit],
    parameters: Option<&SectionParametersReport>,
) -> Option<String> {
    let fit = best_fits.iter().find(|f| f.method == "l2").map(|f| {
        let held = f
            .held_at()
            .map(|held| format!(" (the fit held at its limit {held}; the rest is in the form)"))
            .unwrap_or_default();
        format!(
            "lies {:+.4} mm along its thickness and {:+.4} mm along its chord, twist {:+.4} deg, form RMS {:.4} mm{held}",
            f.dn_mm, f.dchord_mm, f.rotation_deg, f.form.rms_mm
        )
    });
    let parameters = parameters.map(|p| {
        let pitch = p
            .pitch_mm
            .map(|v| format!(", pitch {:+.3} %", 100.0 * v.deviation / v.nominal))
            .unwrap_or_default();
        let verdict = parameters_verdict_text(p)
            .map(|text| format!(": {text}"))
            .unwrap_or_default();
        format!(
            "off nominal: max thickness {:+.4} mm, chord {:+.4} mm, camber {:+.4} mm, chord angle {:+.4} deg{pitch}{verdict}",
            p.max_thickness_mm.deviation,
            p.chord_mm.deviation,
            p.max_camber_mm.deviation,
            p.chord_angle_deg.deviation
        )
    });
    match (fit, parameters) {
        (None, None) => None,
        (fit, parameters) => Some(
            fit.into_iter()
                .chain(parameters)
                .collect::<Vec<_>>()
                .join("; "),
        ),
    }
}

/// A section's verdict on its toleranced parameters and whose tolerances they were, each failure with its
/// deviation and limits, e.g. "FAIL (ISO 484 class S): pitch_mm -21.3000 mm outside [-20.0000, +20.0000] mm";
/// `None` where no parameter has a tolerance.
fn parameters_verdict_text(parameters: &SectionParametersReport) -> Option<String> {
    let verdict = parameters.verdict?;
    let mut sources: Vec<String> = Vec::new();
    for (_, value) in parameters.judged() {
        if let Some(tolerance) = value.tolerance {
            let source = tolerance.from.to_string();
            if !sources.contains(&source) {
                sources.push(source);
            }
        }
    }
    let sources = sources.join(" and ");
    Some(match verdict {
        ParameterVerdict::Pass => format!("PASS ({sources})"),
        ParameterVerdict::Fail => {
            let failures: Vec<String> = parameters
                .out_of_tolerance()
                .into_iter()
                .filter_map(|(name, value)| failure_text(name, value))
                .collect();
            format!("FAIL ({sources}): {}", failures.join(", "))
        }
    })
}

fn event_job(event: &Event) -> Option<&str> {
    match event {
        Event::JobStarted { job, .. } => Some(&job.id),
        Event::ScanStarted { job, .. }
        | Event::Point { job, .. }
        | Event::PointPreview { job, .. }
        | Event::ProfileDone { job, .. }
        | Event::SectionEvaluated { job, .. }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scan(instance: &str, profile: &str) -> ScanRef {
        ScanRef {
            instance: instance.into(),
            profile: profile.into(),
        }
    }

    fn bar_positions(watch: &Watch) -> Vec<(String, u64)> {
        let mut positions: Vec<_> = watch
            .instances
            .iter()
            .map(|(name, i)| (name.clone(), i.bar.position()))
            .collect();
        positions.sort();
        positions
    }

    #[test]
    fn a_resumed_job_s_bars_count_the_profiles_done_before_the_stop() {
        let job = JobInfo {
            id: "j".into(),
            kind: JobKind::Inspect,
            part: "propeller".into(),
            serial: Some("SN-1".into()),
            instances: vec!["A".into(), "B".into(), "C".into()],
            profiles: vec!["r100".into(), "r200".into(), "r300".into()],
            machines: vec!["cmm1".into()],
            tolerance_mm: [-0.1, 0.1],
        };
        let mut watch = Watch::new(None, true);
        let started = Event::JobStarted {
            job,
            done: vec![scan("A", "r100"), scan("A", "r200"), scan("B", "r100")],
        };
        assert_eq!(watch.show(&started).unwrap(), None);
        let expected = |a, b, c| {
            vec![
                ("A".to_string(), a),
                ("B".to_string(), b),
                ("C".to_string(), c),
            ]
        };
        assert_eq!(bar_positions(&watch), expected(2, 1, 0));
        let done = Event::ProfileDone {
            job: "j".into(),
            machine: "cmm1".into(),
            scan: scan("A", "r300"),
            points: 10,
            stats: None,
            verdict: None,
            at_unix_ms: 0,
        };
        watch.show(&done).unwrap();
        assert_eq!(bar_positions(&watch), expected(3, 1, 0));
    }

    #[test]
    fn a_stop_is_reported_as_such_and_counts_read_in_the_singular() {
        let mut watch = Watch::new(Some("j".into()), true);
        let stopped = Event::JobStopped {
            job: "j".into(),
            machine: Some("cmm1".into()),
            scan: None,
            reason: "emergency stop".into(),
            next_step: "run `zeroset clear`".into(),
        };
        assert_eq!(
            watch.show(&stopped).unwrap(),
            Some(JobEnd::Stopped {
                job: "j".into(),
                reason: "emergency stop".into(),
                next_step: "run `zeroset clear`".into(),
            })
        );
        // Another job's events are not this watch's.
        let other = Event::JobAborted { job: "k".into() };
        assert_eq!(watch.show(&other).unwrap(), None);
        assert_eq!(counted(1, "instance"), "1 instance");
        assert_eq!(counted(3, "profile"), "3 profiles");
    }

    #[test]
    fn a_sections_line_gives_its_parameters_verdict_naming_each_failure_and_its_limits() {
        use crate::analysis::tolerances::{
            Iso484Class, ParameterRules, ParameterTolerances, ToleranceRule,
        };
        // B r100 of the sample: pitch 899.897 mm nominal, -1.277 mm off (-0.142 %), thickness -0.0382 mm.
        let mut within = crate::report::tests::sample_parameters();
        ParameterTolerances::new(Some(Iso484Class::S), ParameterRules::default())
            .judge_section(&mut within);
        let line = section_line(&[], Some(&within)).unwrap();
        assert!(
            line.ends_with("pitch -0.142 %: PASS (ISO 484 class S)"),
            "{line}"
        );
        // The part file holds the thickness to 0.03 mm: it fails, and the line says by how much.
        let thin = ParameterRules {
            max_thickness_mm: Some(ToleranceRule {
                lower: Some(-0.03),
                upper: Some(0.03),
                ..ToleranceRule::default()
            }),
            ..ParameterRules::default()
        };
        let mut failing = crate::report::tests::sample_parameters();
        ParameterTolerances::new(Some(Iso484Class::S), thin).judge_section(&mut failing);
        let line = section_line(&[], Some(&failing)).unwrap();
        assert!(
            line.ends_with(
                ": FAIL (ISO 484 class S and the part file): max_thickness_mm -0.0382 mm outside [-0.0300, +0.0300] mm"
            ),
            "{line}"
        );
        // Nothing toleranced, no verdict.
        let line = section_line(&[], Some(&crate::report::tests::sample_parameters())).unwrap();
        assert!(line.ends_with("pitch -0.142 %"), "{line}");
    }
}
