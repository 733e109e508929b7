//! What the campaign injects and when, drawn from a seeded generator: the same seed gives the same faults with
//! the same arguments at the same moments (counted in the job's events, so the machine's pace does not change
//! them; what each fault then meets on the line can still differ from run to run by a few milliseconds).

use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

/// Every fault the simulator injects, and the daemon's `kill -9`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Kind {
    Garbage,
    DropLines,
    Delay,
    Disconnect,
    Estop,
    Collision,
    NoTouch,
    SurfaceNotFound,
    KillDaemon,
}

impl Kind {
    pub(crate) const ALL: [Kind; 9] = [
        Kind::Garbage,
        Kind::DropLines,
        Kind::Delay,
        Kind::Disconnect,
        Kind::Estop,
        Kind::Collision,
        Kind::NoTouch,
        Kind::SurfaceNotFound,
        Kind::KillDaemon,
    ];

    pub(crate) fn name(self) -> &'static str {
        match self {
            Kind::Garbage => "garbage",
            Kind::DropLines => "drop-lines",
            Kind::Delay => "delay",
            Kind::Disconnect => "disconnect",
            Kind::Estop => "estop",
            Kind::Collision => "collision",
            Kind::NoTouch => "no-touch",
            Kind::SurfaceNotFound => "surface-not-found",
            Kind::KillDaemon => "kill -9 daemon",
        }
    }
}

/// One fault with its argument (lines dropped, milliseconds of delay or of a dead line).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Fault {
    pub(crate) kind: Kind,
    pub(crate) arg: Option<u64>,
}

impl Fault {
    /// The simulator's control line for `machine`, or None for the daemon's kill (the campaign does that).
    pub(crate) fn control_line(&self, machine: &str) -> Option<String> {
        (self.kind != Kind::KillDaemon).then(|| format!("fault {machine} {self}"))
    }
}

impl std::fmt::Display for Fault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.arg {
            Some(arg) => write!(f, "{} {arg}", self.kind.name()),
            None => f.write_str(self.kind.name()),
        }
    }
}

/// When a fault goes in, counted from the previous fault (or the job's start): after so many more measured
/// points (inside a scan), or so many milliseconds after the next profile is done (its lift-off, the travel
/// to the next profile, the descent to its entry: at the simulator's 100x these take tens of milliseconds).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Moment {
    AfterPoints(usize),
    AfterProfileDone { ms: u64 },
}

impl std::fmt::Display for Moment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Moment::AfterPoints(n) => write!(f, "{n} points on"),
            Moment::AfterProfileDone { ms } => write!(f, "{ms} ms after a profile"),
        }
    }
}

/// The longest a reply may be delayed: beyond the campaign station's 3 s timeouts, so that some delays stop
/// the job (a lost line) and the rest must not.
const DELAY_MS: std::ops::RangeInclusive<u64> = 100..=4500;
const DEAD_LINE_MS: std::ops::RangeInclusive<u64> = 200..=1500;
const DROPPED_LINES: std::ops::RangeInclusive<u64> = 1..=3;
/// Points between faults: an inspection measures about 5 900, so a job meets five or six faults on average.
const POINTS_BETWEEN: std::ops::RangeInclusive<usize> = 1..=1800;
/// How long after a profile's end a fault between scans goes in.
const AFTER_PROFILE_MS: std::ops::RangeInclusive<u64> = 0..=60;

/// The seeded source of faults and moments.
pub(crate) struct Planner {
    rng: StdRng,
}

impl Planner {
    pub(crate) fn new(seed: u64) -> Planner {
        Planner {
            rng: StdRng::seed_from_u64(seed),
        }
    }

    /// The next fault, every kind equally likely, and its moment: one in four between scans.
    pub(crate) fn next(&mut self) -> (Fault, Moment) {
        let kind = Kind::ALL[self.rng.gen_range(0..Kind::ALL.len())];
        let arg = match kind {
            Kind::DropLines => Some(self.rng.gen_range(DROPPED_LINES)),
            Kind::Delay => Some(self.rng.gen_range(DELAY_MS)),
            Kind::Disconnect => Some(self.rng.gen_range(DEAD_LINE_MS)),
            _ => None,
        };
        let moment = if self.rng.gen_bool(0.25) {
            Moment::AfterProfileDone {
                ms: self.rng.gen_range(AFTER_PROFILE_MS),
            }
        } else {
            Moment::AfterPoints(self.rng.gen_range(POINTS_BETWEEN))
        };
        (Fault { kind, arg }, moment)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_seed_gives_the_same_plan_and_every_kind_comes_up() {
        let mut planner = Planner::new(7);
        let first: Vec<_> = (0..200).map(|_| planner.next()).collect();
        let mut again = Planner::new(7);
        assert!(first.iter().all(|planned| *planned == again.next()));
        let mut other = Planner::new(8);
        assert!(first.iter().any(|planned| *planned != other.next()));
        for kind in Kind::ALL {
            assert!(first.iter().any(|(f, _)| f.kind == kind), "{kind:?}");
        }
        let lines: Vec<_> = first
            .iter()
            .filter_map(|(f, _)| f.control_line("cmm1"))
            .collect();
        assert!(lines
            .iter()
            .any(|l| l.starts_with("fault cmm1 drop-lines ")));
        assert!(lines.iter().all(|l| !l.contains("kill")));
        // Every line is one the simulator reads.
        for line in &lines {
            zeroset_sim::faults::FaultRequest::parse(line).unwrap();
        }
    }
}
