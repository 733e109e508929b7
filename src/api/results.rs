//! Results as the control API carries them: deviation statistics and tolerance verdicts. They live here, not in
//! the analysis that computes them, so that the API's types depend on nothing of the station.

use serde::{Deserialize, Serialize};

/// A summary of deviations, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DeviationStats {
    pub points: usize,
    pub mean_mm: f64,
    pub rms_mm: f64,
    /// Population standard deviation (divided by the number of points), so that rms^2 = mean^2 + std^2.
    pub std_mm: f64,
    pub min_mm: f64,
    pub max_mm: f64,
    /// The point of largest |deviation| and where it is (machine frame, mm).
    pub worst_mm: f64,
    pub worst_at_mm: [f64; 3],
}

/// Whether a profile, instance or part is within tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "verdict", rename_all = "snake_case")]
pub enum Verdict {
    Pass,
    Fail {
        points_outside: usize,
        worst_mm: f64,
    },
}

impl Verdict {
    /// The verdict of a whole made of parts (an instance of its profiles, a part of its instances): it passes iff
    /// every part passes; a failure counts every point outside and keeps the largest |worst|.
    pub fn combine<'a>(verdicts: impl IntoIterator<Item = &'a Verdict>) -> Verdict {
        verdicts
            .into_iter()
            .fold(Verdict::Pass, |whole, part| match (whole, part) {
                (whole, Verdict::Pass) => whole,
                (Verdict::Pass, failed) => failed.clone(),
                (
                    Verdict::Fail {
                        points_outside,
                        worst_mm,
                    },
                    Verdict::Fail {
                        points_outside: more,
                        worst_mm: other,
                    },
                ) => Verdict::Fail {
                    points_outside: points_outside + more,
                    worst_mm: if other.abs() > worst_mm.abs() {
                        *other
                    } else {
                        worst_mm
                    },
                },
            })
    }

    pub fn passed(&self) -> bool {
        *self == Verdict::Pass
    }
}
