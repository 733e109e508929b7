//! The logged report of one inspected part: what was measured, on which machines, against which reference, by
//! which distance and compensation, every point with its deviation, the statistics and the verdicts. One folder
//! per part holds report.json (everything), deviations.csv (one row per point) and summary.txt (for the operator).

mod export;
mod html;
mod individuals;
mod parameter_trend;
mod plots;
mod qif;
mod store;
mod summary;
mod trend;
mod trend_chart;
mod trend_html;
mod writers;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::analysis::section::{
    ParameterValue, SectionBestFit, SectionDistribution, SectionParametersReport,
};
use crate::analysis::stats::{DeviationStats, Tolerance, Verdict};
use crate::analysis::tolerances::Iso484Class;
pub use export::history_csv;
pub use html::{write_html, HTML_FILE};
pub use parameter_trend::{parameter_trend, parameter_trend_text, ParameterTrendRow};
pub use qif::{write_qif, QIF_FILE};
pub use store::{ParameterRecord, ProfileRecord, Store, StoreError, STORE_FILE};
pub use summary::summary_text;
pub use trend::{trend, trend_text, TrendRow};
pub use trend_html::{write_trend_html, TREND_FILE};
pub use writers::{
    write_report, write_sections, DEVIATIONS_FILE, REFERENCE_FILE, REPORT_FILE, SECTIONS_DIR,
    SUMMARY_FILE,
};

pub const FORMAT: &str = "zeroset-report";
pub const VERSION: u32 = 1;
pub const UNITS: &str = "mm";

/// The report of one inspected part.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct PartReport {
    /// [`FORMAT`], [`VERSION`] and [`UNITS`].
    pub format: String,
    pub version: u32,
    pub units: String,
    pub part: String,
    pub serial: String,
    pub job: String,
    /// RFC 3339.
    pub started: String,
    pub finished: String,
    pub machines: Vec<MachineUse>,
    pub reference: ReferenceUse,
    /// How deviations were measured, e.g. "exact orthogonal distance to each profile's 2-D IP".
    pub distance: String,
    /// How ball centres became surface points, e.g. "ball radius along the reported normal".
    pub compensation: String,
    pub tolerance: Tolerance,
    /// The ISO 484 class the parameters were judged by, where the part file names one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iso484: Option<ClassUse>,
    pub instances: Vec<InstanceReport>,
    /// For a propeller: its mean pitch, the mean of its blades' mean pitches, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub propeller_pitch_mm: Option<ParameterValue>,
    /// Pass iff every instance passes and the propeller's mean pitch is within its tolerance.
    pub verdict: Verdict,
    /// Profiles scanned again because a scan came back with a hole in it (absent from older reports).
    #[serde(default)]
    pub rescans: Vec<Rescan>,
}

/// An ISO 484 class and where its table comes from.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct ClassUse {
    pub class: Iso484Class,
    pub cites: String,
}

/// A profile scanned again, and why.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct Rescan {
    pub instance: String,
    pub profile: String,
    /// What was wrong with the first scan: where its gap was and how long, mm.
    pub reason: String,
    /// RFC 3339.
    pub at: String,
}

/// A machine that scanned some of the part's profiles.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct MachineUse {
    pub name: String,
    pub ball_radius_mm: f64,
    pub profiles_scanned: usize,
}

/// The reference the deviations were measured against.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct ReferenceUse {
    pub path: String,
    pub taught_at: String,
    /// The kind of model and how it was fitted, in words.
    pub model: String,
}

impl ReferenceUse {
    /// One line for the reports' headers: where, when, what.
    pub fn describe(&self) -> String {
        format!("{} (taught {}; {})", self.path, self.taught_at, self.model)
    }
}

