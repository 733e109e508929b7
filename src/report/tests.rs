use super::*;
use crate::analysis::stats::RunningStats;

const TOLERANCE: Tolerance = Tolerance {
    lower_mm: -0.1,
    upper_mm: 0.1,
};

/// Deviations pushed beyond the tolerance, first to last.
const EXCESSES: [f64; 2] = [0.11, 0.12];

/// A profile of 7 points whose deviations are `base` plus a small ripple; the first `excess` of them outside.
fn profile(
    name: &str,
    x_mm: f64,
    base: f64,
    excess: usize,
) -> (ProfileReport, RunningStats, usize) {
    let mut stats = RunningStats::default();
    let mut outside = 0;
    let points: Vec<PointRecord> = (0..7)
        .map(|k| {
            let t = k as f64 * 0.9;
            let deviation_mm = if k < excess {
                EXCESSES[k]
            } else {
                base + 0.001 * t.sin()
            };
            let surface = [x_mm, 40.0 * t.cos(), 8.0 * t.sin()];
            stats.push(deviation_mm, surface);
            outside += usize::from(!TOLERANCE.contains(deviation_mm));
            PointRecord {
                centre: [surface[0], surface[1] + 1.0, surface[2]],
                normal: [0.0, 1.0, 0.0],
                surface,
                deviation_mm,
                off_plane_mm: 0.002 * t,
                quality: 1.0,
                flagged: false,
                after_fit_mm: None,
            }
        })
        .collect();
    let summary = stats.summary().unwrap();
    let report = ProfileReport {
        name: name.to_string(),
        x_mm,
        machine: "cmm-left".to_string(),
        scanned_at: "2025-03-04T10:11:12Z".to_string(),
        stats: summary,
        verdict: TOLERANCE.verdict(&summary, outside),
        best_fits: Vec::new(),
        parameters: None,
        distribution: None,
        points,
    };
    (report, stats, outside)
}

fn instance(name: &str, base: f64, excess: usize) -> InstanceReport {
    let mut stats = RunningStats::default();
    let mut profiles = Vec::new();
    let mut outside = 0;
    for (k, x) in [100.0, 300.0].into_iter().enumerate() {
        let (report, profile_stats, profile_outside) =
            profile(&format!("p{x}"), x, base, if k == 1 { excess } else { 0 });
        stats.merge(&profile_stats);
        outside += profile_outside;
        profiles.push(report);
    }
    let summary = stats.summary().unwrap();
    InstanceReport {
        name: name.to_string(),
        stats: summary,
        verdict: TOLERANCE.verdict(&summary, outside),
        index_deg: None,
        angular_spacing_deg: None,
        blade_pitch_mm: None,
        profiles,
    }
}

pub(super) fn sample_report() -> PartReport {
    let instances = vec![instance("blade-A", 0.004, 0), instance("blade-B", -0.02, 2)];
    PartReport {
        format: FORMAT.to_string(),
        version: VERSION,
        units: UNITS.to_string(),
        part: "propeller-3".to_string(),
        serial: "SN-0042".to_string(),
        job: "job-17".to_string(),
        started: "2025-03-04T10:00:00Z".to_string(),
        finished: "2025-03-04T10:20:00Z".to_string(),
        machines: vec![MachineUse {
            name: "cmm-left".to_string(),
            ball_radius_mm: 1.0,
            profiles_scanned: 4,
        }],
        reference: ReferenceUse {
            path: "/var/lib/zeroset/references/propeller-3.json".to_string(),
            taught_at: "2025-03-01T08:00:00Z".to_string(),
            model: "implicit polynomial of degree 4 per profile, ridge-regularised 3L refined by orthogonal distances"
                .to_string(),
        },
        distance: "exact orthogonal distance to each profile's 2-D IP".to_string(),
        compensation: "ball radius along the reported normal".to_string(),
        tolerance: TOLERANCE,
        rescans: Vec::new(),
        iso484: None,
        propeller_pitch_mm: None,
        verdict: Verdict::combine(instances.iter().map(|i| &i.verdict)),
        instances,
    }
}

fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_written_report_reads_back_as_it_was_and_leaves_only_its_three_files() {
    let report = sample_report();
    assert_eq!(
        report.verdict,
        Verdict::Fail {
            points_outside: 2,
            worst_mm: 0.12,
            parameters_outside: 0,
        }
    );
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("propeller-3").join("SN-0042");
    write_report(&dir, &report).unwrap();
    assert_eq!(read_report(&dir).unwrap(), report);
    assert_eq!(
        file_names(&dir),
        ["deviations.csv", "report.json", "summary.txt"]
    );
    // Writing again replaces the files, still without temporaries.
    write_report(&dir, &report).unwrap();
    assert_eq!(
        file_names(&dir),
        ["deviations.csv", "report.json", "summary.txt"]
    );
}

