//! The campaign's counts and violations, and the summary it prints.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::time::Duration;

use super::plan::Kind;

#[derive(Default)]
pub(crate) struct Tally {
    pub(crate) seed: u64,
    pub(crate) injected: BTreeMap<Kind, usize>,
    /// Seen to take effect in the simulator's transcript (drop-lines: lines dropped; kill: done by the campaign).
    pub(crate) fired: BTreeMap<Kind, usize>,
    /// Job stops that followed each kind (the stop is put down to the latest fault before it).
    pub(crate) stops: BTreeMap<Kind, usize>,
    pub(crate) violations: Vec<String>,
    pub(crate) jobs_finished: usize,
    /// Jobs that could not go on, with the operator's last word.
    pub(crate) jobs_stuck: Vec<String>,
    /// Profiles the station scanned again after finding a hole in them.
    pub(crate) gap_rescans: usize,
    pub(crate) clears: usize,
    /// Refused clears by their reason, as the CLI gave it.
    pub(crate) refusals: BTreeMap<String, usize>,
    /// Daemon restarts an operator needed because clear kept failing.
    pub(crate) restarts_to_clear: usize,
    /// Fresh stations (simulator and daemon) for jobs left stuck.
    pub(crate) stations: usize,
    /// Events a watcher missed by falling behind.
    pub(crate) lagged: u64,
    /// The faults' phase: from the first job's start to the last job's end.
    pub(crate) elapsed: Duration,
    pub(crate) transcripts: Vec<String>,
}

impl Tally {
    pub(crate) fn injected_total(&self) -> usize {
        self.injected.values().sum()
    }

    pub(crate) fn faults_a_minute(&self) -> f64 {
        self.injected_total() as f64 / (self.elapsed.as_secs_f64() / 60.0)
    }

    pub(crate) fn refused(&mut self, message: &str) {
        // Positions vary from one refusal to the next: each decimal number is folded to `#`, so that refusals of
        // one cause count together, and the first 200 characters of what is left name it (a refused way out's
        // GoTo and the machine's answer to it).
        let key: String = fold_decimals(message.trim()).chars().take(200).collect();
        *self.refusals.entry(key).or_default() += 1;
    }

    pub(crate) fn summary(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "fault campaign, seed {}: {} faults in {} jobs ({} finished, {} could not go on), {:.1} min, {:.1} faults a minute",
            self.seed,
            self.injected_total(),
            self.jobs_finished + self.jobs_stuck.len(),
            self.jobs_finished,
            self.jobs_stuck.len(),
            self.elapsed.as_secs_f64() / 60.0,
            self.faults_a_minute()
        );
        let _ = writeln!(
            out,
            "{:<20} {:>8} {:>8} {:>8}",
            "fault", "injected", "fired", "stops"
        );
        for kind in Kind::ALL {
            let fired = match kind {
                // A delay leaves no mark of its own in the transcript.
                Kind::Delay => "-".to_string(),
                Kind::KillDaemon => self.count(&self.injected, kind).to_string(),
                _ => self.count(&self.fired, kind).to_string(),
            };
            let _ = write!(
                out,
                "{:<20} {:>8} {:>8} {:>8}",
                kind.name(),
                self.count(&self.injected, kind),
                fired,
                self.count(&self.stops, kind)
            );
            match kind {
                Kind::DropLines => out.push_str("   (fired: reply lines dropped)"),
                Kind::Collision | Kind::SurfaceNotFound => {
                    out.push_str("   (armed twice before a move fires once)")
                }
                Kind::NoTouch => out.push_str("   (armed twice before a scan fires once)"),
                _ => {}
            }
            out.push('\n');
        }
        let _ = writeln!(
            out,
            "profiles rescanned for a hole: {}; clears: {} ({} refused); daemon restarts to clear: {}; fresh stations: {}; events missed by the watcher: {}",
            self.gap_rescans,
            self.clears,
            self.refusals.values().sum::<usize>(),
            self.restarts_to_clear,
            self.stations,
            self.lagged
        );
        for (reason, n) in &self.refusals {
            let _ = writeln!(out, "  clear refused {n} x: {reason}");
        }
        for stuck in &self.jobs_stuck {
            let _ = writeln!(out, "could not go on: {stuck}");
        }
        let _ = writeln!(out, "violations: {}", self.violations.len());
        for (what, n) in self.violation_kinds() {
            let _ = writeln!(out, "  {n:>5} {what}");
        }
        for violation in &self.violations {
            let _ = writeln!(out, "  VIOLATION {violation}");
        }
        let _ = writeln!(
            out,
            "simulator transcripts: {}",
            self.transcripts.join(", ")
        );
        out
    }

    /// The violations counted by what went wrong.
    pub(crate) fn violation_kinds(&self) -> BTreeMap<&'static str, usize> {
        const KINDS: [(&str, &str); 8] = [
            ("motion ", "motion after an error before ClearAllErrors"),
            (
                "that no injected fault explains",
                "a collision or missing surface of the station's own",
            ),
            ("): report: ", "points lost or added in the report"),
            (
                "): history: ",
                "the history not holding the inspection once, whole",
            ),
            ("scanned again", "a complete profile scanned again"),
            (
                "does not count it",
                "a complete profile forgotten at a resume",
            ),
            (
                "last word does not name",
                "a job that could not go on, its message incomplete",
            ),
            (
                "clear failed",
                "clear kept failing until the daemon was restarted",
            ),
        ];
        let mut kinds = BTreeMap::new();
        for violation in &self.violations {
            let kind = KINDS
                .iter()
                .find(|(mark, _)| violation.contains(mark))
                .map_or("other", |(_, kind)| kind);
            *kinds.entry(kind).or_default() += 1;
        }
        kinds
    }

    fn count(&self, counts: &BTreeMap<Kind, usize>, kind: Kind) -> usize {
        counts.get(&kind).copied().unwrap_or(0)
    }
}

/// `text` with each decimal number (a run of digits, signs and points holding a point) written `#`; codes and
/// names such as `0006` and `cmm1` stay.
fn fold_decimals(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut number = String::new();
    let flush = |number: &mut String, out: &mut String| {
        if number.contains('.') && number.chars().any(|c| c.is_ascii_digit()) {
            out.push('#');
        } else {
            out.push_str(number);
        }
        number.clear();
    };
    for c in text.chars() {
        if c.is_ascii_digit() || c == '.' || c == '-' {
            number.push(c);
        } else {
            flush(&mut number, &mut out);
            out.push(c);
        }
    }
    flush(&mut number, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::fold_decimals;

    #[test]
    fn refusals_differing_only_in_positions_read_the_same() {
        assert_eq!(
            fold_decimals("not cleared: machine cmm1: GoTo(X(-10.62), Y(5.0), Z(75)): error 0006 (severity 2)."),
            "not cleared: machine cmm1: GoTo(X(#), Y(#), Z(75)): error 0006 (severity 2)."
        );
    }
}
