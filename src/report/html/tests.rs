use quick_xml::events::Event;

use super::*;
use crate::analysis::stats::RunningStats;
use crate::report::{
    InstanceReport, MachineUse, PointRecord, ReferenceUse, FORMAT, UNITS, VERSION,
};

const TOLERANCE: Tolerance = Tolerance {
    lower_mm: -0.1,
    upper_mm: 0.1,
};
const PROFILES: [(&str, f64); 3] = [("r100", 100.0), ("r300", 300.0), ("r500", 500.0)];

/// A blade section at `radius` from the z axis in the vertical plane at `azimuth_deg`: an ellipse of half-axes
/// 40 and 5 mm, lifted by `lift_mm` along z, whose deviations are the lift seen along each normal (a blade lying
/// above the model reads positive on its upper face and negative on its lower one, as in seed 003).
fn section(radius: f64, azimuth_deg: f64, lift_mm: f64) -> Vec<PointRecord> {
    let (sin_a, cos_a) = azimuth_deg.to_radians().sin_cos();
    (0..60)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / 60.0;
            let (along, up) = (40.0 * t.cos(), 5.0 * t.sin() + lift_mm);
            let surface = [
                radius * cos_a - along * sin_a,
                radius * sin_a + along * cos_a,
                up,
            ];
            let (n_along, n_up) = (5.0 * t.cos(), 40.0 * t.sin());
            let length = n_along.hypot(n_up);
            let normal = [
                -n_along * sin_a / length,
                n_along * cos_a / length,
                n_up / length,
            ];
            PointRecord {
                centre: [
                    surface[0] + normal[0],
                    surface[1] + normal[1],
                    surface[2] + normal[2],
                ],
                normal,
                surface,
                deviation_mm: lift_mm * normal[2],
                off_plane_mm: 0.0,
                quality: 1.0,
                flagged: false,
                after_fit_mm: None,
            }
        })
        .collect()
}

fn verdict_of(stats: &RunningStats, points: &[PointRecord]) -> (DeviationStats, Verdict) {
    let summary = stats.summary().unwrap();
    let outside = points
        .iter()
        .filter(|p| !TOLERANCE.contains(p.deviation_mm))
        .count();
    (summary, TOLERANCE.verdict(&summary, outside))
}

fn instance(name: &str, azimuth_deg: f64, lift_per_100_mm: f64) -> InstanceReport {
    let mut all = RunningStats::default();
    let mut all_points = Vec::new();
    let profiles = PROFILES
        .iter()
        .map(|&(profile, radius)| {
            let points = section(radius, azimuth_deg, lift_per_100_mm * radius / 100.0);
            let mut stats = RunningStats::default();
            points
                .iter()
                .for_each(|p| stats.push(p.deviation_mm, p.surface));
            all.merge(&stats);
            all_points.extend_from_slice(&points);
            let (stats, verdict) = verdict_of(&stats, &points);
            ProfileReport {
                name: profile.to_string(),
                x_mm: radius,
                machine: "cmm1".to_string(),
                scanned_at: "2025-03-04T10:11:12Z".to_string(),
                stats,
                verdict,
                best_fits: Vec::new(),
                parameters: None,
                distribution: None,
                points,
            }
        })
        .collect();
    let (stats, verdict) = verdict_of(&all, &all_points);
    InstanceReport {
        name: name.to_string(),
        stats,
        verdict,
        index_deg: None,
        angular_spacing_deg: None,
        blade_pitch_mm: None,
        profiles,
    }
}