#[test]
fn deviations_csv_has_a_header_with_units_and_one_row_per_point() {
    let report = sample_report();
    let root = tempfile::tempdir().unwrap();
    write_report(root.path(), &report).unwrap();
    let text = std::fs::read_to_string(root.path().join(DEVIATIONS_FILE)).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[0],
        "instance,profile,index,x_mm,y_mm,z_mm,deviation_mm,off_plane_mm,quality,flagged"
    );
    let points: usize = report
        .instances
        .iter()
        .flat_map(|i| &i.profiles)
        .map(|p| p.points.len())
        .sum();
    assert_eq!(points, 28);
    assert_eq!(lines.len(), 1 + points);
    // blade-B's second profile: its first point is outside, 0.11 mm, at (300, 40, 0).
    let row = lines
        .iter()
        .find(|l| l.starts_with("blade-B,p300,0,"))
        .expect("the row of blade-B p300 point 0");
    assert_eq!(
        *row,
        "blade-B,p300,0,300.000000,40.000000,0.000000,0.110000,0.000000,1,0"
    );
}

#[test]
fn the_summary_names_instances_profiles_units_and_verdicts() {
    let report = sample_report();
    let text = summary_text(&report);
    for expected in [
        "propeller-3, serial SN-0042, job job-17",
        "blade-A",
        "blade-B",
        "p300",
        "mm",
        "-0.1000 mm to +0.1000 mm",
        "FAIL (2 points outside the tolerance, worst +0.1200 mm)",
        "PASS",
        "FAIL (2 outside)",
        "cmm-left (ball radius 1.000 mm, 4 profiles)",
        "degree 4",
    ] {
        assert!(text.contains(expected), "no '{expected}' in\n{text}");
    }
    // One header and one row per instance and per profile, aligned: every row's verdict starts in one column.
    let table: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("instance"))
        .collect();
    assert_eq!(table.len(), 1 + 2 * 3, "{text}");
    let verdict_column = table[0].find("verdict").unwrap();
    for line in &table[1..] {
        let verdict = &line[verdict_column..];
        assert!(
            verdict.starts_with("PASS") || verdict.starts_with("FAIL"),
            "{line}"
        );
    }
    let root = tempfile::tempdir().unwrap();
    write_report(root.path(), &report).unwrap();
    assert_eq!(
        std::fs::read_to_string(root.path().join(SUMMARY_FILE)).unwrap(),
        text
    );
}

#[test]
fn reading_names_the_file_and_what_is_wrong() {
    let root = tempfile::tempdir().unwrap();
    let error = read_report(root.path()).unwrap_err();
    assert!(
        matches!(&error, ReportError::Read { path, .. } if path.ends_with("report.json")),
        "{error}"
    );
    let mut report = sample_report();
    report.version = 9;
    write_report(root.path(), &report).unwrap();
    let error = read_report(root.path()).unwrap_err().to_string();
    assert!(
        error.contains("report.json") && error.contains("version 9"),
        "{error}"
    );
    let blocked = root.path().join("file-not-folder");
    std::fs::write(&blocked, "x").unwrap();
    let error = write_report(&blocked.join("inner"), &report)
        .unwrap_err()
        .to_string();
    assert!(error.contains("file-not-folder"), "{error}");
}

#[test]
fn the_summary_says_where_each_fitted_section_lies_and_how_far_its_parameters_are_off() {
    use crate::analysis::section::{SectionBestFit, SectionForm};
    let mut report = sample_report();
    assert!(
        !summary_text(&report).contains("sections:"),
        "no section table without fits"
    );
    let profile = &mut report.instances[1].profiles[0];
    let fit = |method: &str, dn_mm: f64| SectionBestFit {
        mode: "full".into(),
        method: method.into(),
        dn_mm,
        dchord_mm: 0.0123,
        shift_mm: [0.0, dn_mm],
        rotation_deg: -0.0121,
        chord_direction: [1.0, 0.0],
        form: SectionForm {
            min_mm: -0.004,
            max_mm: 0.004,
            rms_mm: 0.0021,
            zone_mm: 0.008,
        },
        limits: Default::default(),
        at_limit: Vec::new(),
    };
    profile.best_fits = vec![fit("l2", -0.4012), fit("minzone", -0.3990)];
    profile.parameters = Some(sample_parameters());
    let text = summary_text(&report);
    let (line, cells) = summary_row(&text, "sections:", "blade-B");
    assert_eq!(
        cells,
        [
            "blade-B", "p100", "-0.4012", "+0.0123", "-0.0121", "0.0021", "+0.0200", "-0.0382",
            "-0.0134", "-0.0039", "-0.0293", "-0.142"
        ],
        "least squares, not the minimum zone: {line}"
    );
    assert!(!text.contains("held at its limit"), "{text}");
    // A fit the part file's [best_fit] held at a limit says so below the table, naming the section and the limit.
    let minzone = &mut report.instances[1].profiles[0].best_fits[1];
    minzone.limits.dn_mm = Some(0.25);
    minzone.at_limit = vec!["dn_mm".into()];
    let text = summary_text(&report);
    assert!(
        text.contains(
            "blade-B p100: the minzone fit held at its limit dn +-0.25 mm ([best_fit]); the rest is in its form"
        ),
        "{text}"
    );
}

