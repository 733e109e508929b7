use std::collections::HashSet;
use std::path::Path;
use std::process::{Command, Output};

use quick_xml::events::Event;
use quick_xml::Reader;

use super::*;
use crate::analysis::stats::{RunningStats, Tolerance, Verdict};
use crate::report::{
    InstanceReport, MachineUse, PointRecord, ProfileReport, ReferenceUse, FORMAT, UNITS, VERSION,
};

const SCHEMA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../shared/reference/qif3/QIFDocument.xsd"
);

const TOLERANCE: Tolerance = Tolerance {
    lower_mm: -0.1,
    upper_mm: 0.1,
};

/// A profile of 6 points on an ellipse in the plane x = `x_mm`, deviations `deviations` (mm).
fn profile(name: &str, x_mm: f64, machine: &str, deviations: [f64; 6]) -> ProfileReport {
    let mut stats = RunningStats::default();
    let mut outside = 0;
    let points = deviations
        .iter()
        .enumerate()
        .map(|(k, &deviation_mm)| {
            let t = k as f64;
            let normal = [0.0, t.cos(), t.sin()];
            let surface = [x_mm, 30.0 * t.cos(), 6.0 * t.sin()];
            stats.push(deviation_mm, surface);
            outside += usize::from(!TOLERANCE.contains(deviation_mm));
            PointRecord {
                centre: [x_mm, surface[1] + normal[1], surface[2] + normal[2]],
                normal,
                surface,
                deviation_mm,
                off_plane_mm: 0.0003 * t,
                quality: 0.5 + 0.1 * t,
                flagged: false,
                after_fit_mm: None,
            }
        })
        .collect();
    let summary = stats.summary().expect("six points");
    ProfileReport {
        name: name.to_string(),
        x_mm,
        machine: machine.to_string(),
        scanned_at: format!("2025-03-04T10:{:02}:00Z", x_mm as u32 / 10),
        stats: summary,
        verdict: TOLERANCE.verdict(&summary, outside),
        best_fits: Vec::new(),
        parameters: None,
        distribution: None,
        points,
    }
}

