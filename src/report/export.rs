//! The inspection history as CSV, for spreadsheets: one row per profile of each instance of each inspection.

use super::store::ProfileRecord;

/// The CSV text of `history`, with a header that states the units.
pub fn history_csv(history: &[ProfileRecord]) -> String {
    let mut writer = csv::Writer::from_writer(Vec::new());
    let header = [
        "serial", "finished", "instance", "profile", "points", "mean_mm", "rms_mm", "min_mm",
        "max_mm", "lower_mm", "upper_mm", "passed", "rescans",
    ];
    writer.write_record(header).expect("writing to memory");
    for r in history {
        writer
            .write_record([
                r.serial.clone(),
                r.finished.clone(),
                r.instance.clone(),
                r.profile.clone(),
                r.points.to_string(),
                r.mean_mm.to_string(),
                r.rms_mm.to_string(),
                r.min_mm.to_string(),
                r.max_mm.to_string(),
                r.lower_mm.to_string(),
                r.upper_mm.to_string(),
                r.passed.to_string(),
                r.rescans.to_string(),
            ])
            .expect("writing to memory");
    }
    String::from_utf8(writer.into_inner().expect("flushing to memory")).expect("UTF-8 fields")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_row_per_profile_under_a_header_with_units() {
        let record = ProfileRecord {
            serial: "SN-1".into(),
            finished: "2026-11-23T10:00:00Z".into(),
            instance: "B".into(),
            profile: "r300".into(),
            points: 357,
            mean_mm: 0.11481,
            rms_mm: 0.6068,
            min_mm: -0.6775,
            max_mm: 0.6879,
            passed: false,
            rescans: 1,
            lower_mm: -0.1,
            upper_mm: 0.1,
        };
        let text = history_csv(&[record.clone(), record]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("serial,finished,instance,profile,points,mean_mm"));
        assert_eq!(
            lines[1],
            "SN-1,2026-11-23T10:00:00Z,B,r300,357,0.11481,0.6068,-0.6775,0.6879,-0.1,0.1,false,1"
        );
    }
}
