//! Trends across parts of what the tolerance applies to. The band holds every point's deviation, so a profile of a
//! part passes iff its worst + deviation (the largest, `max_mm`) is at most the upper limit and its worst -
//! deviation (the smallest, `min_mm`) at least the lower. The trend follows those two extremes per part, and the
//! form value (worst + minus worst -, the width of the zone around the nominal that holds every point), never the
//! mean deviation, in which a profile too fat on one side and too thin on the other cancels to zero.
//!
//! The capability indices, over the parts of the history, with x̄ the mean and s the sample standard deviation
//! (n - 1) of the parts' values, USL and LSL the band's limits:
//! - CPU = (USL - x̄ of worst +) / (3 s of worst +): the one-sided index of the upper extreme;
//! - CPL = (x̄ of worst - - LSL) / (3 s of worst -): the one-sided index of the lower extreme;
//! - Cpk = min(CPU, CPL): the profile's capability where it is;
//! - Cp = (USL - LSL - x̄ of form) / (3 (s of worst + + s of worst -)): the Cpk the profile would have if its whole
//!   position were centred (shifted until CPU = CPL); for a characteristic without form (worst + = worst -, one
//!   sigma) it is the textbook (USL - LSL) / 6 sigma. Cp is negative when the mean form alone is wider than the band.

use std::collections::BTreeMap;

use super::individuals::{individuals, Individuals};
use super::store::ProfileRecord;

/// Below this many parts, capability indices are too uncertain to act on; the trend says so.
pub const FEW_PARTS: usize = 25;

/// One part's inspection of one profile, as the trend follows it.
#[derive(Debug, Clone, PartialEq)]
pub struct PartSample {
    pub serial: String,
    /// When the inspection finished, RFC 3339.
    pub finished: String,
    /// The largest deviation of the profile's points, mm.
    pub worst_plus_mm: f64,
    /// The smallest (most negative) deviation, mm.
    pub worst_minus_mm: f64,
    /// The profile's verdict in that inspection.
    pub passed: bool,
}

impl PartSample {
    /// The form value: worst + minus worst -, mm.
    pub fn form_mm(&self) -> f64 {
        self.worst_plus_mm - self.worst_minus_mm
    }
}

/// One extreme (worst + or worst -) over the parts: its spread, its one-sided index and its control chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Extreme {
    pub mean_mm: f64,
    /// The sample standard deviation over the parts, mm (0 for one part).
    pub spread_mm: f64,
    /// CPU for worst +, CPL for worst -; `None` when the spread is zero (one part, or all alike).
    pub index: Option<f64>,
    /// `None` for one part.
    pub chart: Option<Individuals>,
}

/// One profile of one instance over the parts of the history.
#[derive(Debug, Clone, PartialEq)]
pub struct TrendRow {
    pub instance: String,
    pub profile: String,
    /// In the order inspected.
    pub parts: Vec<PartSample>,
    pub worst_plus: Extreme,
    pub worst_minus: Extreme,
    pub form_mean_mm: f64,
    pub form_max_mm: f64,
    /// `None` when either extreme's spread is zero.
    pub cp: Option<f64>,
    pub cpk: Option<f64>,
}

impl TrendRow {
    /// How many of the parts failed this profile.
    pub fn failed(&self) -> usize {
        self.parts.iter().filter(|p| !p.passed).count()
    }

    /// How many parts break a control-chart rule on either extreme.
    pub fn signalled(&self) -> usize {
        let mut parts: Vec<usize> = [&self.worst_plus, &self.worst_minus]
            .iter()
            .flat_map(|e| {
                e.chart
                    .iter()
                    .flat_map(|c| c.signals.iter().map(|(k, _)| *k))
            })
            .collect();
        parts.sort_unstable();
        parts.dedup();
        parts.len()
    }
}

/// The trend of every profile in `history` (oldest inspection first), against the tolerance band.
pub fn trend(history: &[ProfileRecord], lower_mm: f64, upper_mm: f64) -> Vec<TrendRow> {
    let mut runs: BTreeMap<(String, String), Vec<PartSample>> = BTreeMap::new();
    for record in history {
        runs.entry((record.instance.clone(), record.profile.clone()))
            .or_default()
            .push(PartSample {
                serial: record.serial.clone(),
                finished: record.finished.clone(),
                worst_plus_mm: record.max_mm,
                worst_minus_mm: record.min_mm,
                passed: record.passed,
            });
    }
    runs.into_iter()
        .map(|((instance, profile), parts)| row(instance, profile, parts, lower_mm, upper_mm))
        .collect()
}

