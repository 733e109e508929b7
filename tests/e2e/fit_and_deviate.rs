//! Fitting the master's points and measuring the other blades against the model, through the binary.

use std::path::PathBuf;

use rand::SeedableRng;
use rand_distr::Distribution;

use zeroset_sim::naca::Naca4;

use crate::support::{config, deviate, fit_ip, mean, naca_csv, zeroset_with_stdout_closed};

/// The exact deviations of a point file, every point required to have one.
fn exact_deviations(model: &std::path::Path, points: &str, out: &std::path::Path) -> Vec<f64> {
    let (values, _) = deviate(model, points, None, out);
    values
        .into_iter()
        .map(|d| d.expect("every exact distance"))
        .collect()
}

fn rms(values: &[f64]) -> f64 {
    (values.iter().map(|d| d * d).sum::<f64>() / values.len() as f64).sqrt()
}

fn largest(values: &[f64]) -> f64 {
    values.iter().fold(0.0f64, |m, d| m.max(d.abs()))
}

#[test]
fn blades_b_and_c_deviate_by_the_simulated_0_8_mm_and_blade_a_by_its_noise() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("a.json");
    let (fit, saved) = fit_ip(
        &config("profiles/seed003-profile3-blade-a.csv"),
        &[],
        &model,
    );
    // Seed 003's quartic: the points held out of the fit choose degree 4, higher degrees only following the noise.
    assert!(
        fit.contains("fitted a degree-4 implicit polynomial"),
        "{fit}"
    );
    assert!(
        fit.contains(
            "degree 4 chosen by the RMS distance of the points held out of the fit (4: 2."
        ),
        "{fit}"
    );
    assert_eq!(saved["units"], "mm");
    assert_eq!(saved["version"], 1);
    assert_eq!(saved["model"]["kind"], "ip-profile");
    let fit_rms = saved["model"]["fit"]["rms_distance_mm"].as_f64().unwrap();
    assert!(
        fit_rms > 0.001 && fit_rms < 0.003,
        "the fit follows the 2 um noise: RMS {fit_rms} mm"
    );
    for (blade, expected) in [("a", 0.0), ("b", -0.8), ("c", 0.8)] {
        let points = config(&format!("profiles/seed003-profile3-blade-{blade}.csv"));
        let out = dir.path().join(format!("{blade}.csv"));
        let (values, printed) = deviate(&model, &points, None, &out);
        assert!(printed.contains("n = 400"), "{printed}");
        assert!(
            printed.contains("certificate: 400 of 400 distances proved the global minimum"),
            "{printed}"
        );
        let values: Vec<f64> = values
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

    // A closed standard output (`| head` with its lines) ends each offline command quietly, with the code of a
    // program cut off by it, after any file it was asked for is written.
    let points = config("profiles/seed003-profile3-blade-b.csv");
    let refit = dir.path().join("refit.json");
    let deviations = dir.path().join("closed.csv");
    for args in [
        vec![
            "fit",
            "ip",
            "--points",
            &points,
            "--degree",
            "4",
            "--out",
            refit.to_str().unwrap(),
        ],
        vec![
            "deviate",
            "--model",
            model.to_str().unwrap(),
            "--points",
            &points,
            "--out",
            deviations.to_str().unwrap(),
        ],
        vec![
            "evaluate",
            "--model",
            model.to_str().unwrap(),
            "--points",
            &points,
        ],
    ] {
        let run = zeroset_with_stdout_closed(&args);
        assert_eq!(run.code, Some(141), "zeroset {args:?}: {}", run.stderr);
        assert_eq!(run.stderr, "", "zeroset {args:?}");
    }
    assert!(refit.exists() && deviations.exists());
}