/// Blades A (the model), B below it and C above it, sinking and rising further outwards as in seed 003.
fn propeller(instances: Vec<InstanceReport>) -> PartReport {
    let failing = instances
        .iter()
        .filter_map(|i| match i.verdict {
            Verdict::Fail { points_outside, .. } => Some(points_outside),
            Verdict::Pass => None,
        })
        .sum();
    let worst = instances
        .iter()
        .map(|i| i.stats.worst_mm)
        .fold(0.0, |w: f64, d| if d.abs() > w.abs() { d } else { w });
    PartReport {
        format: FORMAT.to_string(),
        version: VERSION,
        units: UNITS.to_string(),
        part: "propeller".to_string(),
        serial: "SN-7".to_string(),
        job: "job-7".to_string(),
        started: "2025-03-04T10:00:00Z".to_string(),
        finished: "2025-03-04T10:20:00Z".to_string(),
        machines: vec![MachineUse {
            name: "cmm1".to_string(),
            ball_radius_mm: 1.0,
            profiles_scanned: instances.len() * PROFILES.len(),
        }],
        reference: ReferenceUse {
            path: "data/references/propeller.json".to_string(),
            taught_at: "2025-03-01T08:00:00Z".to_string(),
            model: "implicit polynomial of degree 4 per profile".to_string(),
        },
        distance: "exact orthogonal distance".to_string(),
        compensation: "ball radius along the normal".to_string(),
        tolerance: TOLERANCE,
        rescans: Vec::new(),
        iso484: None,
        propeller_pitch_mm: None,
        verdict: if failing == 0 {
            Verdict::Pass
        } else {
            Verdict::Fail {
                points_outside: failing,
                worst_mm: worst,
                parameters_outside: 0,
            }
        },
        instances,
    }
}

fn three_blades() -> PartReport {
    propeller(vec![
        instance("A", 0.0, 0.0),
        instance("B", 120.0, -0.2),
        instance("C", 240.0, 0.2),
    ])
}

/// How plotters writes a text element holding `text`.
fn svg_text(text: &str) -> String {
    format!(">\n{text}\n</text>")
}

/// The inline SVG documents of a page, in order.
pub(crate) fn svgs(html: &str) -> Vec<&str> {
    html.match_indices("<svg")
        .map(|(start, _)| {
            let end = html[start..].find("</svg>").expect("an <svg> is closed") + start;
            &html[start..end + "</svg>".len()]
        })
        .collect()
}

/// Fails unless `document` is well-formed XML (every element closed, in order, by its own name).
fn assert_well_formed(document: &str) {
    let mut reader = quick_xml::Reader::from_str(document);
    let mut depth = 0usize;
    loop {
        match reader.read_event() {
            Ok(Event::Start(_)) => depth += 1,
            Ok(Event::End(_)) => depth -= 1,
            Ok(Event::Eof) => break,
            Ok(_) => {}
            Err(e) => panic!("not well-formed at {}: {e}", reader.buffer_position()),
        }
    }
    assert_eq!(depth, 0, "unclosed elements");
}

#[test]
fn every_profile_has_a_deviation_and_a_whisker_plot_with_units() {
    let html = report_html(&three_blades()).unwrap();
    assert_eq!(html.matches("<svg").count(), 2 * PROFILES.len());
    assert_eq!(html.matches("</svg>").count(), 2 * PROFILES.len());
    let plots = svgs(&html);
    for (k, (profile, _)) in PROFILES.iter().enumerate() {
        let (deviation, whiskers) = (plots[2 * k], plots[2 * k + 1]);
        assert_well_formed(deviation);
        assert_well_formed(whiskers);
        assert!(
            deviation.contains(&format!("{profile}: signed deviation")),
            "{profile}"
        );
        assert!(deviation.contains("deviation (mm)"), "{profile}");
        assert!(
            deviation.contains("tolerance -0.100 .. +0.100 mm"),
            "{profile}"
        );
        assert!(whiskers.contains("u, horizontal (mm)"), "{profile}");
        for name in ["A", "B", "C"] {
            assert!(
                deviation.contains(&svg_text(name)),
                "{profile}: legend {name}"
            );
            assert!(
                whiskers.contains(&svg_text(name)),
                "{profile}: panel {name}"
            );
        }
    }
    // The largest deviation, 1.0 mm on r500, against a 80 mm chord: 0.1 * 80 / 1.0 = 8, drawn x 10.
    assert!(plots[5].contains("whiskers x 10 "), "r500 magnification");
    // r100 reaches 0.2 mm: 40, drawn x 50.
    assert!(plots[1].contains("whiskers x 50 "), "r100 magnification");
}

