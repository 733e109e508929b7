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

/// Whether a profile, instance or part is within tolerance: every point within the part's band, and every
/// toleranced parameter (of its sections, blades, the part) within its limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "verdict", rename_all = "snake_case")]
pub enum Verdict {
    Pass,
    Fail {
        points_outside: usize,
        /// The largest |deviation| of a point, whether or not a point is outside.
        worst_mm: f64,
        /// Parameters out of their tolerance (absent in older reports, and when none is).
        #[serde(default, skip_serializing_if = "is_zero")]
        parameters_outside: usize,
    },
}

/// "1 point", "2 points".
pub(crate) fn counted(count: usize, noun: &str) -> String {
    format!("{count} {noun}{}", if count == 1 { "" } else { "s" })
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

impl Verdict {
    /// The verdict of a whole made of parts (an instance of its profiles, a part of its instances): it passes iff
    /// every part passes; a failure counts every point and parameter outside and keeps the largest |worst|.
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
                        parameters_outside,
                    },
                    Verdict::Fail {
                        points_outside: more,
                        worst_mm: other,
                        parameters_outside: more_parameters,
                    },
                ) => Verdict::Fail {
                    points_outside: points_outside + more,
                    worst_mm: if other.abs() > worst_mm.abs() {
                        *other
                    } else {
                        worst_mm
                    },
                    parameters_outside: parameters_outside + more_parameters,
                },
            })
    }

    /// This verdict with `parameters` more parameters out of tolerance, of a whole whose largest |deviation| is
    /// `worst_mm`.
    pub fn with_parameters_outside(self, parameters: usize, worst_mm: f64) -> Verdict {
        if parameters == 0 {
            return self;
        }
        let failed = Verdict::Fail {
            points_outside: 0,
            worst_mm,
            parameters_outside: parameters,
        };
        Verdict::combine([&self, &failed])
    }

    /// What failed, with the worst deviation (mm): "2 points outside the tolerance, worst +0.1200 mm, 1 parameter
    /// out of tolerance", or "1 parameter out of tolerance (every point within, worst +0.0300 mm)"; `None` for a
    /// pass.
    pub fn what_failed(&self) -> Option<String> {
        let Verdict::Fail {
            points_outside,
            worst_mm,
            parameters_outside,
        } = self
        else {
            return None;
        };
        let parameters = format!(
            "{} out of tolerance",
            counted(*parameters_outside, "parameter")
        );
        Some(match (points_outside, parameters_outside) {
            (0, _) => format!("{parameters} (every point within, worst {worst_mm:+.4} mm)"),
            (n, 0) => format!(
                "{} outside the tolerance, worst {worst_mm:+.4} mm",
                counted(*n, "point")
            ),
            (n, _) => format!(
                "{} outside the tolerance, worst {worst_mm:+.4} mm, {parameters}",
                counted(*n, "point")
            ),
        })
    }

    /// The verdict in a table's cell, beside a column of the worst deviation: "PASS", "FAIL (2 outside)",
    /// "FAIL (0 outside, 1 parameter)".
    pub fn cell_text(&self) -> String {
        match self {
            Verdict::Pass => "PASS".to_string(),
            Verdict::Fail {
                points_outside,
                parameters_outside: 0,
                ..
            } => format!("FAIL ({points_outside} outside)"),
            Verdict::Fail {
                points_outside,
                parameters_outside,
                ..
            } => format!(
                "FAIL ({points_outside} outside, {})",
                counted(*parameters_outside, "parameter")
            ),
        }
    }

    pub fn passed(&self) -> bool {
        *self == Verdict::Pass
    }
}