fn row(
    instance: String,
    profile: String,
    parts: Vec<PartSample>,
    lower_mm: f64,
    upper_mm: f64,
) -> TrendRow {
    let plus: Vec<f64> = parts.iter().map(|p| p.worst_plus_mm).collect();
    let minus: Vec<f64> = parts.iter().map(|p| p.worst_minus_mm).collect();
    let worst_plus = extreme(&plus, |mean| upper_mm - mean);
    let worst_minus = extreme(&minus, |mean| mean - lower_mm);
    let forms: Vec<f64> = parts.iter().map(PartSample::form_mm).collect();
    let form_mean_mm = mean(&forms);
    let form_max_mm = forms.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let cpk = worst_plus
        .index
        .zip(worst_minus.index)
        .map(|(u, l)| u.min(l));
    let cp = cpk.map(|_| {
        (upper_mm - lower_mm - form_mean_mm)
            / (3.0 * (worst_plus.spread_mm + worst_minus.spread_mm))
    });
    TrendRow {
        instance,
        profile,
        parts,
        worst_plus,
        worst_minus,
        form_mean_mm,
        form_max_mm,
        cp,
        cpk,
    }
}

/// An extreme's statistics; `room` is its mean's distance inside its limit (negative outside).
fn extreme(values: &[f64], room: impl Fn(f64) -> f64) -> Extreme {
    let mean_mm = mean(values);
    let spread_mm = sample_deviation(values, mean_mm);
    Extreme {
        mean_mm,
        spread_mm,
        index: (spread_mm > 0.0).then(|| room(mean_mm) / (3.0 * spread_mm)),
        chart: individuals(values),
    }
}

pub(super) fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// The sample (n - 1) standard deviation; 0 for one value.
pub(super) fn sample_deviation(values: &[f64], mean: f64) -> f64 {
    if values.len() < 2 {
        return 0.0;
    }
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (values.len() - 1) as f64).sqrt()
}

/// A warning line when the fewest of `parts` (each row's count) is too few to trust Cp and Cpk; empty otherwise.
/// `what` names what was counted, e.g. "parts in the history".
pub(super) fn few_parts_warning(parts: impl Iterator<Item = usize>, what: &str) -> String {
    let fewest = parts.min().unwrap_or(0);
    if fewest < FEW_PARTS {
        format!("warning: {fewest} {what}; Cp and Cpk need {FEW_PARTS} or more to be trusted\n")
    } else {
        String::new()
    }
}

