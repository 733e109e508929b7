//! A fit that is plainly not a model of its data says so, with the reason and what to try; a good one says
//! nothing; points no machine measured, or far from the rest, are named by their lines.

use crate::support::{config, deviate, fit_ip, zeroset};

/// The warning lines a command printed.
fn warnings(printed: &str) -> Vec<&str> {
    printed
        .lines()
        .map(str::trim)
        .filter(|l| l.starts_with("warning:"))
        .collect()
}

#[test]
fn a_spurious_branch_is_a_warning_only_beside_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("model.json");
    // Seed 003's blades: the quartics of a and b have further zero-set components, far out in the box (the
    // warning of every fit before): no warning. (Held out, the points of b and c, 0.8 mm off a's quartic, choose
    // degree 6; the degree is given here.)
    for (blade, components) in [("a", 2), ("b", 3), ("c", 1)] {
        let (printed, saved) = fit_ip(
            &config(&format!("profiles/seed003-profile3-blade-{blade}.csv")),
            &["--degree", "4"],
            &model,
        );
        assert_eq!(
            saved["model"]["fit"]["zero_set_components"], components,
            "{printed}"
        );
        assert_eq!(
            saved["model"]["fit"]["branches_beside_data"], 0,
            "{printed}"
        );
        assert!(warnings(&printed).is_empty(), "blade {blade}:\n{printed}");
    }
    // A quartic on a NACA 2412 with a sharp trailing edge grows a branch 0.7 mm from the section: said.
    let (printed, saved) = fit_ip(
        &config("profiles/naca2412-sharp-te-exact.csv"),
        &["--edges", "none", "--degree", "4"],
        &model,
    );
    assert_eq!(
        saved["model"]["fit"]["branches_beside_data"], 1,
        "{printed}"
    );
    let said = warnings(&printed);
    assert!(
        said.len() == 1
            && said[0].contains("1 spurious zero-set branch(es) within 2.01 mm of the data"),
        "{printed}"
    );
}

#[test]
fn profiles_fitted_as_one_surface_are_told_to_use_stack() {
    let dir = tempfile::tempdir().unwrap();
    let points = config("profiles/naca-blade-a-5-profiles.csv");
    let (printed, saved) = fit_ip(&points, &[], &dir.path().join("surface.json"));
    let rms = saved["model"]["fit"]["rms_distance_mm"].as_f64().unwrap();
    let said = warnings(&printed);
    assert!(
        said.iter()
            .any(|w| w.contains("the points' own scatter") && w.contains(&format!("{rms:.4} mm"))),
        "RMS {rms} mm: {printed}"
    );
    assert!(
        said.iter()
            .any(|w| w.contains("5 parallel planes of constant x")
                && w.contains("--stack")
                && w.contains(
                    "the surface took degree 4: points held out of profiles cannot judge it"
                )),
        "{printed}"
    );
    // Held out, the profiles' points would choose a degree that passes through every plane and models nothing
    // between them.
    assert_eq!(saved["model"]["ip"]["poly"]["degree"], 4, "{printed}");
    // As a stack the same points raise neither doubt.
    let (printed, _) = fit_ip(&points, &["--stack"], &dir.path().join("stack.json"));
    assert!(
        !printed.contains("own scatter") && !printed.contains("parallel planes"),
        "{printed}"
    );
}

#[test]
fn a_fit_beyond_the_part_s_tolerance_is_named_with_where() {
    let dir = tempfile::tempdir().unwrap();
    let points = config("profiles/seed003-profile3-blade-a.csv");
    let (printed, saved) = fit_ip(&points, &[], &dir.path().join("model.json"));
    let max = saved["model"]["fit"]["max_distance_mm"].as_f64().unwrap();
    assert!(warnings(&printed).is_empty(), "{printed}");
    // A tolerance just below the fit's largest distance: the fit is not good to it.
    let tolerance = format!("{}", max * 0.9);
    let (printed, _) = fit_ip(
        &points,
        &["--tolerance", &tolerance],
        &dir.path().join("model.json"),
    );
    let said = warnings(&printed);
    assert!(
        said.len() == 1
            && said[0].contains(&format!("{max:.4} mm from the model at ("))
            && said[0].contains(&format!("tolerance of {tolerance} mm")),
        "{printed}"
    );
    let (printed, _) = fit_ip(
        &points,
        &["--tolerance", &format!("{}", max * 1.1)],
        &dir.path().join("model.json"),
    );
    assert!(warnings(&printed).is_empty(), "{printed}");
}

/// The blade-a profile with line `line` (the header is line 1) replaced by `row`.
fn with_row(dir: &std::path::Path, line: usize, row: &str) -> String {
    let text = std::fs::read_to_string(config("profiles/seed003-profile3-blade-a.csv")).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[line - 1] = row;
    let path = dir.join(format!("line-{line}.csv"));
    std::fs::write(&path, lines.join("\n") + "\n").unwrap();
    path.display().to_string()
}

#[test]
fn a_point_no_machine_measured_or_far_from_the_rest_is_named_by_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let absurd = with_row(dir.path(), 51, "1e30,0");
    let run = zeroset(&[
        "fit",
        "ip",
        "--points",
        &absurd,
        "--out",
        dir.path().join("m.json").to_str().unwrap(),
    ]);
    assert!(!run.success);
    assert!(
        run.stderr.contains(&format!(
            "{absurd}: line 51: column y: 1e30 mm is beyond any measuring machine's reach"
        )),
        "{}",
        run.stderr
    );
    let stray = with_row(dir.path(), 80, "400,20");
    let (printed, _) = fit_ip(&stray, &[], &dir.path().join("m.json"));
    assert!(
        warnings(&printed)
            .iter()
            .any(|w| w.contains("1 point(s) stand far from all the others (line 80)")),
        "{printed}"
    );
}

#[test]
fn deviate_leaves_points_far_outside_the_model_unmeasured_and_names_them() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("a.json");
    fit_ip(
        &config("profiles/seed003-profile3-blade-b.csv"),
        &[],
        &model,
    );
    // Blade a's points, one of them a kilometre away (a unit error: metres written as millimetres).
    let points = with_row(dir.path(), 51, "99000,-400");
    let out = dir.path().join("deviations.csv");
    let (values, printed) = deviate(&model, &points, None, &out);
    assert_eq!(values.len(), 400);
    assert_eq!(values[49], None, "the far point has no deviation");
    assert_eq!(values.iter().filter(|v| v.is_none()).count(), 1);
    let status = std::fs::read_to_string(&out).unwrap();
    assert!(
        status
            .lines()
            .nth(50)
            .unwrap()
            .ends_with(",outside-model-range"),
        "{status}"
    );
    assert!(printed.contains("n = 399"), "{printed}");
    assert!(
        warnings(&printed).iter().any(|w| w
            .contains("1 point(s) lie far outside the model's range")
            && w.contains("(line 51)")),
        "{printed}"
    );
    // The statistics are those of the 399 measured points: blade a lies 0.8 mm off blade b's model.
    let rms = printed
        .split("RMS ")
        .nth(1)
        .and_then(|s| s.split(' ').next())
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap();
    assert!((rms - 0.8).abs() < 0.01, "{printed}");
}
