//! Trends across parts of the blade parameters: a section's (chord, thicknesses, edge radii, camber, chord angle,
//! pitch), a blade's (mean pitch, angular spacing) and the propeller's mean pitch. Per parameter, over the parts:
//! x̄ the mean and s the sample standard deviation (n - 1) of its deviation from nominal; and where the newest
//! inspection held it to a tolerance [LSL, USL] on that deviation, the indices of one characteristic:
//! - Cp = (USL - LSL) / (6 s): its capability were it centred in its tolerance;
//! - Cpk = min(USL - x̄, x̄ - LSL) / (3 s): its capability where it is.
//!
//! Unlike a profile's point deviations, a parameter is one value per part, so the textbook definitions apply.

use std::collections::HashMap;

use super::individuals::{individuals, Individuals};
use super::store::ParameterRecord;
use super::trend::{few_parts_warning, mean, sample_deviation};

/// One part's value of one parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterSample {
    pub serial: String,
    /// When the inspection finished, RFC 3339.
    pub finished: String,
    /// Measured minus nominal, in the parameter's unit.
    pub deviation: f64,
    /// `None` where that inspection gave the parameter no tolerance.
    pub passed: Option<bool>,
}

/// One parameter of one section (or blade, or the part) over the parts of the history.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterTrendRow {
    /// Empty for the part's own parameters.
    pub instance: String,
    /// Empty for a blade's or the part's parameters.
    pub profile: String,
    /// The report's key, its unit last (`chord_mm`, `chord_angle_deg`).
    pub parameter: String,
    /// In the order inspected.
    pub parts: Vec<ParameterSample>,
    pub mean: f64,
    /// The sample standard deviation (0 for one part).
    pub spread: f64,
    /// The newest inspection's limits on the deviation (lower, upper), where it had them.
    pub limits: Option<(f64, f64)>,
    /// `None` without limits or without spread.
    pub cp: Option<f64>,
    pub cpk: Option<f64>,
    /// `None` for one part.
    pub chart: Option<Individuals>,
}

impl ParameterTrendRow {
    /// "mm" or "deg", from the key.
    pub fn unit(&self) -> &str {
        self.parameter.rsplit('_').next().unwrap_or("")
    }

    /// Where the parameter belongs, e.g. "blade-B r100", "blade-B (blade)", "(part)".
    pub fn place(&self) -> String {
        match (self.instance.as_str(), self.profile.as_str()) {
            ("", _) => "(part)".to_string(),
            (instance, "") => format!("{instance} (blade)"),
            (instance, profile) => format!("{instance} {profile}"),
        }
    }

    /// How many parts were out of its tolerance.
    pub fn failed(&self) -> usize {
        self.parts
            .iter()
            .filter(|p| p.passed == Some(false))
            .count()
    }

    pub fn signalled(&self) -> usize {
        self.chart.as_ref().map_or(0, |c| {
            let mut parts: Vec<usize> = c.signals.iter().map(|(k, _)| *k).collect();
            parts.dedup();
            parts.len()
        })
    }
}

/// The trend of every parameter in `history` (oldest inspection first), in the order the reports list them.
pub fn parameter_trend(history: &[ParameterRecord]) -> Vec<ParameterTrendRow> {
    let mut order: Vec<(&str, &str, &str)> = Vec::new();
    let mut runs: HashMap<(&str, &str, &str), Vec<&ParameterRecord>> = HashMap::new();
    for record in history {
        let key = (
            record.instance.as_str(),
            record.profile.as_str(),
            record.parameter.as_str(),
        );
        let run = runs.entry(key).or_default();
        if run.is_empty() {
            order.push(key);
        }
        run.push(record);
    }
    order.into_iter().map(|key| row(&runs[&key])).collect()
}

fn row(records: &[&ParameterRecord]) -> ParameterTrendRow {
    let first = records[0];
    let values: Vec<f64> = records.iter().map(|r| r.deviation).collect();
    let mean = mean(&values);
    let spread = sample_deviation(&values, mean);
    let limits = records.last().and_then(|r| r.limits);
    let indices = limits.filter(|_| spread > 0.0).map(|(lower, upper)| {
        (
            (upper - lower) / (6.0 * spread),
            (upper - mean).min(mean - lower) / (3.0 * spread),
        )
    });
    ParameterTrendRow {
        instance: first.instance.clone(),
        profile: first.profile.clone(),
        parameter: first.parameter.clone(),
        parts: records
            .iter()
            .map(|r| ParameterSample {
                serial: r.serial.clone(),
                finished: r.finished.clone(),
                deviation: r.deviation,
                passed: r.passed,
            })
            .collect(),
        mean,
        spread,
        limits,
        cp: indices.map(|(cp, _)| cp),
        cpk: indices.map(|(_, cpk)| cpk),
        chart: individuals(&values),
    }
}