#[test]
fn the_page_states_the_verdict_and_every_profile_mean_as_tabled() {
    let report = three_blades();
    let html = report_html(&report).unwrap();
    assert!(html.contains("<div class=\"verdict fail\">FAIL: "));
    assert!(html.contains("ball radius 1.000 mm"));
    assert!(html.contains("<dd>-0.1000 mm .. +0.1000 mm</dd>"));
    for instance in &report.instances {
        assert!(html.contains(&format!("<td class=\"name\">{}</td>", instance.name)));
        for profile in &instance.profiles {
            let mean = deviation_mm(profile.stats.mean_mm);
            assert!(
                html.contains(&format!("<td>{mean}</td>")),
                "{} {}",
                instance.name,
                profile.name
            );
        }
    }
    // B's upper faces lie 0.2 mm per 100 mm of radius below A's: r500's worst is -1.0 mm at its top, z = 4.
    let r500 = &report.instances[1].profiles[2];
    assert_eq!(deviation_mm(r500.stats.worst_mm), "-1.0000 mm");
    assert!(html.contains("<td>-1.0000 mm</td>"));
    let passing = report_html(&propeller(vec![instance("A", 0.0, 0.0)])).unwrap();
    assert!(passing.contains("<div class=\"verdict pass\">PASS</div>"));
    assert!(!passing.contains("FAIL"));
}

#[test]
fn names_from_configuration_are_escaped() {
    let mut report = propeller(vec![instance("A&<B>", 0.0, 0.0)]);
    report.serial = "SN\"1'".to_string();
    let html = report_html(&report).unwrap();
    assert!(html.contains("A&amp;&lt;B&gt;"));
    assert!(html.contains("SN&quot;1&#39;"));
    assert!(!html.contains("A&<B>"));
    svgs(&html).into_iter().for_each(assert_well_formed);
}

#[test]
fn an_instance_without_a_plane_is_named_and_left_out_of_the_figures() {
    let mut report = three_blades();
    report.instances[2].profiles[0].points.truncate(2);
    let html = report_html(&report).unwrap();
    assert!(html.contains("Not drawn (fewer than 3 points, or all on one line): C</p>"));
    assert_eq!(html.matches("<svg").count(), 2 * PROFILES.len());
    let r100 = svgs(&html)[0];
    assert!(!r100.contains(&svg_text("C")) && r100.contains(&svg_text("B")));
}

#[test]
fn write_html_replaces_the_file_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(HTML_FILE), "old").unwrap();
    let report = three_blades();
    write_html(dir.path(), &report).unwrap();
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(names, [HTML_FILE]);
    let written = std::fs::read_to_string(dir.path().join(HTML_FILE)).unwrap();
    assert_eq!(written, report_html(&report).unwrap());
    let missing = dir.path().join("no-such-folder");
    let error = write_html(&missing, &report).unwrap_err().to_string();
    assert!(
        error.contains("no-such-folder") && error.contains(HTML_FILE),
        "{error}"
    );
}

#[test]
fn the_blade_table_shows_each_sections_parameters_measured_and_off_nominal() {
    let mut report = three_blades();
    let html = report_html(&report).unwrap();
    assert!(
        !html.contains("Section parameters"),
        "no table without parameters"
    );
    report.instances[1].profiles[0].parameters = Some(crate::report::tests::sample_parameters());
    let html = report_html(&report).unwrap();
    for cell in [
        "<td>B</td><td>r100</td><td>172.8700 mm (+0.0200)</td><td>20.7001 mm (-0.0382)</td>",
        "<td>55.0475 deg (-0.0293)</td><td>898.6200 mm (-1.2770)</td><td>-</td></tr>",
        "edge thicknesses 2 mm in from each edge",
    ] {
        assert!(html.contains(cell), "{cell} not in the page");
    }
    assert_eq!(
        html.matches("<td>r100</td><td>172.8700").count(),
        1,
        "one row, B's"
    );
}

#[test]
fn the_blade_places_table_gives_each_blades_turn_and_spacing() {
    let mut report = three_blades();
    assert!(!report_html(&report).unwrap().contains("Blade places"));
    report.instances[2].index_deg = Some(0.0101);
    report.instances[2].angular_spacing_deg = Some(crate::analysis::section::ParameterValue::of(
        120.0, 120.0099,
    ));
    let html = report_html(&report).unwrap();
    let row = "<tr><td>C</td><td>+0.0101 deg</td><td>120.0099 deg (+0.0099)</td><td>120.0000 deg</td><td>-</td></tr>";
    assert!(html.contains(row), "{row} not in the page");
    assert_eq!(
        html.matches("<tr><td>A</td><td>").count(),
        0,
        "only C has a spacing"
    );
}