fn instance(name: &str, machine: &str, profiles: Vec<ProfileReport>) -> InstanceReport {
    let mut stats = RunningStats::default();
    for point in profiles.iter().flat_map(|p| &p.points) {
        stats.push(point.deviation_mm, point.surface);
    }
    let summary = stats.summary().expect("points");
    let outside = profiles
        .iter()
        .flat_map(|p| &p.points)
        .filter(|p| !TOLERANCE.contains(p.deviation_mm))
        .count();
    assert!(profiles.iter().all(|p| p.machine == machine));
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

/// Blades A (on cmm-left) and B (on cmm-right), profiles r100 and r200 each; B/r200 fails with one point at
/// +0.1375 mm. A/r200's deviations are all positive, its smallest 4.5e-7 mm (a decimal QIF must not write in
/// exponent notation).
fn two_blade_report() -> PartReport {
    let blade_a = instance(
        "A",
        "cmm-left",
        vec![
            profile(
                "r100",
                100.0,
                "cmm-left",
                [0.0123456789012345, -0.0311, 0.004, -0.002, 0.0, 0.019],
            ),
            profile(
                "r200",
                200.0,
                "cmm-left",
                [0.00000045, 0.0021, 0.0452, 0.0133, 0.007, 0.001],
            ),
        ],
    );
    let blade_b = instance(
        "B",
        "cmm-right",
        vec![
            profile(
                "r100",
                100.0,
                "cmm-right",
                [-0.051, -0.0623, 0.011, 0.034, -0.0999, 0.05],
            ),
            profile(
                "r200",
                200.0,
                "cmm-right",
                [0.02, 0.1375, -0.0488, 0.03, 0.09, -0.004],
            ),
        ],
    );
    let instances = vec![blade_a, blade_b];
    PartReport {
        format: FORMAT.to_string(),
        version: VERSION,
        units: UNITS.to_string(),
        part: "propeller-2".to_string(),
        serial: "SN-QIF-0007".to_string(),
        job: "propeller-2-SN-QIF-0007-1741082400000".to_string(),
        started: "2025-03-04T10:00:00Z".to_string(),
        finished: "2025-03-04T10:30:00Z".to_string(),
        machines: ["cmm-left", "cmm-right"]
            .map(|name| MachineUse {
                name: name.to_string(),
                ball_radius_mm: 1.5,
                profiles_scanned: 2,
            })
            .to_vec(),
        reference: ReferenceUse {
            path: "/var/lib/zeroset/references/propeller-2.json".to_string(),
            taught_at: "2025-03-01T08:00:00Z".to_string(),
            model: "implicit polynomial of degree 4 per profile".to_string(),
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

/// Runs exactly `xmllint --noout --nonet --schema <QIFDocument.xsd> report.qif` in `dir`.
fn xmllint(dir: &Path) -> Output {
    match Command::new("xmllint")
        .args(["--noout", "--nonet", "--schema", SCHEMA, QIF_FILE])
        .current_dir(dir)
        .output()
    {
        Ok(output) => output,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => panic!(
            "xmllint is not installed, so report.qif cannot be validated: install libxml2-utils \
             (apt-get install libxml2-utils)"
        ),
        Err(e) => panic!("cannot run xmllint: {e}"),
    }
}

fn written(report: &PartReport) -> (tempfile::TempDir, String) {
    let dir = tempfile::tempdir().unwrap();
    write_qif(dir.path(), report).unwrap();
    let text = std::fs::read_to_string(dir.path().join(QIF_FILE)).unwrap();
    (dir, text)
}

fn rewritten(dir: &Path, text: &str) {
    std::fs::write(dir.join(QIF_FILE), text).unwrap();
}

fn assert_valid(dir: &Path) {
    let output = xmllint(dir);
    assert!(
        output.status.success(),
        "report.qif does not validate:\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
}

fn assert_rejected(dir: &Path, why: &str) -> String {
    let output = xmllint(dir);
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert!(
        !output.status.success(),
        "{why}: xmllint accepted it:\n{stderr}"
    );
    stderr
}

#[test]
fn the_written_document_validates_against_the_qif3_schema_and_leaves_no_temporary() {
    let (dir, _) = written(&two_blade_report());
    assert_valid(dir.path());
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(names, [QIF_FILE]);
}

#[test]
fn a_document_with_status_ok_or_a_missing_characteristic_is_rejected() {
    let (dir, text) = written(&two_blade_report());
    let failing = "<CharacteristicStatusEnum>FAIL</CharacteristicStatusEnum>";
    assert_eq!(text.matches(failing).count(), 1, "{text}");
    rewritten(
        dir.path(),
        &text.replace(
            failing,
            "<CharacteristicStatusEnum>OK</CharacteristicStatusEnum>",
        ),
    );
    let stderr = assert_rejected(dir.path(), "status OK");
    assert!(stderr.contains("CharacteristicStatusEnum"), "{stderr}");

    let start = text.find("<LineProfileCharacteristicItem ").unwrap();
    let end_tag = "</LineProfileCharacteristicItem>";
    let end = start + text[start..].find(end_tag).unwrap() + end_tag.len();
    rewritten(dir.path(), &format!("{}{}", &text[..start], &text[end..]));
    let stderr = assert_rejected(dir.path(), "a characteristic item removed");
    assert!(
        stderr.contains("CharacteristicMeasurementToItemKeyref"),
        "{stderr}"
    );

    rewritten(dir.path(), &text);
    assert_valid(dir.path());
}

/// The text of every element named `name` (entities resolved), in document order, and the value of `attribute`
/// on each element named `attribute_of`.
fn texts_and_attributes(
    text: &str,
    name: &str,
    attribute_of: &str,
    attribute: &str,
) -> (Vec<String>, Vec<String>) {
    let mut reader = Reader::from_str(text);
    let (mut texts, mut attributes) = (Vec::new(), Vec::new());
    // The escaped text of the element being read, when it is one named `name`.
    let mut escaped: Option<String> = None;
    loop {
        match reader.read_event().unwrap() {
            Event::Start(start) | Event::Empty(start) => {
                if start.name().as_ref() == name.as_bytes() {
                    escaped = Some(String::new());
                }
                if start.name().as_ref() == attribute_of.as_bytes() {
                    let value = start.try_get_attribute(attribute).unwrap().unwrap();
                    attributes.push(value.unescape_value().unwrap().into_owned());
                }
            }
            Event::Text(content) => {
                if let Some(escaped) = &mut escaped {
                    escaped.push_str(&content.decode().unwrap());
                }
            }
            Event::GeneralRef(reference) => {
                if let Some(escaped) = &mut escaped {
                    escaped.push_str(&format!("&{};", reference.decode().unwrap()));
                }
            }
            Event::End(_) => {
                if let Some(escaped) = escaped.take() {
                    texts.push(quick_xml::escape::unescape(&escaped).unwrap().into_owned());
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    (texts, attributes)
}

fn texts(text: &str, name: &str) -> Vec<String> {
    texts_and_attributes(text, name, "", "").0
}

fn numbers_in(text: &str, name: &str) -> Vec<f64> {
    texts(text, name)
        .iter()
        .flat_map(|list| list.split(' ').map(|v| v.parse::<f64>().unwrap()))
        .collect()
}

#[test]
fn the_numbers_agree_with_the_report_and_the_serial_is_there() {
    let report = two_blade_report();
    let (_dir, text) = written(&report);
    let profiles: Vec<&ProfileReport> = report.instances.iter().flat_map(|i| &i.profiles).collect();
    let each = |f: fn(&ProfileReport) -> f64| profiles.iter().map(|p| f(p)).collect::<Vec<_>>();

    // Values are written to the last bit, so they read back exactly.
    assert_eq!(
        numbers_in(&text, "Value"),
        each(|p| 2.0 * p.stats.worst_mm.abs())
    );
    assert_eq!(numbers_in(&text, "Value")[3], 0.275);
    assert_eq!(
        numbers_in(&text, "WorstPositiveDeviation"),
        each(|p| p.stats.max_mm)
    );
    assert_eq!(
        numbers_in(&text, "WorstNegativeDeviation"),
        each(|p| p.stats.min_mm)
    );
    assert_eq!(numbers_in(&text, "WorstNegativeDeviation")[1], 0.00000045);
    assert_eq!(numbers_in(&text, "ToleranceValue"), [0.2; 4]);
    assert!(
        texts(&text, "OuterDisposition").is_empty(),
        "a centred zone"
    );
    assert_eq!(
        texts(&text, "CharacteristicStatusEnum"),
        ["PASS", "PASS", "PASS", "FAIL"]
    );
    assert_eq!(texts(&text, "InspectionStatusEnum"), ["FAIL", "FAIL"]);

    let (_, counts) = texts_and_attributes(&text, "", "MeasuredPointSet", "count");
    assert_eq!(counts, ["6"; 4]);
    let all_points = || profiles.iter().flat_map(|p| &p.points);
    assert_eq!(
        numbers_in(&text, "Points"),
        all_points().flat_map(|p| p.surface).collect::<Vec<_>>()
    );
    assert_eq!(
        numbers_in(&text, "Deviations"),
        all_points().map(|p| p.deviation_mm).collect::<Vec<_>>()
    );
    assert_eq!(numbers_in(&text, "ProbeRadius"), [1.5; 4]);

    assert_eq!(texts(&text, "SerialNumber"), ["SN-QIF-0007"]);
    assert_eq!(
        texts(&text, "Name")[..3],
        ["cmm-left", "cmm-right", "propeller-2"]
    );
    assert_eq!(
        texts(&text, "FeatureName")[..4],
        ["A/r100", "A/r200", "B/r100", "B/r200"]
    );
    assert_eq!(texts(&text, "UnitName"), ["degree", "mm"]);
    assert!(texts(&text, "Description")[0].contains("2 x max |deviation|"));
    assert!(text.contains("<!-- Each line-profile characteristic's measured Value is"));
}

#[test]
fn ids_are_unique_references_resolve_and_id_max_is_the_largest() {
    let (_dir, text) = written(&two_blade_report());
    let mut reader = Reader::from_str(&text);
    let mut ids = Vec::new();
    let mut id_max = None;
    loop {
        match reader.read_event().unwrap() {
            Event::Start(start) | Event::Empty(start) => {
                for attribute in start.attributes() {
                    let attribute = attribute.unwrap();
                    let value: u32 = match attribute.key.as_ref() {
                        b"id" | b"idMax" => attribute.unescape_value().unwrap().parse().unwrap(),
                        _ => continue,
                    };
                    if attribute.key.as_ref() == b"id" {
                        ids.push(value);
                    } else {
                        id_max = Some(value);
                    }
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    let unique: HashSet<u32> = ids.iter().copied().collect();
    assert_eq!(unique.len(), ids.len(), "{ids:?}");
    // standard, part, curve definition, 2 devices, 8 per profile, results, actual component
    assert_eq!(ids.len(), 1 + 1 + 1 + 2 + 8 * 4 + 1 + 1);
    assert_eq!(id_max, ids.iter().copied().max());
    let references = [
        "CharacteristicItemId",
        "FeatureItemId",
        "WholePointSetId",
        "Id",
    ];
    for name in references {
        for target in texts(&text, name) {
            let target: u32 = target.parse().unwrap();
            assert!(unique.contains(&target), "{name} {target} names no element");
        }
    }
}

#[test]
fn an_off_centre_zone_states_its_outer_boundary_and_a_profile_machine_missing_from_the_list_is_a_device(
) {
    let mut report = two_blade_report();
    report.tolerance = Tolerance {
        lower_mm: -0.05,
        upper_mm: 0.15,
    };
    report.machines.truncate(1);
    let (dir, text) = written(&report);
    assert_valid(dir.path());
    assert_eq!(numbers_in(&text, "ToleranceValue"), [0.2; 4]);
    assert_eq!(numbers_in(&text, "OuterDisposition"), [0.15; 4]);
    assert_eq!(texts(&text, "Name")[..2], ["cmm-left", "cmm-right"]);
    assert_eq!(
        numbers_in(&text, "ProbeRadius"),
        [1.5; 2],
        "unknown radius left out"
    );
}

/// The element `<{element} ...>...</{element}>` of the document whose text holds `<{child}>{value}</{child}>`.
fn element_with<'a>(text: &'a str, element: &str, child: &str, value: &str) -> &'a str {
    let (open, close) = (format!("<{element} "), format!("</{element}>"));
    let wanted = format!("<{child}>{value}</{child}>");
    text.match_indices(&open)
        .map(|(start, _)| &text[start..start + text[start..].find(&close).unwrap() + close.len()])
        .find(|found| found.contains(&wanted))
        .unwrap_or_else(|| panic!("no {element} with {wanted} in\n{text}"))
}

/// The definition, nominal and measurement of the blade parameter named `name`, a QIF `kind` characteristic.
fn parameter_elements<'a>(text: &'a str, kind: &str, name: &str) -> [&'a str; 3] {
    let item = element_with(text, &format!("{kind}Item"), "Name", name);
    let id = item.split('"').nth(1).unwrap();
    [
        element_with(text, &format!("{kind}Definition"), "Name", name),
        element_with(text, &format!("{kind}Nominal"), "Name", name),
        element_with(
            text,
            &format!("{kind}Measurement"),
            "CharacteristicItemId",
            id,
        ),
    ]
}

#[test]
fn blade_parameters_are_characteristics_with_their_nominal_tolerance_value_and_status() {
    let mut report = two_blade_report();
    crate::report::tests::judge_a_sample_blade(&mut report);
    report.propeller_pitch_mm = Some(crate::analysis::section::ParameterValue::of(900.0, 901.5));
    let (dir, text) = written(&report);
    assert_valid(dir.path());
    // B/r100's maximum thickness: nominal 20.7383 mm, measured 20.7001 mm, held to +-0.03 mm: it fails.
    let [definition, nominal, measurement] =
        parameter_elements(&text, "ThicknessCharacteristic", "B/r100 max_thickness_mm");
    assert_eq!(numbers_in(definition, "MaxValue"), [0.03]);
    assert_eq!(numbers_in(definition, "MinValue"), [-0.03]);
    assert_eq!(texts(definition, "DefinedAsLimit"), ["false"]);
    assert_eq!(numbers_in(nominal, "TargetValue"), [20.7383]);
    assert_eq!(numbers_in(measurement, "Value"), [20.7001]);
    assert_eq!(texts(measurement, "CharacteristicStatusEnum"), ["FAIL"]);
    let scanned_at = &report.instances[1].profiles[0].scanned_at;
    assert_eq!(texts(measurement, "TimeStamp"), [scanned_at.as_str()]);
    // Its chord is within class I: a passing length.
    let [_, _, chord] = parameter_elements(&text, "LengthCharacteristic", "B/r100 chord_mm");
    assert_eq!(texts(chord, "CharacteristicStatusEnum"), ["PASS"]);
    // No class tolerances the chord angle or an edge radius: measured, not analysed.
    let [definition, _, measurement] =
        parameter_elements(&text, "AngleCharacteristic", "B/r100 chord_angle_deg");
    assert_eq!(texts(definition, "NonTolerance"), ["MEASURED"]);
    assert_eq!(numbers_in(measurement, "Value"), [55.0475]);
    assert_eq!(
        texts(measurement, "CharacteristicStatusEnum"),
        ["NOT_ANALYZED"]
    );
    let [_, nominal, _] = parameter_elements(&text, "RadiusCharacteristic", "B/r100 le_radius_mm");
    assert_eq!(numbers_in(nominal, "TargetValue"), [2.9214]);
    // The blade's mean pitch, 1.2 % coarse against class I's +-1 % (+-9 mm), and the propeller's, untoleranced.
    let [definition, _, measurement] =
        parameter_elements(&text, "LengthCharacteristic", "B blade_pitch_mm");
    assert_eq!(numbers_in(definition, "MaxValue"), [9.0]);
    assert_eq!(texts(measurement, "CharacteristicStatusEnum"), ["FAIL"]);
    assert!(
        !measurement.contains("<TimeStamp>"),
        "a blade's parameter has no one scan"
    );
    let [_, _, measurement] =
        parameter_elements(&text, "LengthCharacteristic", "propeller_pitch_mm");
    assert_eq!(numbers_in(measurement, "Value"), [901.5]);
    // Four line profiles, eight parameters of B/r100, one of blade B, one of the propeller.
    let counts = texts_and_attributes(&text, "", "CharacteristicMeasurements", "n").1;
    assert_eq!(counts, ["14"]);
}
