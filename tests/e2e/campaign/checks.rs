//! What must hold after every job of the campaign, each check returning the violations it finds (a campaign
//! goes on after one, to count them all).

use std::collections::BTreeMap;

use nalgebra::Point3;
use zeroset::api::Event;
use zeroset::report::PartReport;

/// Points per profile, keyed by (instance, profile).
pub(crate) type Counts = BTreeMap<(String, String), usize>;

/// Points per profile of an inspection report.
pub(crate) fn point_counts(report: &PartReport) -> Counts {
    report
        .instances
        .iter()
        .flat_map(|i| {
            i.profiles
                .iter()
                .map(|p| ((i.name.clone(), p.name.clone()), p.points.len()))
        })
        .collect()
}

/// Points per profile that the statistics use (not flagged as a cusp): what the history counts. How many a
/// profile flags varies with the probe's noise from one inspection to the next.
pub(crate) fn statistic_counts(report: &PartReport) -> Counts {
    report
        .instances
        .iter()
        .flat_map(|i| {
            i.profiles.iter().map(|p| {
                let used = p.points.iter().filter(|point| !point.flagged).count();
                ((i.name.clone(), p.name.clone()), used)
            })
        })
        .collect()
}

/// Two points of a profile closer than a micrometre: one measured twice (a resumed scan appended to a cut one
/// would repeat the start).
pub(crate) fn repeated_points(report: &PartReport) -> Vec<String> {
    let mut found = Vec::new();
    for instance in &report.instances {
        for profile in &instance.profiles {
            let repeats = profile
                .points
                .iter()
                .enumerate()
                .filter(|(i, a)| {
                    profile.points[i + 1..]
                        .iter()
                        .any(|b| (Point3::from(a.centre) - Point3::from(b.centre)).norm() <= 1e-3)
                })
                .map(|(_, a)| a.centre)
                .collect::<Vec<_>>();
            if let Some(first) = repeats.first() {
                found.push(format!(
                    "instance {} profile {}: {} points appear twice, the first at {first:?}",
                    instance.name,
                    profile.name,
                    repeats.len()
                ));
            }
        }
    }
    found
}

/// Profiles whose point count differs from `whole`'s, which `source` names (e.g. an uninterrupted inspection's:
/// a lost or an extra stretch).
pub(crate) fn count_differences(
    what: &str,
    counts: &Counts,
    whole: &Counts,
    source: &str,
) -> Vec<String> {
    let mut found = Vec::new();
    for (key, expected) in whole {
        match counts.get(key) {
            Some(n) if n == expected => {}
            Some(n) => found.push(format!(
                "{what}: instance {} profile {}: {n} points, {source} has {expected}",
                key.0, key.1
            )),
            None => found.push(format!(
                "{what}: instance {} profile {} is missing",
                key.0, key.1
            )),
        }
    }
    for key in counts.keys().filter(|k| !whole.contains_key(*k)) {
        found.push(format!(
            "{what}: instance {} profile {} is not in the plan",
            key.0, key.1
        ));
    }
    found
}

/// The history's rows of one serial (`zeroset report --export csv`): its points per profile (those its
/// statistics use, see [`statistic_counts`]), and every profile there more than once.
pub(crate) fn history_counts(csv: &str, serial: &str) -> (Counts, Vec<String>) {
    let mut reader = csv::Reader::from_reader(csv.as_bytes());
    let headers = match reader.headers() {
        Ok(headers) => headers.clone(),
        Err(e) => {
            return (
                Counts::new(),
                vec![format!("the history export does not read: {e}")],
            )
        }
    };
    let column = |name: &str| headers.iter().position(|h| h == name);
    let (Some(s), Some(i), Some(p), Some(n)) = (
        column("serial"),
        column("instance"),
        column("profile"),
        column("points"),
    ) else {
        return (
            Counts::new(),
            vec![format!("the history export lacks a column: {headers:?}")],
        );
    };
    let mut counts = Counts::new();
    let mut found = Vec::new();
    for record in reader.records().flatten().filter(|r| &r[s] == serial) {
        let key = (record[i].to_string(), record[p].to_string());
        let points = record[n].parse().unwrap_or(usize::MAX);
        if counts.insert(key.clone(), points).is_some() {
            found.push(format!(
                "history: {serial} instance {} profile {} is there more than once",
                key.0, key.1
            ));
        }
    }
    if counts.is_empty() {
        found.push(format!("history: {serial} is not in the history"));
    }
    (counts, found)
}

