//! report.qif: the part's inspection as a QIF 3.0 Results document (valid against QIFDocument.xsd), for plant
//! systems that import QIF. Each profile of each instance is one line-profile characteristic with its tolerance
//! zone, its measured point set, its form value, its worst deviations and its status; the actual component
//! carries the part's serial number. Each blade parameter (a section's chord, thicknesses, edge radii, camber,
//! chord angle and pitch; a blade's mean pitch and angular spacing; the propeller's mean pitch) is a length,
//! thickness, radius or angle characteristic with its nominal, tolerance, value and status. Lengths are in mm,
//! angles in degrees.

mod document;
mod elements;
mod ids;
mod parameters;
mod qpid;
mod results;

use std::path::Path;

use super::PartReport;
use crate::analysis::stats::DeviationStats;
use crate::fsutil::write_atomically;

pub const QIF_FILE: &str = "report.qif";

/// What a line-profile characteristic's measured value is, written into the document (comment and description)
/// so that an importer does not have to guess.
const FORM_VALUE_MEANING: &str = "Each line-profile characteristic's measured Value is the profile's form value \
     2 x max |deviation| (the width of the zone centred on the nominal curve that holds every point, comparable \
     with ToleranceValue); WorstPositiveDeviation and WorstNegativeDeviation are the largest and the smallest \
     signed deviation (positive = outside the material).";

/// Writes `dir`/report.qif atomically. The error names the file.
pub fn write_qif(dir: &Path, report: &PartReport) -> std::io::Result<()> {
    let path = dir.join(QIF_FILE);
    let bytes = document::qif_document(report).map_err(|e| {
        std::io::Error::new(e.kind(), format!("cannot write {}: {e}", path.display()))
    })?;
    write_atomically(&path, &bytes)
}

/// A profile's form value as QIF's line-profile Value: 2 x max |deviation|, the width of the tolerance zone
/// centred on the nominal that just holds every point (ASME's actual value of a profile tolerance). It is the
/// number to compare with the zone's width, upper - lower, when the zone is centred on the nominal.
fn form_value_mm(stats: &DeviationStats) -> f64 {
    2.0 * stats.worst_mm.abs()
}

#[cfg(test)]
mod tests;