/// The trend as a table an engineer reads, units stated, with a warning when the history is short.
pub fn trend_text(rows: &[TrendRow], lower_mm: f64, upper_mm: f64) -> String {
    let index = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
    let mut text = format!(
        "tolerance {lower_mm:+.3} .. {upper_mm:+.3} mm; per part: worst + = largest deviation, worst - = smallest, \
         form = worst + minus worst -\n\
         Cpk = min(CPU of worst +, CPL of worst -); Cp = the Cpk if the profile's position were centred \
         (definitions in trend.html)\n\
         {:<9} {:<8} {:>5} {:>6} {:>9} {:>7} {:>9} {:>7} {:>7} {:>7} {:>8} {:>8} {:>7}\n",
        "instance",
        "profile",
        "parts",
        "failed",
        "worst+",
        "sd",
        "worst-",
        "sd",
        "form",
        "max",
        "Cp",
        "Cpk",
        "signals"
    );
    text.push_str(&format!(
        "{:<9} {:<8} {:>5} {:>6} {:>9} {:>7} {:>9} {:>7} {:>7} {:>7}\n",
        "", "", "", "", "mean mm", "mm", "mean mm", "mm", "mean mm", "mm"
    ));
    for row in rows {
        text.push_str(&format!(
            "{:<9} {:<8} {:>5} {:>6} {:>+9.4} {:>7.4} {:>+9.4} {:>7.4} {:>7.4} {:>7.4} {:>8} {:>8} {:>7}\n",
            row.instance,
            row.profile,
            row.parts.len(),
            row.failed(),
            row.worst_plus.mean_mm,
            row.worst_plus.spread_mm,
            row.worst_minus.mean_mm,
            row.worst_minus.spread_mm,
            row.form_mean_mm,
            row.form_max_mm,
            index(row.cp),
            index(row.cpk),
            row.signalled()
        ));
    }
    text.push_str(&few_parts_warning(
        rows.iter().map(|r| r.parts.len()),
        "parts in the history",
    ));
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(instance: &str, min_mm: f64, max_mm: f64, mean_mm: f64) -> ProfileRecord {
        ProfileRecord {
            serial: "SN".into(),
            finished: "t".into(),
            instance: instance.into(),
            profile: "r100".into(),
            points: 300,
            mean_mm,
            rms_mm: mean_mm.abs(),
            min_mm,
            max_mm,
            passed: min_mm >= -0.1 && max_mm <= 0.1,
            rescans: 0,
            lower_mm: -0.1,
            upper_mm: 0.1,
        }
    }

    fn only(rows: &[TrendRow], instance: &str) -> TrendRow {
        rows.iter()
            .find(|r| r.instance == instance)
            .unwrap()
            .clone()
    }

    #[test]
    fn a_profile_outside_the_band_has_capability_below_one() {
        // Blade B r100 shifted outwards, every point outside +-0.1 mm. Worst +: 0.50, 0.52, 0.54, 0.56 mm, mean
        // 0.53, s = sqrt(0.002 / 3) = 0.0258199. Worst -: 0.30, 0.31, 0.32, 0.33 mm, mean 0.315,
        // s = sqrt(0.0005 / 3) = 0.0129099.
        // CPU = (0.1 - 0.53) / (3 x 0.0258199) = -5.55128; CPL = (0.315 + 0.1) / (3 x 0.0129099) = 10.71525;
        // Cpk = -5.55128. Mean form 0.215 mm > the band's 0.2 mm: Cp = (0.2 - 0.215) / (3 x 0.0387298) = -0.12910.
        // The parts' means (0.40 .. 0.43, s 0.0129) would give Cpk -8.13 yet a Cp of 2.58.
        let history: Vec<ProfileRecord> = [(0.30, 0.50), (0.31, 0.52), (0.32, 0.54), (0.33, 0.56)]
            .iter()
            .enumerate()
            .map(|(k, (lo, hi))| record("B", *lo, *hi, 0.40 + 0.01 * k as f64))
            .collect();
        let b = only(&trend(&history, -0.1, 0.1), "B");
        assert_eq!((b.parts.len(), b.failed()), (4, 4));
        assert!((b.worst_plus.mean_mm - 0.53).abs() < 1e-12);
        assert!((b.worst_plus.spread_mm - 0.025_819_889).abs() < 1e-9);
        assert!((b.worst_minus.spread_mm - 0.012_909_944).abs() < 1e-9);
        assert!((b.worst_plus.index.unwrap() + 5.551_276).abs() < 1e-5);
        assert!((b.worst_minus.index.unwrap() - 10.715_254).abs() < 1e-5);
        assert!((b.cpk.unwrap() + 5.551_276).abs() < 1e-5);
        assert!((b.cp.unwrap() + 0.129_10).abs() < 1e-5);
        assert!((b.form_mean_mm - 0.215).abs() < 1e-12);
        assert!((b.form_max_mm - 0.23).abs() < 1e-12);
        let text = trend_text(&[b], -0.1, 0.1);
        assert!(text.contains("-0.13") && text.contains("-5.55"), "{text}");
        assert!(text.contains("warning: 4 parts"), "{text}");
    }

    #[test]
    fn a_profile_whose_mean_cancels_is_not_capable() {
        // Too fat on one side, too thin on the other: every part's mean deviation is 0 (+- 0.001), its extremes
        // +-0.3 mm. Worst +: 0.29, 0.30, 0.31 (mean 0.30, s 0.01); worst -: -0.31, -0.30, -0.29 (mean -0.30,
        // s 0.01). CPU = CPL = (0.1 - 0.3) / 0.03 = -6.6667; Cp = (0.2 - 0.6) / (3 x 0.02) = -6.6667. On the means
        // (s 0.001) Cp and Cpk would be 33.3.
        let history: Vec<ProfileRecord> = [
            (-0.31, 0.29, -0.001),
            (-0.30, 0.30, 0.0),
            (-0.29, 0.31, 0.001),
        ]
        .iter()
        .map(|(lo, hi, mean)| record("C", *lo, *hi, *mean))
        .collect();
        let c = only(&trend(&history, -0.1, 0.1), "C");
        assert!((c.cpk.unwrap() + 6.666_667).abs() < 1e-5, "{c:?}");
        assert!((c.cp.unwrap() + 6.666_667).abs() < 1e-5, "{c:?}");
    }

    #[test]
    fn a_capable_profile_has_cp_at_least_cpk() {
        // Worst +: 0.02, 0.03, 0.04, 0.05 (mean 0.035, s 0.0129099); worst -: -0.06, -0.04, -0.05, -0.03 (mean
        // -0.045, s 0.0129099). CPU = 0.065 / 0.0387298 = 1.67829, CPL = 0.055 / 0.0387298 = 1.42009: Cpk 1.42009.
        // Mean form 0.08: Cp = 0.12 / (3 x 0.0258199) = 1.54919.
        let history: Vec<ProfileRecord> =
            [(-0.06, 0.02), (-0.04, 0.03), (-0.05, 0.04), (-0.03, 0.05)]
                .iter()
                .map(|(lo, hi)| record("A", *lo, *hi, 0.0))
                .chain([record("D", -0.05, 0.05, 0.0)])
                .collect();
        let rows = trend(&history, -0.1, 0.1);
        let a = only(&rows, "A");
        assert!((a.worst_plus.index.unwrap() - 1.678_29).abs() < 1e-5);
        assert!((a.worst_minus.index.unwrap() - 1.420_09).abs() < 1e-5);
        assert!((a.cpk.unwrap() - 1.420_09).abs() < 1e-5);
        assert!((a.cp.unwrap() - 1.549_19).abs() < 1e-5);
        assert_eq!(a.failed(), 0);
        assert_eq!(a.worst_plus.chart.as_ref().unwrap().signals, []);
        // One part: no spread, no index, no control chart.
        let d = only(&rows, "D");
        assert_eq!(
            (d.cp, d.cpk, d.worst_plus.chart.clone()),
            (None, None, None)
        );
        assert_eq!(d.worst_plus.spread_mm, 0.0);
    }
}