/// One instance (blade) of the part: its statistics over all its profiles and their reports.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct InstanceReport {
    pub name: String,
    pub stats: DeviationStats,
    pub verdict: Verdict,
    /// For a propeller's blade: how far it is turned about the hub axis from its place, deg (in the sense of the
    /// instances' step), from its sections' least-squares fits; absent for other parts and in older reports.
    #[serde(default)]
    pub index_deg: Option<f64>,
    /// ... and its angular spacing from the blade before it (the first blade's from the last), deg.
    #[serde(default)]
    pub angular_spacing_deg: Option<ParameterValue>,
    /// For a propeller's blade: its mean pitch, the mean of its sections' pitches, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blade_pitch_mm: Option<ParameterValue>,
    pub profiles: Vec<ProfileReport>,
}

/// One scanned profile of an instance, with every point.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct ProfileReport {
    pub name: String,
    pub x_mm: f64,
    pub machine: String,
    /// RFC 3339.
    pub scanned_at: String,
    pub stats: DeviationStats,
    pub verdict: Verdict,
    /// The section's best fits to its reference (least squares, then minimum zone): where it lies, its twist and
    /// its form once those are removed. Empty in older reports, or where the section could not be fitted.
    #[serde(default)]
    pub best_fits: Vec<SectionBestFit>,
    /// The section's parameters measured beside its reference's (chord, thicknesses, camber, chord angle, pitch).
    /// Absent in older reports, for parts whose reference is a solid, or where the section has none (said in the
    /// daemon's log).
    #[serde(default)]
    pub parameters: Option<SectionParametersReport>,
    /// The section's thickness and camber along its chord, nominal and measured, where it has parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub distribution: Option<SectionDistribution>,
    pub points: Vec<PointRecord>,
}

/// One measured point: as reported, compensated, and its deviation.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct PointRecord {
    /// Ball centre and outward unit normal as the machine reported them (machine frame, mm).
    pub centre: [f64; 3],
    pub normal: [f64; 3],
    /// The compensated surface point (machine frame, mm).
    pub surface: [f64; 3],
    pub deviation_mm: f64,
    pub off_plane_mm: f64,
    /// The I++ quality the machine reported with the point.
    pub quality: f64,
    /// Compensation flagged the contact as not unique (a cusp: the surface more concave than the ball): the point
    /// is kept but left out of the statistics and the verdict. Absent (false) in older reports.
    #[serde(default)]
    pub flagged: bool,
    /// The deviation once the section's least-squares best fit (its shift and twist) is removed, mm: its form
    /// error at this point. Absent for flagged points, where the section could not be fitted, and in older
    /// reports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub after_fit_mm: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReportError {
    #[error("{path}: cannot read the report: {problem}")]
    Read { path: String, problem: String },
    #[error("{path}: not a readable report: {problem}")]
    Parse { path: String, problem: String },
    #[error("{path}: {problem}; read it with the zeroset version that wrote it")]
    Unsupported { path: String, problem: String },
}

/// Reads the report.json of a part's report folder (for `zeroset report`).
pub fn read_report(dir: &Path) -> Result<PartReport, ReportError> {
    let path = dir.join(REPORT_FILE);
    let shown = || path.display().to_string();
    let text = std::fs::read_to_string(&path).map_err(|e| ReportError::Read {
        path: shown(),
        problem: e.to_string(),
    })?;
    let report: PartReport = serde_json::from_str(&text).map_err(|e| ReportError::Parse {
        path: shown(),
        problem: e.to_string(),
    })?;
    let unsupported = if report.format != FORMAT {
        Some(format!("format '{}' is not '{FORMAT}'", report.format))
    } else if report.version != VERSION {
        Some(format!(
            "version {} is not supported (this build reads version {VERSION})",
            report.version
        ))
    } else if report.units != UNITS {
        Some(format!(
            "units '{}' (only {UNITS} are supported)",
            report.units
        ))
    } else {
        None
    };
    match unsupported {
        Some(problem) => Err(ReportError::Unsupported {
            path: shown(),
            problem,
        }),
        None => Ok(report),
    }
}

#[cfg(test)]
pub(crate) mod tests;
