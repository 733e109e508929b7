//! Fitting the master's points and measuring the other blades against the model, through the binary.

use crate::support::{config, deviations, mean, zeroset_ok};

#[test]
fn blades_b_and_c_deviate_by_the_simulated_0_8_mm_and_blade_a_by_its_noise() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("a.json");
    let fit = zeroset_ok(&[
        "fit",
        "ip",
        "--points",
        &config("profiles/seed003-profile3-blade-a.csv"),
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(
        fit.contains("fitted a degree-4 implicit polynomial"),
        "{fit}"
    );
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(saved["units"], "mm");
    assert_eq!(saved["version"], 1);
    assert_eq!(saved["model"]["kind"], "ip-profile");
    let rms = saved["model"]["fit"]["rms_distance_mm"].as_f64().unwrap();
    assert!(
        rms > 0.001 && rms < 0.003,
        "the fit follows the 2 um noise: RMS {rms} mm"
    );
    for (blade, expected) in [("a", 0.0), ("b", -0.8), ("c", 0.8)] {
        let out = dir.path().join(format!("{blade}.csv"));
        let printed = zeroset_ok(&[
            "deviate",
            "--model",
            model.to_str().unwrap(),
            "--points",
            &config(&format!("profiles/seed003-profile3-blade-{blade}.csv")),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(printed.contains("n = 400"), "{printed}");
        let values: Vec<f64> = deviations(&out)
            .into_iter()
            .map(|d| d.expect("every exact distance"))
            .collect();
        assert_eq!(values.len(), 400);
        assert!(
            (mean(&values) - expected).abs() < 0.001,
            "blade {blade}: mean {}",
            mean(&values)
        );
        assert!(
            values.iter().all(|d| (d - expected).abs() < 0.01),
            "blade {blade}: a point off by more than 10 um"
        );
    }
}

#[test]
fn the_paper_distance_against_the_published_quartic_agrees_with_the_exact_one() {
    let dir = tempfile::tempdir().unwrap();
    let model = config("models/seed003-profile3.json");
    let points = config("profiles/seed003-profile3-blade-b.csv");
    let mut by_method = Vec::new();
    for method in ["exact", "paper", "taubin"] {
        let out = dir.path().join(format!("{method}.csv"));
        zeroset_ok(&[
            "deviate",
            "--model",
            &model,
            "--points",
            &points,
            "--distance",
            method,
            "--out",
            out.to_str().unwrap(),
        ]);
        by_method.push(deviations(&out));
    }
    let (exact, paper, taubin) = (&by_method[0], &by_method[1], &by_method[2]);
    let mut answered = 0;
    for i in 0..exact.len() {
        let e = exact[i].expect("exact always answers");
        // Blade B lies 0.8 mm inside the published curve along its normal.
        assert!((e + 0.8).abs() < 0.01, "point {i}: exact {e}");
        if let Some(p) = paper[i] {
            answered += 1;
            assert!(
                p.abs() >= e.abs() - 1e-6,
                "the paper's foot is on the curve, never nearer"
            );
            assert!((p - e).abs() < 0.01, "point {i}: paper {p} vs exact {e}");
        }
        // Taubin's estimate is first order: off by far more than the paper's on a 0.8 mm offset.
        assert!(taubin[i].is_some());
    }
    assert!(
        answered > 300,
        "the paper's method answers most points of this fat section: {answered}"
    );
}

#[test]
fn a_stack_of_five_profiles_measures_blade_b_below_blade_a() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("stack.json");
    let fit = zeroset_ok(&[
        "fit",
        "ip",
        "--stack",
        "--degree",
        "8",
        "--points",
        &config("profiles/naca-blade-a-5-profiles.csv"),
        "--out",
        model.to_str().unwrap(),
    ]);
    assert_eq!(fit.matches("fitted a degree-8").count(), 5, "{fit}");
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(saved["model"]["kind"], "ip-stack");
    let xs: Vec<f64> = saved["model"]["profiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["x"].as_f64().unwrap())
        .collect();
    assert_eq!(xs, vec![100.0, 200.0, 300.0, 400.0, 500.0]);
    let measure = |blade: &str| {
        let out = dir.path().join(format!("{blade}.csv"));
        zeroset_ok(&[
            "deviate",
            "--model",
            model.to_str().unwrap(),
            "--points",
            &config(&format!("profiles/naca-blade-{blade}-5-profiles.csv")),
            "--out",
            out.to_str().unwrap(),
        ]);
        deviations(&out)
            .into_iter()
            .map(|d| d.expect("every exact distance"))
            .collect::<Vec<f64>>()
    };
    let a = measure("a");
    let rms_a = (a.iter().map(|d| d * d).sum::<f64>() / a.len() as f64).sqrt();
    assert!(
        rms_a < 0.01,
        "blade A against its own model: RMS {rms_a} mm"
    );
    // Blade B is shifted 0.4 mm (root) to 1.0 mm (tip) along -z: no point can be farther than that, and the
    // points of the tip profile (the last 400) face the shift along their normals by up to the full 1.0 mm.
    let b = measure("b");
    assert!(
        b.iter().all(|d| d.abs() <= 1.0 + 0.01),
        "a deviation beyond the largest shift"
    );
    let tip_max = b[1600..].iter().fold(0.0f64, |m, d| m.max(d.abs()));
    assert!(
        tip_max > 0.95,
        "the tip profile's largest deviation is {tip_max} mm"
    );
    let root_max = b[..400].iter().fold(0.0f64, |m, d| m.max(d.abs()));
    assert!(
        root_max > 0.38 && root_max < 0.41,
        "the root profile's largest deviation is {root_max} mm"
    );
}

/// Points on the ellipsoid x^2/40^2 + y^2/30^2 + z^2/20^2 = 1 (mm), moved `offset` mm along the outward normal,
/// as an x,y,z point file.
fn ellipsoid_csv(path: &std::path::Path, count: usize, offset: f64) {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut text = String::from("x,y,z\n");
    for i in 0..count {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f64;
        let (ux, uy, uz) = (r * phi.cos(), r * phi.sin(), z);
        let p = [40.0 * ux, 30.0 * uy, 20.0 * uz];
        let n = [p[0] / 1600.0, p[1] / 900.0, p[2] / 400.0];
        let length = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let q: Vec<String> = (0..3)
            .map(|k| format!("{:.6}", p[k] + offset * n[k] / length))
            .collect();
        text.push_str(&q.join(","));
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

#[test]
fn a_surface_fitted_to_3d_points_measures_an_offset_surface() {
    let dir = tempfile::tempdir().unwrap();
    let master = dir.path().join("master.csv");
    let part = dir.path().join("part.csv");
    ellipsoid_csv(&master, 1500, 0.0);
    ellipsoid_csv(&part, 500, 0.25);
    let model = dir.path().join("surface.json");
    let fit = zeroset_ok(&[
        "fit",
        "ip",
        "--points",
        master.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
    ]);
    assert!(fit.contains("(surface) to 1500 points"), "{fit}");
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(saved["model"]["kind"], "ip-surface");
    let out = dir.path().join("deviations.csv");
    zeroset_ok(&[
        "deviate",
        "--model",
        model.to_str().unwrap(),
        "--points",
        part.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let values: Vec<f64> = deviations(&out)
        .into_iter()
        .map(|d| d.expect("every exact distance"))
        .collect();
    assert!(
        values.iter().all(|d| (d - 0.25).abs() < 0.001),
        "an offset of 0.25 mm everywhere: {:?}",
        &values[..5]
    );
}