/// The parameters' trend as a table an engineer reads, units stated.
pub fn parameter_trend_text(rows: &[ParameterTrendRow]) -> String {
    let index = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
    let mut text = format!(
        "parameters: per part the deviation from nominal; Cp = (USL - LSL) / 6 s, Cpk = min(USL - mean, mean - LSL) \
         / 3 s, on the newest inspection's tolerance\n\
         {:<18} {:<20} {:>5} {:>6} {:>10} {:>9} {:>24} {:>7} {:>7} {:>7}\n",
        "where", "parameter", "parts", "failed", "mean", "sd", "tolerance", "Cp", "Cpk", "signals"
    );
    for row in rows {
        let unit = row.unit();
        let tolerance = row.limits.map_or("-".to_string(), |(lower, upper)| {
            format!("{lower:+.4} .. {upper:+.4} {unit}")
        });
        text.push_str(&format!(
            "{:<18} {:<20} {:>5} {:>6} {:>+10.4} {:>9.4} {:>24} {:>7} {:>7} {:>7}\n",
            row.place(),
            row.parameter,
            row.parts.len(),
            row.failed(),
            row.mean,
            row.spread,
            tolerance,
            index(row.cp),
            index(row.cpk),
            row.signalled()
        ));
    }
    text.push_str(&few_parts_warning(
        rows.iter().map(|r| r.parts.len()),
        "parts with parameters in the history",
    ));
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(
        serial: &str,
        place: (&str, &str),
        parameter: &str,
        deviation: f64,
        limits: Option<(f64, f64)>,
    ) -> ParameterRecord {
        ParameterRecord {
            serial: serial.into(),
            finished: format!("2026-12-0{}T10:00:00Z", serial.len()),
            instance: place.0.into(),
            profile: place.1.into(),
            parameter: parameter.into(),
            nominal: 20.0,
            measured: 20.0 + deviation,
            deviation,
            limits,
            passed: limits.map(|(lower, upper)| (lower..=upper).contains(&deviation)),
        }
    }

    #[test]
    fn a_toleranced_parameter_gets_the_textbook_indices_and_its_failures_counted() {
        // Max thickness of B r100 over four parts: -0.02, -0.01, 0.00, +0.05 mm against -0.03 .. +0.03 mm.
        // Mean 0.005, s = sqrt((0.000625 + 0.000225 + 0.000025 + 0.002025) / 3) = sqrt(0.0029 / 3) = 0.0310913.
        // Cp = 0.06 / (6 s) = 0.321634; Cpk = min(0.025, 0.035) / (3 s) = 0.268028.
        let tolerance = Some((-0.03, 0.03));
        let history: Vec<ParameterRecord> = [-0.02, -0.01, 0.0, 0.05]
            .iter()
            .zip(["S1", "S22", "S333", "S4444"])
            .flat_map(|(&d, serial)| {
                [
                    record(serial, ("B", "r100"), "max_thickness_mm", d, tolerance),
                    record(serial, ("B", ""), "blade_pitch_mm", 2.0 * d, None),
                ]
            })
            .collect();
        let rows = parameter_trend(&history);
        assert_eq!(rows.len(), 2);
        let thickness = &rows[0];
        assert_eq!(
            (thickness.place().as_str(), thickness.unit()),
            ("B r100", "mm")
        );
        assert_eq!((thickness.parts.len(), thickness.failed()), (4, 1));
        assert!((thickness.mean - 0.005).abs() < 1e-12);
        assert!((thickness.spread - 0.031_091_264).abs() < 1e-9);
        assert!((thickness.cp.unwrap() - 0.321_634).abs() < 1e-6);
        assert!((thickness.cpk.unwrap() - 0.268_028).abs() < 1e-6);
        // Without a tolerance: its spread, no index, no failure.
        let pitch = &rows[1];
        assert_eq!(pitch.place(), "B (blade)");
        assert_eq!((pitch.cp, pitch.cpk, pitch.failed()), (None, None, 0));
        assert!((pitch.spread - 2.0 * thickness.spread).abs() < 1e-12);
        let text = parameter_trend_text(&rows);
        let line = text.lines().find(|l| l.starts_with("B r100")).unwrap();
        assert!(
            line.contains("-0.0300 .. +0.0300 mm")
                && line.contains("0.32")
                && line.contains("0.27"),
            "{text}"
        );
        assert!(text.contains("warning: 4 parts"), "{text}");
    }

    #[test]
    fn the_newest_tolerance_judges_and_one_part_has_no_spread() {
        // The tolerance was tightened for the second part: the indices use the newest.
        let history = vec![
            record("S1", ("", ""), "propeller_pitch_mm", 1.0, Some((-9.0, 9.0))),
            record(
                "S22",
                ("", ""),
                "propeller_pitch_mm",
                3.0,
                Some((-4.0, 4.0)),
            ),
            record(
                "S1",
                ("A", "r200"),
                "chord_angle_deg",
                0.01,
                Some((-0.1, 0.1)),
            ),
        ];
        let rows = parameter_trend(&history);
        let pitch = &rows[0];
        assert_eq!(pitch.place(), "(part)");
        // Mean 2, s = sqrt(2) = 1.414214: Cp = 8 / 8.485281 = 0.942809; Cpk = 2 / 4.242641 = 0.471405.
        assert!((pitch.cp.unwrap() - 0.942_809).abs() < 1e-6);
        assert!((pitch.cpk.unwrap() - 0.471_405).abs() < 1e-6);
        let angle = &rows[1];
        assert_eq!((angle.unit(), angle.spread), ("deg", 0.0));
        assert_eq!((angle.cp, angle.chart.clone()), (None, None));
    }
}
