//! Trends across parts: for each profile of each instance, the mean deviation of every inspected part, their mean
//! and spread, and the process capability against the tolerance (Cp = (USL - LSL) / 6 sigma, Cpk = min(USL - mean,
//! mean - LSL) / 3 sigma, sigma the sample standard deviation of the parts' means).

use std::collections::BTreeMap;

use super::store::ProfileRecord;

/// Below this many parts, capability indices are too uncertain to act on; the trend says so.
pub const FEW_PARTS: usize = 25;

/// One profile of one instance over the parts of the history.
#[derive(Debug, Clone, PartialEq)]
pub struct TrendRow {
    pub instance: String,
    pub profile: String,
    pub parts: usize,
    /// The mean over the parts of each part's mean deviation, mm.
    pub mean_mm: f64,
    /// The sample standard deviation of the parts' means, mm (0 for one part).
    pub spread_mm: f64,
    /// `None` when the spread is zero (one part, or all alike).
    pub cp: Option<f64>,
    pub cpk: Option<f64>,
    /// Each part's mean deviation in the order inspected, for the run chart.
    pub run_mm: Vec<f64>,
}

/// The trend of every profile in `history` (oldest inspection first), against the tolerance band.
pub fn trend(history: &[ProfileRecord], lower_mm: f64, upper_mm: f64) -> Vec<TrendRow> {
    let mut runs: BTreeMap<(String, String), Vec<f64>> = BTreeMap::new();
    for record in history {
        runs.entry((record.instance.clone(), record.profile.clone()))
            .or_default()
            .push(record.mean_mm);
    }
    runs.into_iter()
        .map(|((instance, profile), run_mm)| {
            let parts = run_mm.len();
            let mean_mm = run_mm.iter().sum::<f64>() / parts as f64;
            let spread_mm = if parts > 1 {
                (run_mm.iter().map(|m| (m - mean_mm).powi(2)).sum::<f64>() / (parts - 1) as f64)
                    .sqrt()
            } else {
                0.0
            };
            let (cp, cpk) = if spread_mm > 0.0 {
                (
                    Some((upper_mm - lower_mm) / (6.0 * spread_mm)),
                    Some((upper_mm - mean_mm).min(mean_mm - lower_mm) / (3.0 * spread_mm)),
                )
            } else {
                (None, None)
            };
            TrendRow {
                instance,
                profile,
                parts,
                mean_mm,
                spread_mm,
                cp,
                cpk,
                run_mm,
            }
        })
        .collect()
}

/// The trend as a table an engineer reads, units stated, with a warning when the history is short.
pub fn trend_text(rows: &[TrendRow], lower_mm: f64, upper_mm: f64) -> String {
    let index = |v: Option<f64>| v.map_or("-".to_string(), |v| format!("{v:.2}"));
    let mut text = format!(
        "tolerance {lower_mm:+.3} .. {upper_mm:+.3} mm\n{:<9} {:<8} {:>5} {:>10} {:>10} {:>6} {:>6}\n",
        "instance", "profile", "parts", "mean mm", "spread mm", "Cp", "Cpk"
    );
    for row in rows {
        text.push_str(&format!(
            "{:<9} {:<8} {:>5} {:>+10.4} {:>10.4} {:>6} {:>6}\n",
            row.instance,
            row.profile,
            row.parts,
            row.mean_mm,
            row.spread_mm,
            index(row.cp),
            index(row.cpk)
        ));
    }
    let fewest = rows.iter().map(|r| r.parts).min().unwrap_or(0);
    if fewest < FEW_PARTS {
        text.push_str(&format!(
            "warning: {fewest} parts in the history; Cp and Cpk need {FEW_PARTS} or more to be trusted\n"
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(instance: &str, profile: &str, mean_mm: f64) -> ProfileRecord {
        ProfileRecord {
            serial: "SN".into(),
            finished: "t".into(),
            instance: instance.into(),
            profile: profile.into(),
            points: 300,
            mean_mm,
            rms_mm: mean_mm.abs(),
            min_mm: mean_mm,
            max_mm: mean_mm,
            passed: true,
            rescans: 0,
            lower_mm: -0.1,
            upper_mm: 0.1,
        }
    }

    #[test]
    fn capability_matches_hand_computed_values() {
        // Profile B/r100 over four parts: means 0.010, 0.020, 0.030, 0.040 mm. Mean 0.025 mm; sample standard
        // deviation sqrt(0.0005 / 3) = 0.0129099 mm. Tolerance -0.1 .. +0.1: Cp = 0.2 / (6 x 0.0129099) = 2.5820,
        // Cpk = (0.1 - 0.025) / (3 x 0.0129099) = 1.9365.
        let history: Vec<ProfileRecord> = [0.010, 0.020, 0.030, 0.040]
            .iter()
            .flat_map(|m| [record("B", "r100", *m), record("A", "r100", 0.001)])
            .collect();
        let rows = trend(&history, -0.1, 0.1);
        let b = rows.iter().find(|r| r.instance == "B").unwrap();
        assert_eq!(b.parts, 4);
        assert!((b.mean_mm - 0.025).abs() < 1e-12);
        assert!((b.spread_mm - 0.012_909_944).abs() < 1e-9);
        assert!((b.cp.unwrap() - 2.581_989).abs() < 1e-6);
        assert!((b.cpk.unwrap() - 1.936_492).abs() < 1e-6);
        assert_eq!(b.run_mm, [0.010, 0.020, 0.030, 0.040]);
        // Blade A never moved: no spread, no capability index.
        let a = rows.iter().find(|r| r.instance == "A").unwrap();
        assert_eq!((a.spread_mm, a.cp, a.cpk), (0.0, None, None));
        let text = trend_text(&rows, -0.1, 0.1);
        assert!(text.contains("2.58") && text.contains("1.94"), "{text}");
        assert!(text.contains("warning: 4 parts"), "{text}");
    }
}
