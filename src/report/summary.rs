//! The summary an operator reads at the machine: the part, what it was measured with and against, the tolerance,
//! one table row per instance (all its profiles) and per profile, and for sections with a best fit or parameters
//! where each lies (its least-squares fit) and how far its parameters are off their nominals.

use std::fmt::Write;

use super::PartReport;
use crate::analysis::section::{ParameterValue, SectionParametersReport};
use crate::analysis::stats::{DeviationStats, Verdict};
use crate::analysis::tolerances::{failure_text, ParameterVerdict, ToleranceSource};

/// Deviations are shown to 0.1 um, coordinates to 1 um, in every report people read.
pub(super) const DEVIATION_DECIMALS: usize = 4;
pub(super) const COORDINATE_DECIMALS: usize = 3;

const COLUMNS: [&str; 11] = [
    "instance",
    "profile",
    "x_mm",
    "points",
    "mean_mm",
    "rms_mm",
    "min_mm",
    "max_mm",
    "worst_mm",
    "worst at (x, y, z) mm",
    "verdict",
];
/// The first columns are names, left-aligned; the rest numbers, right-aligned; the verdict is left-aligned.
const LEFT_ALIGNED: [usize; 3] = [0, 1, 10];
const SECTION_COLUMNS: [&str; 13] = [
    "instance",
    "profile",
    "dn_mm",
    "dchord_mm",
    "twist_deg",
    "form_rms_mm",
    "d_chord_mm",
    "d_thickness_mm",
    "d_le_mm",
    "d_te_mm",
    "d_chord_angle_deg",
    "d_pitch_%",
    "parameters",
];

/// The summary table as text (also printed by the CLI).
pub fn summary_text(report: &PartReport) -> String {
    let mut text = String::new();
    let machines: Vec<String> = report.machines.iter().map(machine_text).collect();
    let reference = &report.reference;
    let mut lines = vec![
        (
            "part",
            format!(
                "{}, serial {}, job {}",
                report.part, report.serial, report.job
            ),
        ),
        ("verdict", verdict_text(&report.verdict)),
        ("started", report.started.clone()),
        ("finished", report.finished.clone()),
        (
            "tolerance",
            format!(
                "{} mm to {} mm",
                deviation(report.tolerance.lower_mm),
                deviation(report.tolerance.upper_mm)
            ),
        ),
        ("reference", reference.describe()),
        ("distance", report.distance.clone()),
        ("compensation", report.compensation.clone()),
        ("machines", machines.join("; ")),
        (
            "units",
            "all lengths in mm, deviations positive outside the material".into(),
        ),
    ];
    if let Some(tolerances) = parameter_tolerances_text(report) {
        lines.insert(5, ("parameter tolerances", tolerances));
    }
    let label_width = lines
        .iter()
        .map(|(label, _)| label.len())
        .max()
        .unwrap_or(0);
    for (label, value) in lines {
        writeln!(text, "{label:<label_width$}  {value}").expect("writing to a String");
    }
    text.push('\n');
    let mut rows = vec![COLUMNS.map(String::from).to_vec()];
    for instance in &report.instances {
        rows.push(row(
            &instance.name,
            "(all)",
            None,
            &instance.stats,
            &instance.verdict,
        ));
        for profile in &instance.profiles {
            rows.push(row(
                &instance.name,
                &profile.name,
                Some(profile.x_mm),
                &profile.stats,
                &profile.verdict,
            ));
        }
    }
    text.push_str(&table(&rows, &LEFT_ALIGNED));
    text.push_str(&sections_text(report));
    text.push_str(&spacings_text(report));
    text.push_str(&failures_text(report));
    text
}