/// What a stop's event leaves the operator without: the machine, the profile, or what to do.
pub(crate) fn stop_message_gaps(event: &Event) -> Vec<&'static str> {
    let Event::JobStopped {
        machine,
        scan,
        reason,
        next_step,
        ..
    } = event
    else {
        return Vec::new();
    };
    let mut gaps = Vec::new();
    if machine.is_none() && !reason.contains("cmm") {
        gaps.push("the machine");
    }
    if scan.is_none() {
        gaps.push("the profile");
    }
    if !next_step.contains("zeroset ") && !next_step.contains("jog") {
        gaps.push("what to do");
    }
    gaps
}

/// What an operator's last word on a job that could not go on (the `status` and the refused `clear`) leaves
/// out of machine, part, profile (one of `profiles`) and what to do.
pub(crate) fn final_message_gaps(
    text: &str,
    machine: &str,
    part: &str,
    profiles: &[String],
) -> Vec<&'static str> {
    let mut gaps = Vec::new();
    if !text.contains(machine) {
        gaps.push("the machine");
    }
    if !text.contains(part) {
        gaps.push("the part");
    }
    if !profiles.iter().any(|p| text.contains(p.as_str())) {
        gaps.push("the profile");
    }
    if !text.contains("zeroset ") && !text.contains("jog") {
        gaps.push("what to do");
    }
    gaps
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(rows: &[(&str, &str, usize)]) -> Counts {
        rows.iter()
            .map(|(i, p, n)| ((i.to_string(), p.to_string()), *n))
            .collect()
    }

    #[test]
    fn a_short_profile_a_missing_one_and_a_doubled_history_row_are_found() {
        let whole = counts(&[("A", "r200", 391), ("A", "r300", 380)]);
        let cut = counts(&[("A", "r200", 351)]);
        let found = count_differences("SN-1", &cut, &whole, "an uninterrupted inspection");
        assert_eq!(found.len(), 2, "{found:?}");
        assert!(found[0].contains("r200: 351 points, an uninterrupted inspection has 391"));
        assert!(found[1].contains("r300 is missing"));
        assert!(count_differences("SN-1", &whole, &whole, "it").is_empty());
        let csv = "serial,finished,instance,profile,points\n\
                   SN-1,t,A,r200,391\nSN-1,t,A,r300,380\nSN-1,t,A,r300,380\nSN-2,t,A,r200,10\n";
        let (counts, found) = history_counts(csv, "SN-1");
        assert_eq!(counts, whole);
        assert_eq!(
            found,
            ["history: SN-1 instance A profile r300 is there more than once"]
        );
        let (counts, found) = history_counts(csv, "SN-3");
        assert!(counts.is_empty());
        assert_eq!(found, ["history: SN-3 is not in the history"]);
    }

    #[test]
    fn a_final_message_must_name_machine_part_profile_and_what_to_do() {
        let full = "machine cmm1: profile A r200 of part propeller: the way out is not clear; jog the probe";
        let profiles = ["r200".to_string(), "r300".to_string()];
        assert!(final_message_gaps(full, "cmm1", "propeller", &profiles).is_empty());
        assert_eq!(
            final_message_gaps("the way out is not clear", "cmm1", "propeller", &profiles),
            ["the machine", "the part", "the profile", "what to do"]
        );
    }
}