#[test]
fn the_summary_gives_each_blades_turn_and_spacing_where_the_report_has_them() {
    let mut report = sample_report();
    assert!(
        !summary_text(&report).contains("blades:"),
        "a part with no spacings"
    );
    report.instances[1].index_deg = Some(0.0512);
    report.instances[1].angular_spacing_deg = Some(crate::analysis::section::ParameterValue::of(
        120.0, 120.0487,
    ));
    let text = summary_text(&report);
    let (_, cells) = summary_row(&text, "blades:", "blade-B");
    assert_eq!(
        cells,
        ["blade-B", "+0.0512", "120.0487", "120.0000", "+0.0487"]
    );
}

/// The first row starting with `first` of the summary's table headed `table`, and its cells.
fn summary_row<'a>(text: &'a str, table: &str, first: &str) -> (&'a str, Vec<&'a str>) {
    let line = text
        .lines()
        .skip_while(|l| !l.starts_with(table))
        .find(|l| l.starts_with(first))
        .unwrap_or_else(|| panic!("no row of {first} under {table} in\n{text}"));
    (line, line.split_whitespace().collect())
}

/// A blade section's parameters as a report holds them: B r100 of the simulator's propeller, made thinner and
/// turned (deviations -0.0382 mm of thickness, -0.0293 deg of chord angle, -1.2770 mm of pitch).
pub(crate) fn sample_parameters() -> crate::analysis::section::SectionParametersReport {
    use crate::analysis::section::ParameterValue;
    let value = ParameterValue::of;
    crate::analysis::section::SectionParametersReport {
        edge_distance_mm: 2.0,
        chord_mm: value(172.85, 172.87),
        max_thickness_mm: value(20.7383, 20.7001),
        max_thickness_at: value(0.3, 0.301),
        le_thickness_mm: value(6.4028, 6.3894),
        te_thickness_mm: value(0.5804, 0.5765),
        // A round nose, a sharp trailing edge.
        le_radius_mm: Some(value(2.9214, 2.9066)),
        te_radius_mm: None,
        max_camber_mm: value(6.9075, 6.9073),
        max_camber_at: value(0.4, 0.4),
        chord_angle_deg: value(55.0768, 55.0475),
        chord_middle_mm: Some([value(0.0, 0.0021), value(0.0, -0.4003)]),
        pitch_mm: Some(value(899.897, 898.62)),
        verdict: None,
    }
}

/// `report`'s second instance, first profile given [`sample_parameters`] judged by ISO 484 class I with the maximum
/// thickness held to +-0.03 mm by the part file (it fails, at -0.0382 mm), and a blade mean pitch 1.2 % coarse
/// (outside class I's +-1 %).
pub(crate) fn judge_a_sample_blade(report: &mut super::PartReport) {
    use crate::analysis::tolerances::{
        Iso484Class, Parameter, ParameterRules, ParameterTolerances, ToleranceRule,
    };
    let thin = ParameterRules {
        max_thickness_mm: Some(ToleranceRule {
            lower: Some(-0.03),
            upper: Some(0.03),
            ..ToleranceRule::default()
        }),
        ..ParameterRules::default()
    };
    let tolerances = ParameterTolerances::new(Some(Iso484Class::I), thin);
    let mut parameters = sample_parameters();
    tolerances.judge_section(&mut parameters);
    report.instances[1].profiles[0].parameters = Some(parameters);
    let mut pitch = crate::analysis::section::ParameterValue::of(900.0, 910.8);
    tolerances.judge(Parameter::BladePitch, &mut pitch);
    report.instances[1].blade_pitch_mm = Some(pitch);
    let (class, cites) = tolerances.class().unwrap();
    report.iso484 = Some(super::ClassUse {
        class,
        cites: cites.into(),
    });
}

#[test]
fn the_summary_names_whose_tolerances_judged_the_parameters_and_lists_each_one_out_of_them() {
    let mut report = sample_report();
    assert!(!summary_text(&report).contains("parameter tolerances"));
    judge_a_sample_blade(&mut report);
    let text = summary_text(&report);
    assert!(
        text.contains(
            "parameter tolerances  the part file's [tolerance.parameters], else ISO 484 class I (ISO 484-2:1981"
        ),
        "{text}"
    );
    let (_, cells) = summary_row(&text, "sections:", "blade-B");
    assert_eq!(cells.last(), Some(&"FAIL"), "{text}");
    let (_, cells) = summary_row(&text, "blades:", "blade-B");
    assert_eq!(cells, ["blade-B", "910.800", "+1.200"]);
    let failures: Vec<&str> = text
        .lines()
        .skip_while(|l| *l != "out of tolerance:")
        .skip(1)
        .collect();
    assert_eq!(
        failures,
        [
            // The section's pitch, -0.142 %, is within class I's +-1.5 %.
            "  blade-B p100: max_thickness_mm -0.0382 mm outside [-0.0300, +0.0300] mm (the part file)",
            "  blade blade-B: blade_pitch_mm +10.8000 mm outside [-9.0000, +9.0000] mm (ISO 484 class I)",
        ]
    );
}
