use super::*;
use crate::report::tests::sample_report;

fn open(dir: &tempfile::TempDir) -> Store {
    Store::open(&dir.path().join(STORE_FILE)).unwrap()
}

#[test]
fn an_inspection_is_entered_whole_and_read_back_per_profile() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = open(&dir);
    let report = sample_report();
    store
        .record(&report, Path::new("/reports/SN-0042/job-17"))
        .unwrap();
    assert_eq!(
        store.latest_report("SN-0042").unwrap(),
        Some(PathBuf::from("/reports/SN-0042/job-17"))
    );
    assert_eq!(store.latest_report("SN-9").unwrap(), None);
    let history = store.profile_history("propeller-3", 10).unwrap();
    let expected: usize = report.instances.iter().map(|i| i.profiles.len()).sum();
    assert_eq!(history.len(), expected);
    let b300 = history
        .iter()
        .find(|r| r.instance == "blade-B" && r.profile == "p300")
        .unwrap();
    let reported = &report.instances[1].profiles[1];
    assert_eq!(b300.mean_mm, reported.stats.mean_mm);
    assert_eq!(b300.points, reported.stats.points);
    assert_eq!(b300.passed, reported.verdict.passed());
}

#[test]
fn every_rescan_of_an_inspection_is_kept_with_its_profile() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = open(&dir);
    let mut report = sample_report();
    let (instance, profile) = (
        report.instances[1].name.clone(),
        report.instances[1].profiles[1].name.clone(),
    );
    report.rescans = vec![crate::report::Rescan {
        instance: instance.clone(),
        profile: profile.clone(),
        reason: "a gap of 4.10 mm after point 120".into(),
        at: "2025-03-04T10:11:12Z".into(),
    }];
    store.record(&report, Path::new("/r/1")).unwrap();
    // Entered again (a job finished twice), the rescan still counts once.
    store.record(&report, Path::new("/r/1")).unwrap();
    let history = store.profile_history("propeller-3", 10).unwrap();
    for record in &history {
        let expected = usize::from(record.instance == instance && record.profile == profile);
        assert_eq!(record.rescans, expected, "{record:?}");
    }
    let reason: String = store
        .connection
        .query_row("SELECT reason FROM rescans", [], |row| row.get(0))
        .unwrap();
    assert_eq!(reason, "a gap of 4.10 mm after point 120");
}

#[test]
fn the_same_job_entered_twice_counts_once_and_history_keeps_the_newest() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = open(&dir);
    let first = sample_report();
    store.record(&first, Path::new("/r/1")).unwrap();
    store.record(&first, Path::new("/r/1")).unwrap();
    let mut second = sample_report();
    second.job = "job-18".into();
    second.finished = "2025-03-05T10:20:00Z".into();
    store.record(&second, Path::new("/r/2")).unwrap();
    let per_inspection: usize = first.instances.iter().map(|i| i.profiles.len()).sum();
    assert_eq!(
        store.profile_history("propeller-3", 10).unwrap().len(),
        2 * per_inspection
    );
    let newest = store.profile_history("propeller-3", 1).unwrap();
    assert!(
        newest.iter().all(|r| r.finished == "2025-03-05T10:20:00Z"),
        "{newest:?}"
    );
    assert_eq!(
        store.latest_report("SN-0042").unwrap(),
        Some(PathBuf::from("/r/2"))
    );
}

#[test]
fn reopening_keeps_the_history_and_a_newer_schema_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    open(&dir)
        .record(&sample_report(), Path::new("/r/1"))
        .unwrap();
    assert_eq!(
        open(&dir).profile_history("propeller-3", 5).unwrap().len(),
        4
    );
    let connection = Connection::open(dir.path().join(STORE_FILE)).unwrap();
    connection
        .execute_batch("PRAGMA user_version = 99")
        .unwrap();
    drop(connection);
    let err = Store::open(&dir.path().join(STORE_FILE))
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("version 99") && err.contains(STORE_FILE),
        "{err}"
    );
}

#[test]
fn a_judged_blades_parameters_are_kept_with_their_limits_and_verdicts() {
    let dir = tempfile::tempdir().unwrap();
    let mut store = open(&dir);
    let mut report = sample_report();
    crate::report::tests::judge_a_sample_blade(&mut report);
    store.record(&report, Path::new("/r/1")).unwrap();
    // Entered again (a job finished twice), each parameter still counts once.
    store.record(&report, Path::new("/r/1")).unwrap();
    let history = store.parameter_history("propeller-3", 10).unwrap();
    let keys: Vec<(&str, &str, &str)> = history
        .iter()
        .map(|r| {
            (
                r.instance.as_str(),
                r.profile.as_str(),
                r.parameter.as_str(),
            )
        })
        .collect();
    let section = |key| ("blade-B", "p100", key);
    assert_eq!(
        keys,
        [
            section("chord_mm"),
            section("max_thickness_mm"),
            section("le_thickness_mm"),
            section("te_thickness_mm"),
            section("max_camber_mm"),
            section("chord_angle_deg"),
            section("le_radius_mm"),
            section("pitch_mm"),
            ("blade-B", "", "blade_pitch_mm"),
        ]
    );
    let thickness = &history[1];
    assert_eq!((thickness.nominal, thickness.measured), (20.7383, 20.7001));
    assert!((thickness.deviation + 0.0382).abs() < 1e-12);
    assert_eq!(
        (thickness.limits, thickness.passed),
        (Some((-0.03, 0.03)), Some(false))
    );
    let blade = &history[8];
    assert_eq!(blade.passed, Some(false));
    assert!((blade.limits.unwrap().1 - 9.0).abs() < 1e-12, "{blade:?}");
    // No ISO 484 class tolerances an edge radius: no limits, no verdict.
    assert_eq!((history[6].limits, history[6].passed), (None, None));
}