#[test]
fn toleranced_parameters_are_marked_with_their_limits_and_each_failure_listed() {
    let mut report = three_blades();
    crate::report::tests::judge_a_sample_blade(&mut report);
    let html = report_html(&report).unwrap();
    for text in [
        "<dt>parameter tolerances</dt><dd>the part file&#39;s [tolerance.parameters], else ISO 484 class I (",
        // The thickness fails the part file's +-0.03 mm; the chord passes class I's +-2 % (min 10 mm).
        "<td><span class=\"fail\">20.7001 mm (-0.0382)</span><br><small>[-0.0300, +0.0300] mm, the part file</small></td>",
        "<td><span class=\"pass\">172.8700 mm (+0.0200)</span><br><small>[-10.0000, +10.0000] mm, ISO 484 class I</small></td>",
        // The edge thicknesses have no tolerance: plain.
        "<td>6.3894 mm (-0.0134)</td>",
        "<td><span class=\"fail\">FAIL</span></td></tr>",
        "<span class=\"fail\">910.8000 mm (+10.8000)</span><br><small>[-9.0000, +9.0000] mm, ISO 484 class I</small>",
        "<h2>Parameters out of tolerance</h2>",
        "<li class=\"fail\">B r100: max_thickness_mm -0.0382 mm outside [-0.0300, +0.0300] mm (the part file)</li>",
        "<li class=\"fail\">blade B: blade_pitch_mm +10.8000 mm outside [-9.0000, +9.0000] mm (ISO 484 class I)</li>",
    ] {
        assert!(html.contains(text), "{text} not in the page:\n{html}");
    }
}

#[test]
fn a_profile_fitted_best_gets_a_third_whisker_plot_of_its_form_after_the_fit() {
    let mut report = three_blades();
    // B's first profile, 0.2 mm off before the fit, is within 2 um of the nominal after it.
    for point in &mut report.instances[1].profiles[0].points {
        point.after_fit_mm = Some(0.002);
    }
    let html = report_html(&report).unwrap();
    let plots = svgs(&html);
    assert_eq!(plots.len(), 2 * PROFILES.len() + 1);
    let after = plots[2];
    assert_well_formed(after);
    let title = format!(
        "{} after the best fit (shift and twist removed)",
        PROFILES[0].0
    );
    assert!(after.contains(&title), "{after}");
    // The largest deviation after the fit, 0.002 mm, against the 80 mm chord: 0.1 * 80 / 0.002 = 4000, x 5000.
    assert!(after.contains("whiskers x 5000 "), "{after}");
    assert!(
        plots[1].contains("whiskers x 50 "),
        "as measured, unchanged"
    );
    assert!(html.contains("its form error.</figcaption>"));
}

#[test]
fn a_section_with_parameters_gets_its_thickness_and_camber_along_the_chord_drawn() {
    let mut report = three_blades();
    let stations = |thicker: f64| -> Vec<[f64; 3]> {
        (0..=20)
            .map(|k| {
                let at = k as f64 / 20.0;
                [at, thicker + 12.0 * at * (1.0 - at), 0.4 * at * (1.0 - at)]
            })
            .collect()
    };
    report.instances[2].profiles[0].distribution =
        Some(crate::analysis::section::SectionDistribution {
            nominal: stations(0.0),
            measured: stations(0.0125),
        });
    let html = report_html(&report).unwrap();
    let plots = svgs(&html);
    assert_eq!(plots.len(), 2 * PROFILES.len() + 1);
    let figure = plots[2];
    assert_well_formed(figure);
    assert!(
        figure.contains(&format!(
            "{}: measured minus nominal along the chord (mm)",
            PROFILES[0].0
        )),
        "{figure}"
    );
    assert!(figure.contains("along the chord from the leading edge (%)"));
    assert!(
        figure.contains(&svg_text("C")),
        "the blade with one, labelled"
    );
    assert!(
        !figure.contains(&svg_text("A")),
        "blades without one left out"
    );
    assert!(html.contains("measured minus the nominal's at the same place along the chord"));
}
