//! Bad input exits non-zero with one line naming the file, the line and the problem.

use std::path::Path;

use crate::support::{config, zeroset};

/// Fits a point file with the given text and returns the single error line (asserting there is exactly one).
fn fit_error(text: &str, degree: &str) -> String {
    fit_error_with(text, &["--degree", degree])
}

/// As [`fit_error`], with these arguments after the point file's.
fn fit_error_with(text: &str, args: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("points.csv");
    std::fs::write(&points, text).unwrap();
    let out = dir.path().join("model.json");
    let run = zeroset(
        &[
            "fit",
            "ip",
            "--points",
            points.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]
        .into_iter()
        .chain(args.iter().copied())
        .collect::<Vec<_>>(),
    );
    assert!(!run.success, "bad input must fail: {}", run.stdout);
    assert!(!out.exists(), "no model is written from bad input");
    let lines: Vec<&str> = run.stderr.lines().collect();
    assert_eq!(lines.len(), 1, "one line: {:?}", run.stderr);
    lines[0].replace(&dir.path().display().to_string(), "DIR")
}

fn circle_csv(count: usize) -> String {
    let mut text = String::from("y,z\n");
    for i in 0..count {
        let t = i as f64 / count as f64 * std::f64::consts::TAU;
        text.push_str(&format!("{},{}\n", 10.0 * t.cos(), 10.0 * t.sin()));
    }
    text
}

#[test]
fn a_missing_file_is_named() {
    let run = zeroset(&[
        "fit",
        "ip",
        "--points",
        "/no/such/file.csv",
        "--out",
        "/tmp/never.json",
    ]);
    assert!(!run.success);
    assert!(
        run.stderr
            .starts_with("error: /no/such/file.csv: cannot open"),
        "{}",
        run.stderr
    );
    assert!(!Path::new("/tmp/never.json").exists());
}

#[test]
fn a_non_number_names_its_line_and_column() {
    let mut text = circle_csv(30);
    text.push_str("1.0,abc\n");
    assert_eq!(
        fit_error(&text, "4"),
        "error: DIR/points.csv: line 32: column z: 'abc' is not a number"
    );
}

#[test]
fn nan_is_rejected() {
    let text = circle_csv(30).replacen("\n10,0\n", "\nNaN,0\n", 1);
    assert_eq!(
        fit_error(&text, "4"),
        "error: DIR/points.csv: line 2: column y: 'NaN' is not a finite number"
    );
}

#[test]
fn an_unknown_column_is_named() {
    let text = circle_csv(30).replacen("y,z", "y,w", 1);
    assert!(fit_error(&text, "4").starts_with("error: DIR/points.csv: line 1: unknown column 'w'"));
}

#[test]
fn too_few_points_for_the_degree_says_how_many_are_needed() {
    let line = fit_error(&circle_csv(12), "4");
    assert_eq!(
        line,
        "error: DIR/points.csv: lines 2-13: 12 points are too few for a degree-4 fit (it has 15 coefficients; give at least 15 points)"
    );
}

#[test]
fn a_stack_profile_s_error_names_that_profile_and_its_own_lines() {
    // Two profiles: 30 points at x = 100 mm (lines 2-31), then 12 at x = 200 mm (lines 32-43), too few for a
    // quartic.
    let mut text = String::from("x,y,z\n");
    for (x, count) in [(100.0, 30), (200.0, 12)] {
        for line in circle_csv(count).lines().skip(1) {
            text.push_str(&format!("{x},{line}\n"));
        }
    }
    assert_eq!(
        fit_error_with(&text, &["--stack", "--degree", "4"]),
        "error: DIR/points.csv: lines 32-43: the profile at x = 200.000 mm: 12 points are too few for a degree-4 \
         fit (it has 15 coefficients; give at least 15 points)"
    );
}

#[test]
fn a_stack_of_profiles_some_with_sharp_edges_and_some_without_names_the_planes_without() {
    // The blade's root profile (sharp trailing edge, lines 2-401) and a circle at x = 250 mm.
    let blade = std::fs::read_to_string(config("profiles/naca-blade-a-5-profiles.csv")).unwrap();
    let mut text: String = blade.lines().take(401).map(|l| format!("{l}\n")).collect();
    for line in circle_csv(200).lines().skip(1) {
        text.push_str(&format!("250,{line}\n"));
    }
    assert_eq!(
        fit_error_with(&text, &["--stack"]),
        "error: DIR/points.csv: the profiles at x = 250.000 mm have no sharp edge while the others have: a stack \
         is lofted face to face between like profiles; check those profiles' points, or fit one polynomial per \
         profile with --edges none"
    );
}

#[test]
fn collinear_points_are_refused() {
    let mut text = String::from("y,z\n");
    for i in 0..40 {
        text.push_str(&format!("{},{}\n", i as f64, 2.0 * i as f64 + 1.0));
    }
    let line = fit_error(&text, "2");
    assert_eq!(line, "error: DIR/points.csv: lines 2-41: the points do not span 2 dimensions (they lie on a straight line); a fit needs a 2-D spread");
}

#[test]
fn a_profile_model_refuses_3d_points() {
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("points.csv");
    std::fs::write(&points, "x,y,z\n1,2,3\n").unwrap();
    let model = crate::support::config("models/seed003-profile3.json");
    let run = zeroset(&[
        "deviate",
        "--model",
        &model,
        "--points",
        points.to_str().unwrap(),
        "--out",
        "/tmp/x.csv",
    ]);
    assert!(!run.success);
    assert!(
        run.stderr
            .contains("is a profile, which needs y,z points; this file has x,y,z"),
        "{}",
        run.stderr
    );
}
