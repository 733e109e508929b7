//! Writes a part's report folder. Each file is written to a temporary name and renamed, and report.json, the
//! one that holds everything, comes last: a folder with a report.json is a complete report.

use std::path::Path;

use super::{summary_text, PartReport};
use crate::analysis::section::ScannedSection;
use crate::fsutil::write_atomically;

pub const REPORT_FILE: &str = "report.json";
pub const DEVIATIONS_FILE: &str = "deviations.csv";
pub const SUMMARY_FILE: &str = "summary.txt";
/// The folder of a report's sections as the station evaluated them, one `INSTANCE-PROFILE.csv` each.
pub const SECTIONS_DIR: &str = "sections";
/// The taught reference the report was measured against, copied beside it.
pub const REFERENCE_FILE: &str = "reference.json";

/// Decimals of the millimetre values in deviations.csv: a nanometre, below any CMM's resolution (report.json
/// holds every value exactly).
const CSV_DECIMALS: usize = 6;

/// The columns of deviations.csv; lengths are in mm, as their names say.
const CSV_HEADER: [&str; 10] = [
    "instance",
    "profile",
    "index",
    "x_mm",
    "y_mm",
    "z_mm",
    "deviation_mm",
    "off_plane_mm",
    "quality",
    "flagged",
];

/// Writes report.json, deviations.csv (one row per point: instance, profile, index, x_mm, y_mm, z_mm of the surface
/// point, deviation_mm, off_plane_mm, quality, flagged (1 where compensation flagged the contact, a point left out
/// of the statistics); header row names units) and summary.txt into `dir` (created if
/// missing), each file atomically. Errors name the file.
pub fn write_report(dir: &Path, report: &PartReport) -> std::io::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| {
        std::io::Error::new(
            e.kind(),
            format!("cannot create the report folder {}: {e}", dir.display()),
        )
    })?;
    write_atomically(&dir.join(DEVIATIONS_FILE), &deviations_csv(report))?;
    write_atomically(&dir.join(SUMMARY_FILE), summary_text(report).as_bytes())?;
    let json = serde_json::to_string_pretty(report).map_err(|e| {
        std::io::Error::other(format!(
            "cannot write {}: {e}",
            dir.join(REPORT_FILE).display()
        ))
    })?;
    write_atomically(&dir.join(REPORT_FILE), json.as_bytes())
}

fn deviations_csv(report: &PartReport) -> Vec<u8> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    let mm = |v: f64| format!("{v:.CSV_DECIMALS$}");
    let rows = std::iter::once(CSV_HEADER.map(String::from).to_vec()).chain(
        report.instances.iter().flat_map(|instance| {
            instance.profiles.iter().flat_map(move |profile| {
                profile
                    .points
                    .iter()
                    .enumerate()
                    .map(move |(index, point)| {
                        vec![
                            instance.name.clone(),
                            profile.name.clone(),
                            index.to_string(),
                            mm(point.surface[0]),
                            mm(point.surface[1]),
                            mm(point.surface[2]),
                            mm(point.deviation_mm),
                            mm(point.off_plane_mm),
                            point.quality.to_string(),
                            u8::from(point.flagged).to_string(),
                        ]
                    })
            })
        }),
    );
    for row in rows {
        writer
            .write_record(&row)
            .expect("writing to memory cannot fail");
    }
    writer.into_inner().expect("flushing to memory cannot fail")
}

/// Writes each section the station evaluated into `dir`/sections/NAME.csv, atomically: `y,z,roll`, the points the
/// section's best fit and parameters took (compensated, flagged contacts left out, in scan order), in the
/// profile's plane of the part's frame (mm), with roll 1 for a contact of the ball rolling round a sharp edge.
/// `zeroset evaluate --reference reference.json --profile PROFILE --points sections/NAME.csv` reads one back and
/// evaluates it as the station did: the coordinates are written in full (the shortest decimal that reads back as
/// the same number), so it reads the same values.
pub fn write_sections(dir: &Path, sections: &[(String, ScannedSection)]) -> std::io::Result<()> {
    let folder = dir.join(SECTIONS_DIR);
    std::fs::create_dir_all(&folder).map_err(|e| {
        std::io::Error::new(e.kind(), format!("cannot create {}: {e}", folder.display()))
    })?;
    for (name, section) in sections {
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer.write_record(["y", "z", "roll"])?;
        for (index, point) in section.points.iter().enumerate() {
            let roll = section.sharp_edge_contacts.contains(&index);
            writer.write_record([
                point.y.to_string(),
                point.z.to_string(),
                u8::from(roll).to_string(),
            ])?;
        }
        let bytes = writer
            .into_inner()
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        write_atomically(&folder.join(format!("{name}.csv")), &bytes)?;
    }
    Ok(())
}