/// Each blade's turn about the hub axis off its place and its angular spacing from the blade before it (deg);
/// empty for parts that have none.
fn spacings_text(report: &PartReport) -> String {
    let mut rows = vec![[
        "blade",
        "turned_deg",
        "spacing_deg",
        "nominal_deg",
        "d_spacing_deg",
        "mean_pitch_mm",
        "d_mean_pitch_%",
    ]
    .map(String::from)
    .to_vec()];
    for instance in &report.instances {
        let (spacing, pitch) = (instance.angular_spacing_deg, instance.blade_pitch_mm);
        if spacing.is_none() && pitch.is_none() {
            continue;
        }
        let turned = instance.index_deg.map(|t| format!("{t:+.4}"));
        rows.push(vec![
            instance.name.clone(),
            turned.unwrap_or_default(),
            spacing.map_or(String::new(), |s| format!("{:.4}", s.measured)),
            spacing.map_or(String::new(), |s| format!("{:.4}", s.nominal)),
            spacing.map_or(String::new(), |s| format!("{:+.4}", s.deviation)),
            pitch.map_or(String::new(), |p| format!("{:.3}", p.measured)),
            pitch.map_or(String::new(), |p| pitch_percent(&p)),
        ]);
    }
    if rows.len() == 1 {
        return String::new();
    }
    let propeller = report
        .propeller_pitch_mm
        .map(|p| {
            format!(
                "propeller mean pitch {:.3} mm (nominal {:.3} mm, {} %)\n",
                p.measured,
                p.nominal,
                pitch_percent(&p)
            )
        })
        .unwrap_or_default();
    format!(
        "\nblades: turn about the hub axis off their places (from the sections' chord middles), angular spacing \
         from the blade before (the first from the last), and mean pitch (of the sections' pitches)\n{}{propeller}",
        table(&rows, &[0])
    )
}

/// Where each section lies after its least-squares best fit (dn: along the thickness direction, + above; twist
/// counter-clockwise in y, z) and its parameters' deviations from nominal; empty when no section has either.
fn sections_text(report: &PartReport) -> String {
    let mut rows = vec![SECTION_COLUMNS.map(String::from).to_vec()];
    for instance in &report.instances {
        for profile in &instance.profiles {
            let fit = profile.best_fits.iter().find(|f| f.method == "l2");
            let parameters = profile.parameters.as_ref();
            if fit.is_none() && parameters.is_none() {
                continue;
            }
            let or_blank = |value: Option<String>| value.unwrap_or_default();
            let off = |read: fn(&SectionParametersReport) -> f64| {
                or_blank(parameters.map(|p| deviation(read(p))))
            };
            rows.push(vec![
                instance.name.clone(),
                profile.name.clone(),
                or_blank(fit.map(|f| deviation(f.dn_mm))),
                or_blank(fit.map(|f| deviation(f.dchord_mm))),
                or_blank(fit.map(|f| format!("{:+.4}", f.rotation_deg))),
                or_blank(fit.map(|f| format!("{:.DEVIATION_DECIMALS$}", f.form.rms_mm))),
                off(|p| p.chord_mm.deviation),
                off(|p| p.max_thickness_mm.deviation),
                off(|p| p.le_thickness_mm.deviation),
                off(|p| p.te_thickness_mm.deviation),
                or_blank(parameters.map(|p| format!("{:+.4}", p.chord_angle_deg.deviation))),
                or_blank(
                    parameters
                        .and_then(|p| p.pitch_mm)
                        .map(|v| pitch_percent(&v)),
                ),
                or_blank(
                    parameters
                        .and_then(|p| p.verdict)
                        .map(|v| parameter_verdict_word(v).into()),
                ),
            ]);
        }
    }
    if rows.len() == 1 {
        return String::new();
    }
    let held: String = report
        .instances
        .iter()
        .flat_map(|instance| {
            instance.profiles.iter().flat_map(move |profile| {
                profile.best_fits.iter().filter_map(move |fit| {
                    let held = fit.held_at()?;
                    Some(format!(
                        "{} {}: the {} fit held at its limit {held} ([best_fit]); the rest is in its form\n",
                        instance.name, profile.name, fit.method
                    ))
                })
            })
        })
        .collect();
    format!(
        "\nsections: least-squares best fit (dn along the thickness, + above; dchord along the chord; twist \
         counter-clockwise in y, z) and parameters minus nominal (thickness: largest inscribed circle; le, te: edge \
         thicknesses; pitch in % of nominal)\n{}",
        table(&rows, &[0, 1, 12])
    ) + &held
}

/// A pitch's deviation in percent of its nominal, e.g. "+0.213".
fn pitch_percent(pitch: &ParameterValue) -> String {
    format!("{:+.3}", 100.0 * pitch.deviation / pitch.nominal)
}

fn parameter_verdict_word(verdict: ParameterVerdict) -> &'static str {
    match verdict {
        ParameterVerdict::Pass => "PASS",
        ParameterVerdict::Fail => "FAIL",
    }
}

/// Where the parameters' tolerances come from, if any parameter has one.
pub(super) fn parameter_tolerances_text(report: &PartReport) -> Option<String> {
    let class = report
        .iso484
        .as_ref()
        .map(|c| format!("ISO 484 class {} ({})", c.class, c.cites));
    let from_part = every_judged(report)
        .any(|(_, _, v)| v.tolerance.map(|t| t.from) == Some(ToleranceSource::PartFile));
    let part = from_part.then(|| "the part file's [tolerance.parameters]".to_string());
    match (class, part) {
        (Some(class), Some(part)) => Some(format!("{part}, else {class}")),
        (class, part) => class.or(part),
    }
}