#[test]
fn the_paper_distance_against_the_published_quartic_agrees_with_the_exact_one() {
    let dir = tempfile::tempdir().unwrap();
    let model = PathBuf::from(config("models/seed003-profile3.json"));
    let points = config("profiles/seed003-profile3-blade-b.csv");
    let by_method: Vec<Vec<Option<f64>>> = ["exact", "paper", "taubin"]
        .iter()
        .map(|m| {
            deviate(
                &model,
                &points,
                Some(m),
                &dir.path().join(format!("{m}.csv")),
            )
            .0
        })
        .collect();
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
        let t = taubin[i].expect("Taubin answers where the gradient does not vanish");
        assert_eq!(
            t.signum(),
            e.signum(),
            "point {i}: Taubin {t} on the other side"
        );
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
    let points = config("profiles/naca-blade-a-5-profiles.csv");
    let (fit, saved) = fit_ip(
        &points,
        &["--stack", "--degree", "8", "--edges", "none"],
        &model,
    );
    assert_eq!(fit.matches("fitted a degree-8").count(), 5, "{fit}");
    assert_eq!(saved["model"]["kind"], "ip-stack");
    let xs: Vec<f64> = saved["model"]["profiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["x"].as_f64().unwrap())
        .collect();
    assert_eq!(xs, vec![100.0, 200.0, 300.0, 400.0, 500.0]);
    let measure = |blade: &str| {
        let points = config(&format!("profiles/naca-blade-{blade}-5-profiles.csv"));
        exact_deviations(&model, &points, &dir.path().join(format!("{blade}.csv")))
    };
    let a = measure("a");
    assert!(
        rms(&a) < 0.01,
        "blade A against its own model: RMS {} mm",
        rms(&a)
    );
    assert_blade_b_lies_below_a(&measure("b"), 0.01, 0.95, (0.38, 0.41));
}

/// Blade B is shifted 0.4 mm (root) to 1.0 mm (tip) along -z: no point can be farther than that (plus `beyond`),
/// and the points of the tip profile (the last 400) face the shift along their normals by up to the full 1.0 mm
/// (more than `tip_above`); the root profile's (the first 400) by 0.4 mm (within `root`).
fn assert_blade_b_lies_below_a(b: &[f64], beyond: f64, tip_above: f64, root: (f64, f64)) {
    assert!(
        largest(b) <= 1.0 + beyond,
        "a deviation beyond the largest shift: {} mm",
        largest(b)
    );
    let tip = largest(&b[1600..]);
    assert!(
        tip > tip_above,
        "the tip profile's largest deviation is {tip} mm"
    );
    let at_root = largest(&b[..400]);
    assert!(
        at_root > root.0 && at_root < root.1,
        "the root profile's largest deviation is {at_root} mm"
    );
}

#[test]
fn a_blade_s_stack_is_lofted_face_by_face_and_measures_blade_b_below_blade_a() {
    // The five profiles have sharp trailing edges: each is fitted face by face, each face lofted through the same
    // face of every profile, the edges running through every profile's edge.
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("stack.json");
    let points = config("profiles/naca-blade-a-5-profiles.csv");
    let (fit, saved) = fit_ip(&points, &["--stack"], &model);
    assert_eq!(saved["model"]["kind"], "ip-faces-stack", "{fit}");
    assert_eq!(
        fit.matches("1 sharp edge(s) at").count(),
        5,
        "every profile's trailing edge: {fit}"
    );
    assert!(fit.contains("stack of faces: 5 profiles"), "{fit}");
    let profiles = saved["model"]["profiles"].as_array().unwrap();
    let xs: Vec<f64> = profiles.iter().map(|p| p["x"].as_f64().unwrap()).collect();
    assert_eq!(xs, vec![100.0, 200.0, 300.0, 400.0, 500.0]);
    assert!(profiles
        .iter()
        .all(|p| p["profile"]["faces"].as_array().unwrap().len() == 3));
    let measure = |blade: &str| {
        let points = config(&format!("profiles/naca-blade-{blade}-5-profiles.csv"));
        exact_deviations(&model, &points, &dir.path().join(format!("{blade}.csv")))
    };
    // Blade A against its own model: the probe's 2 um of noise, and no more (the polynomial stack of the same
    // points at degree 8 reads 4.9 um RMS and 51 um at worst).
    let a = measure("a");
    assert!(rms(&a) < 0.0025, "blade A: RMS {} mm", rms(&a));
    assert!(largest(&a) < 0.010, "blade A: {} mm at worst", largest(&a));
    assert_blade_b_lies_below_a(&measure("b"), 0.005, 0.99, (0.395, 0.405));
}

/// Points on the ellipsoid x^2/40^2 + y^2/30^2 + z^2/20^2 = 1 (mm), moved `offset` mm along the outward normal,
/// as an x,y,z point file.
pub fn ellipsoid_csv(path: &std::path::Path, count: usize, offset: f64) {
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

/// The degree a fit's output says it took, each degree's held-out RMS (um) and the line: the line starting with
/// `start`, as "D chosen by the RMS distance ... (4: a um, 6: b um, 8: c um); --degree gives one".
fn degree_said(fit: &str, start: &str) -> (usize, Vec<(usize, f64)>, String) {
    let line = fit
        .lines()
        .find(|l| l.starts_with(start))
        .unwrap_or_else(|| panic!("no '{start}' line: {fit}"));
    let degree: usize = line[start.len()..]
        .split(' ')
        .next()
        .and_then(|d| d.parse().ok())
        .unwrap_or_else(|| panic!("{line}"));
    let scores: Vec<(usize, f64)> = line[line.find('(').unwrap() + 1..line.find(')').unwrap()]
        .split(", ")
        .map(|score| {
            let (d, rms) = score.split_once(": ").unwrap();
            (
                d.parse().unwrap(),
                rms.trim_end_matches(" um").parse().unwrap(),
            )
        })
        .collect();
    assert_eq!(
        scores.iter().map(|s| s.0).collect::<Vec<_>>(),
        vec![4, 6, 8],
        "{line}"
    );
    (degree, scores, line.to_string())
}

/// The degree and held-out RMS the rule takes: from the lowest up, a higher degree replaces the one chosen so far
/// only by beating its held-out RMS by 10%.
fn degree_by_the_rule(scores: &[(usize, f64)]) -> (usize, f64) {
    let mut expected = scores[0];
    for &score in &scores[1..] {
        if score.1 < 0.9 * expected.1 {
            expected = score;
        }
    }
    expected
}

#[test]
fn a_stack_without_a_degree_takes_the_one_the_points_held_out_of_all_its_profiles_choose() {
    // The blade's NACA profiles have sharp trailing edges, which no quartic follows: the points held out of the
    // five profiles' fits choose a higher degree, one for all of them (profiles blend only at equal degrees).
    let dir = tempfile::tempdir().unwrap();
    let points = config("profiles/naca-blade-a-5-profiles.csv");
    let (fit, saved) = fit_ip(
        &points,
        &["--stack", "--edges", "none"],
        &dir.path().join("stack.json"),
    );
    let (degree, scores, line) = degree_said(&fit, "stack degree ");
    let expected = degree_by_the_rule(&scores);
    assert!(
        degree == expected.0 && line.starts_with(&format!("stack degree {degree} chosen by ")),
        "{line}"
    );
    assert!(
        degree > 4 && scores[0].1 > 2.0 * expected.1,
        "a quartic should not follow the sharp edges: {line}"
    );
    assert_eq!(
        fit.matches(&format!(
            "fitted a degree-{degree} implicit polynomial (profile at x"
        ))
        .count(),
        5,
        "{fit}"
    );
    let degrees: Vec<u64> = saved["model"]["profiles"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["ip"]["poly"]["degree"].as_u64().unwrap())
        .collect();
    assert_eq!(degrees, vec![degree as u64; 5]);
}

#[test]
fn a_surface_fitted_to_3d_points_measures_an_offset_surface() {
    let dir = tempfile::tempdir().unwrap();
    let master = dir.path().join("master.csv");
    let part = dir.path().join("part.csv");
    ellipsoid_csv(&master, 1500, 0.0);
    ellipsoid_csv(&part, 500, 0.25);
    let model = dir.path().join("surface.json");
    let (fit, saved) = fit_ip(master.to_str().unwrap(), &[], &model);
    assert!(fit.contains("(surface) to 1500 points"), "{fit}");
    assert_eq!(saved["model"]["kind"], "ip-surface");
    // An ellipsoid is a quadric: no higher degree follows it better, and the lowest tried is kept.
    let (degree, _, line) = degree_said(&fit, "  degree ");
    assert!(degree == 4 && line.contains("chosen by"), "{line}");
    let values = exact_deviations(
        &model,
        part.to_str().unwrap(),
        &dir.path().join("deviations.csv"),
    );
    assert!(
        values.iter().all(|d| (d - 0.25).abs() < 0.001),
        "an offset of 0.25 mm everywhere: {:?}",
        &values[..5]
    );
}

#[test]
fn a_surface_without_a_degree_takes_the_one_its_held_out_points_choose() {
    // x^6/a^6 + y^6/b^6 + z^6/c^6 = 1, a rounded box of 80 x 60 x 40 mm: a sextic, which no quartic follows, with
    // 2 um of noise along the normal. Degree 6 follows it to the noise; 8 follows the noise too, no closer.
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("box.csv");
    let sizes = [40.0, 30.0, 20.0];
    let mut rng = rand::rngs::StdRng::seed_from_u64(606);
    let noise = rand_distr::Normal::new(0.0, 0.002).unwrap();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut text = String::from("x,y,z\n");
    for i in 0..2000 {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / 2000.0;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f64;
        let u = [r * phi.cos(), r * phi.sin(), z];
        let reach = (0..3)
            .map(|k| (u[k] / sizes[k]).powi(6))
            .sum::<f64>()
            .powf(-1.0 / 6.0);
        let p: Vec<f64> = u.iter().map(|c| c * reach).collect();
        let gradient: Vec<f64> = (0..3).map(|k| p[k].powi(5) / sizes[k].powi(6)).collect();
        let length = gradient.iter().map(|g| g * g).sum::<f64>().sqrt();
        let moved = noise.sample(&mut rng);
        let q: Vec<String> = (0..3)
            .map(|k| format!("{:.6}", p[k] + moved * gradient[k] / length))
            .collect();
        text.push_str(&q.join(","));
        text.push('\n');
    }
    std::fs::write(&points, text).unwrap();
    let (fit, saved) = fit_ip(points.to_str().unwrap(), &[], &dir.path().join("box.json"));
    let (degree, scores, line) = degree_said(&fit, "  degree ");
    let expected = degree_by_the_rule(&scores);
    assert!(
        degree == 6 && expected.0 == 6 && line.contains("chosen by"),
        "{line}"
    );
    assert!(
        scores[0].1 > 5.0 * expected.1 && expected.1 < 3.0,
        "a quartic misses the box's corners by far more than the noise: {line}"
    );
    assert_eq!(saved["model"]["ip"]["poly"]["degree"], 6, "{fit}");
}

#[test]
fn a_sharp_trailing_edge_is_fitted_face_by_face_and_measured_to_the_edge() {
    let dir = tempfile::tempdir().unwrap();
    let foil = Naca4::from_digits("6412", 250.0, true).unwrap();
    let scan = dir.path().join("scan.csv");
    naca_csv(&scan, &foil, 400, 0.0, 0.002, 42);
    let model = dir.path().join("faces.json");
    let (fit, saved) = fit_ip(scan.to_str().unwrap(), &[], &model);
    assert!(fit.contains("1 sharp edge(s) at ("), "{fit}");
    assert!(fit.contains("3 faces joined at the edges"), "{fit}");
    assert!(fit.contains("chosen by held-out RMS"), "{fit}");
    assert_eq!(saved["model"]["kind"], "ip-faces");
    assert_eq!(saved["model"]["faces"].as_array().unwrap().len(), 3);
    let edge = saved["model"]["joins"]
        .as_array()
        .unwrap()
        .iter()
        .find(|j| j["sharp"] == true)
        .expect("the trailing edge");
    let (y, z) = (
        edge["point"][0].as_f64().unwrap(),
        edge["point"][1].as_f64().unwrap(),
    );
    assert!(
        (y - 250.0).hypot(z) < 0.01,
        "the trailing edge at ({y}, {z}) mm"
    );
    // The true section, densely (cosine-spaced: crowded at both edges), lies within 5 um of the model.
    let truth = dir.path().join("truth.csv");
    naca_csv(&truth, &foil, 4000, 0.0, 0.0, 0);
    let (values, printed) = deviate(
        &model,
        truth.to_str().unwrap(),
        None,
        &dir.path().join("t.csv"),
    );
    assert!(
        printed.contains("certificate: 4000 of 4000 distances proved"),
        "{printed}"
    );
    let truth_worst = largest(&values.into_iter().map(|d| d.unwrap()).collect::<Vec<_>>());
    assert!(
        truth_worst < 0.005,
        "the true section is {truth_worst} mm from the model"
    );
    // Round the edge, 0.1 mm out, in its normal cone: the edge itself is the nearest point of the part.
    let beyond = dir.path().join("beyond.csv");
    let mut text = String::from("y,z\n");
    for degrees in [-60.0f64, -30.0, 0.0, 30.0, 60.0] {
        let (sin, cos) = degrees.to_radians().sin_cos();
        text.push_str(&format!("{},{}\n", 250.0 + 0.1 * cos, 0.1 * sin));
    }
    std::fs::write(&beyond, text).unwrap();
    let values = exact_deviations(&model, beyond.to_str().unwrap(), &dir.path().join("b.csv"));
    assert!(
        values.iter().all(|d| (d - 0.1).abs() < 0.005),
        "0.1 mm beyond the edge: {values:?}"
    );
    // One polynomial round the same points misses the true section by more than twice as much.
    let single = dir.path().join("single.json");
    let (fit, saved) = fit_ip(
        scan.to_str().unwrap(),
        &["--edges", "none", "--degree", "8"],
        &single,
    );
    assert!(!fit.contains("sharp edge"), "{fit}");
    assert_eq!(saved["model"]["kind"], "ip-profile");
    let values = exact_deviations(&single, truth.to_str().unwrap(), &dir.path().join("s.csv"));
    assert!(
        largest(&values) > 2.0 * truth_worst,
        "one polynomial: {} mm, the faces {truth_worst} mm",
        largest(&values)
    );
}

#[test]
fn deviations_near_a_sharp_trailing_edge_keep_their_sign() {
    // Found in review: fitted at degree 8 to these exact NACA 2412 points (the reviewer's generator, lower
    // surface first), the free orthogonal refinement grew a sliver of zero set inside the last tenth of the chord,
    // and 22 of these 32 points (at 50% to 99.5% of chord, alternately 0.05 mm outside and 0.02 mm inside the true
    // surface) were reported on the wrong side.
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("naca8.json");
    let (fit, _) = fit_ip(
        &config("profiles/naca2412-sharp-te-exact.csv"),
        &["--degree", "8"],
        &model,
    );
    assert!(!fit.contains("crosses"), "the fit reports a sliver:\n{fit}");
    let points = config("profiles/naca2412-sharp-te-side-points.csv");
    let values = exact_deviations(&model, &points, &dir.path().join("side.csv"));
    assert_eq!(values.len(), 32);
    for (i, d) in values.iter().enumerate() {
        let (expected, offset) = if i % 2 == 0 {
            (1.0, 0.05)
        } else {
            (-1.0, -0.02)
        };
        assert_eq!(
            d.signum(),
            expected,
            "point {i}, {offset} mm off the surface: {d} mm"
        );
        assert!(
            (d - offset).abs() < 0.01,
            "point {i}: {d} mm for {offset} mm"
        );
    }
}

/// The ellipsoid is the supershape m1 = m2 = 4 with every exponent 2: `zeroset fit supershape` recovers it from
/// its points (symmetry read from them), and `zeroset deviate` measures the surface 0.25 mm outside it by the exact
/// distance to the recovered solid.
#[test]
fn a_supershape_recovered_from_3d_points_measures_an_offset_surface() {
    let dir = tempfile::tempdir().unwrap();
    let master = dir.path().join("master.csv");
    let part = dir.path().join("part.csv");
    ellipsoid_csv(&master, 2000, 0.0);
    ellipsoid_csv(&part, 300, 0.25);
    let model = dir.path().join("supershape.json");
    let printed = fit_supershape_ok(&master, &model, &[]);
    assert!(
        printed.contains("2000 points") && printed.contains("symmetry 4,4"),
        "{printed}"
    );
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(saved["model"]["kind"], "supershape");
    assert_eq!(saved["units"], "mm");
    let values = exact_deviations(
        &model,
        part.to_str().unwrap(),
        &dir.path().join("deviations.csv"),
    );
    assert!(
        values.iter().all(|d| (d - 0.25).abs() < 0.002),
        "an offset of 0.25 mm everywhere: worst {}",
        values.iter().fold(0.0f64, |m, d| m.max((d - 0.25).abs()))
    );
}

/// A rounded box, the superquadric epsilon1 = 0.4 (along z), epsilon2 = 0.6 (across), half sizes 30 x 20 x 12 mm,
/// turned and moved off the origin: x = a1 C(eta)^e1 C(omega)^e2 and so on, C the signed power of the cosine.
fn superquadric_csv(path: &std::path::Path, count: usize) {
    let signed = |t: f64, e: f64| t.signum() * t.abs().powf(e);
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let (e1, e2) = (0.4, 0.6);
    let (cos_t, sin_t) = (0.5f64.cos(), 0.5f64.sin());
    let mut text = String::from("x,y,z\n");
    for i in 0..count {
        let eta = (1.0 - 2.0 * (i as f64 + 0.5) / count as f64).asin();
        let omega = golden * i as f64;
        let x = 30.0 * signed(eta.cos(), e1) * signed(omega.cos(), e2);
        let y = 20.0 * signed(eta.cos(), e1) * signed(omega.sin(), e2);
        let z = 12.0 * signed(eta.sin(), e1);
        // A turn of 0.5 rad about x, then 100, -50, 25 mm off the origin.
        let p = [
            100.0 + x,
            -50.0 + cos_t * y - sin_t * z,
            25.0 + sin_t * y + cos_t * z,
        ];
        text.push_str(&format!("{:.6},{:.6},{:.6}\n", p[0], p[1], p[2]));
    }
    std::fs::write(path, text).unwrap();
}

/// `zeroset fit supershape --points POINTS --out MODEL` with `extra` options.
fn fit_supershape(
    points: &std::path::Path,
    model: &std::path::Path,
    extra: &[&str],
) -> crate::support::Run {
    let mut args = vec![
        "fit",
        "supershape",
        "--points",
        points.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    crate::support::zeroset(&args)
}

/// `fit_supershape` that must succeed; what it printed.
fn fit_supershape_ok(points: &std::path::Path, model: &std::path::Path, extra: &[&str]) -> String {
    let run = fit_supershape(points, model, extra);
    assert!(
        run.success,
        "zeroset fit supershape {extra:?} failed:\n{}\n{}",
        run.stdout, run.stderr
    );
    run.stdout
}

/// The RMS of the exact distances `zeroset fit supershape` prints, mm.
fn printed_rms_mm(printed: &str) -> f64 {
    printed
        .split("exact distances of the points: RMS ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("{printed}"))
}

/// `zeroset fit supershape --superquadric` fits the 11-parameter family: it prints the rounded box's sizes and
/// exponents, and the model's exact distances to its own points are at the print's rounding; symmetry numbers
/// other than a superquadric's are refused by the recovery, naming them.
#[test]
fn a_superquadric_is_recovered_with_its_sizes_and_exponents() {
    let dir = tempfile::tempdir().unwrap();
    let points = dir.path().join("box.csv");
    superquadric_csv(&points, 2000);
    let model = dir.path().join("box.json");
    let printed = fit_supershape_ok(
        &points,
        &model,
        &["--superquadric", "--no-truncation", "--no-holes"],
    );
    let line = printed
        .lines()
        .find(|l| l.contains("superquadric: sizes"))
        .unwrap_or_else(|| panic!("{printed}"));
    let numbers: Vec<f64> = line
        .replace("epsilon1", "")
        .replace("epsilon2", "")
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter_map(|t| t.parse().ok())
        .collect();
    assert_eq!(numbers.len(), 5, "three sizes and two exponents: {line}");
    // A quarter turn about the axis swaps a1 and a2 and is the same superquadric: they are compared as a pair.
    let mut across = [numbers[0], numbers[1]];
    across.sort_by(f64::total_cmp);
    let got = [across[1], across[0], numbers[2], numbers[3], numbers[4]];
    for (got, want) in got.iter().zip([30.0, 20.0, 12.0, 0.4, 0.6]) {
        assert!((got - want).abs() < 1e-3 * want.max(1.0), "{line}");
    }
    assert!(printed.contains("symmetry 4,4"), "{printed}");
    let rms = printed_rms_mm(&printed);
    assert!(rms < 1e-3, "RMS {rms} mm for exact points: {printed}");
    let refused = fit_supershape(&points, &model, &["--superquadric", "--symmetry", "6,4"]);
    assert!(
        !refused.success
            && refused
                .stderr
                .contains("a superquadric has the symmetry numbers 4,4, not 6,4"),
        "{}",
        refused.stderr
    );
}

/// Points on the ellipsoid of `centre` and semi-axes `axes` that lie outside the other ellipsoid, labelled.
fn ellipsoid_segment(
    label: &str,
    count: usize,
    centre: [f64; 3],
    axes: [f64; 3],
    other: ([f64; 3], [f64; 3]),
) -> String {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut text = String::new();
    for i in 0..count {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f64;
        let unit = [r * phi.cos(), r * phi.sin(), z];
        let p: Vec<f64> = (0..3).map(|k| centre[k] + axes[k] * unit[k]).collect();
        let (c, a) = other;
        let inside: f64 = (0..3).map(|k| ((p[k] - c[k]) / a[k]).powi(2)).sum();
        if inside > 1.0 {
            text.push_str(&format!("{:.6},{:.6},{:.6},{label}\n", p[0], p[1], p[2]));
        }
    }
    text
}

/// A part scanned in two segments (`x,y,z,segment`: a body and a cap standing out of its top) is recovered
/// segment by segment and joined by union: the model holds every point of both within 0.05 mm, and a segment
/// too small to fit is named in the error.
#[test]
fn a_segmented_scan_is_recovered_as_the_union_of_its_segments() {
    let dir = tempfile::tempdir().unwrap();
    let body = ([0.0, 0.0, 0.0], [40.0, 30.0, 20.0]);
    let cap = ([5.0, 0.0, 22.0], [15.0, 12.0, 10.0]);
    let points = dir.path().join("segments.csv");
    std::fs::write(
        &points,
        format!(
            "x,y,z,segment\n{}{}",
            ellipsoid_segment("body", 2000, body.0, body.1, cap),
            ellipsoid_segment("cap", 1200, cap.0, cap.1, body)
        ),
    )
    .unwrap();
    let model = dir.path().join("segments.json");
    let printed = fit_supershape_ok(&points, &model, &[]);
    assert!(
        printed.contains("2 segments of")
            && printed.contains("segment 'body'")
            && printed.contains("segment 'cap'"),
        "{printed}"
    );
    let rms = printed_rms_mm(&printed);
    assert!(rms < 0.05, "RMS {rms} mm: {printed}");
    let saved: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert!(saved["method"]
        .as_str()
        .unwrap()
        .contains("2 segments joined by R_p union"));
    std::fs::write(
        &points,
        format!(
            "x,y,z,segment\n{}1,2,3,burr\n",
            ellipsoid_segment("body", 500, body.0, body.1, cap)
        ),
    )
    .unwrap();
    let refused = fit_supershape(&points, &model, &[]);
    assert!(
        !refused.success
            && refused
                .stderr
                .contains("segment 'burr': 1 points cannot fix"),
        "{}",
        refused.stderr
    );
}