/// Every toleranced parameter of the report with where it is ("B r100", "blade B", "propeller") and its name.
fn every_judged(
    report: &PartReport,
) -> impl Iterator<Item = (String, &'static str, &ParameterValue)> {
    let sections = report.instances.iter().flat_map(|instance| {
        instance.profiles.iter().flat_map(move |profile| {
            profile.parameters.iter().flat_map(move |p| {
                p.judged().map(move |(parameter, v)| {
                    (
                        format!("{} {}", instance.name, profile.name),
                        parameter.key(),
                        v,
                    )
                })
            })
        })
    });
    let blades = report.instances.iter().flat_map(|instance| {
        let blade = format!("blade {}", instance.name);
        [
            ("blade_pitch_mm", instance.blade_pitch_mm.as_ref()),
            ("angular_spacing_deg", instance.angular_spacing_deg.as_ref()),
        ]
        .into_iter()
        .filter_map(move |(name, v)| Some((blade.clone(), name, v?)))
    });
    let propeller = report
        .propeller_pitch_mm
        .as_ref()
        .map(|v| ("propeller".to_string(), "propeller_pitch_mm", v));
    sections
        .chain(blades)
        .chain(propeller)
        .filter(|(_, _, v)| v.tolerance.is_some())
}

/// Each parameter out of tolerance, where it is, by how much and whose tolerance, e.g. "B r100: pitch_mm -21.3000
/// mm outside [-20.0000, +20.0000] mm (ISO 484 class S)".
pub(super) fn parameter_failures(report: &PartReport) -> Vec<String> {
    every_judged(report)
        .filter_map(|(place, name, value)| {
            let text = failure_text(name, value)?;
            let from = value.tolerance?.from;
            Some(format!("{place}: {text} ({from})"))
        })
        .collect()
}

/// The list of parameters out of tolerance, if any.
fn failures_text(report: &PartReport) -> String {
    let failures = parameter_failures(report);
    if failures.is_empty() {
        return String::new();
    }
    let mut text = String::from(
        "
out of tolerance:
",
    );
    for failure in failures {
        writeln!(text, "  {failure}").expect("writing to a String");
    }
    text
}

fn row(
    instance: &str,
    profile: &str,
    x_mm: Option<f64>,
    stats: &DeviationStats,
    verdict: &Verdict,
) -> Vec<String> {
    let at = stats
        .worst_at_mm
        .map(|c| format!("{c:.COORDINATE_DECIMALS$}"));
    vec![
        instance.to_string(),
        profile.to_string(),
        x_mm.map_or(String::new(), |x| format!("{x:.COORDINATE_DECIMALS$}")),
        stats.points.to_string(),
        deviation(stats.mean_mm),
        format!("{:.DEVIATION_DECIMALS$}", stats.rms_mm),
        deviation(stats.min_mm),
        deviation(stats.max_mm),
        deviation(stats.worst_mm),
        format!("({})", at.join(", ")),
        // The worst deviation has its own column.
        verdict.cell_text(),
    ]
}

/// A machine as the reports name it: its name, its ball and how many profiles it scanned.
pub(super) fn machine_text(m: &super::MachineUse) -> String {
    format!(
        "{} (ball radius {:.COORDINATE_DECIMALS$} mm, {} profiles)",
        m.name, m.ball_radius_mm, m.profiles_scanned
    )
}

/// A signed deviation as every report shows it, e.g. "+0.0123" (in mm).
pub(super) fn deviation(mm: f64) -> String {
    format!("{mm:+.DEVIATION_DECIMALS$}")
}

fn verdict_text(verdict: &Verdict) -> String {
    verdict
        .what_failed()
        .map_or_else(|| "PASS".to_string(), |failed| format!("FAIL ({failed})"))
}

/// Rows padded to their columns' widths, two spaces apart; the columns `left` left-aligned, the rest right.
fn table(rows: &[Vec<String>], left: &[usize]) -> String {
    let widths: Vec<usize> = (0..rows[0].len())
        .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
        .collect();
    let mut text = String::new();
    for row in rows {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(c, (cell, &width))| {
                if left.contains(&c) {
                    format!("{cell:<width$}")
                } else {
                    format!("{cell:>width$}")
                }
            })
            .collect();
        writeln!(text, "{}", cells.join("  ").trim_end()).expect("writing to a String");
    }
    text
}
