//! `zeroset evaluate`: a section moved rigidly off its nominal reads back as that motion, and its form as the
//! noise left once the motion is removed; the minimum zone is never wider than least squares'.

use std::path::{Path, PathBuf};

use zeroset_sim::naca::Naca4;

use crate::support::{config, fit_ip, naca_csv, zeroset, zeroset_ok};

/// The numbers of `line` after `marker`, up to `count`.
pub(crate) fn numbers_after(printed: &str, marker: &str, count: usize) -> Vec<f64> {
    let line = printed
        .lines()
        .find(|l| l.contains(marker))
        .unwrap_or_else(|| panic!("no '{marker}' in:\n{printed}"));
    let rest = &line[line.find(marker).unwrap() + marker.len()..];
    rest.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+'))
        .filter_map(|s| s.parse::<f64>().ok())
        .take(count)
        .collect()
}

/// What `zeroset evaluate --model MODEL --points POINTS` with the `extra` arguments printed.
fn evaluate(model: &Path, points: &Path, extra: &[&str]) -> String {
    let mut args = vec![
        "evaluate",
        "--model",
        model.to_str().unwrap(),
        "--points",
        points.to_str().unwrap(),
    ];
    args.extend(extra);
    zeroset_ok(&args)
}

/// The master blade's profile 3 fitted into `dir`/a.json, and its own points 0.4 mm lower and 0.05 mm to +y (what
/// a blade shifted on the hub would measure) in `dir`/moved.csv: the model, the moved section, the master's text.
fn master_and_moved(dir: &Path) -> (PathBuf, PathBuf, String) {
    let model = dir.join("a.json");
    let blade = config("profiles/seed003-profile3-blade-a.csv");
    fit_ip(&blade, &[], &model);
    let text = std::fs::read_to_string(&blade).unwrap();
    let mut moved = String::from("y,z\n");
    for line in text.lines().skip(1) {
        let (y, z) = line.split_once(',').unwrap();
        let (y, z): (f64, f64) = (y.parse().unwrap(), z.parse().unwrap());
        moved.push_str(&format!("{},{}\n", y + 0.05, z - 0.4));
    }
    let section = dir.join("moved.csv");
    std::fs::write(&section, moved).unwrap();
    (model, section, text)
}

#[test]
fn a_section_moved_off_its_nominal_reads_back_as_the_motion_and_its_noise() {
    let dir = tempfile::tempdir().unwrap();
    let (model, section, text) = master_and_moved(dir.path());
    let mut zones = Vec::new();
    for method in ["l2", "minzone"] {
        let out = dir.path().join(format!("{method}.csv"));
        let printed = evaluate(
            &model,
            &section,
            &["--method", method, "--out", out.to_str().unwrap()],
        );
        let chord = numbers_after(&printed, "chord direction (y, z)", 2);
        let shift = numbers_after(&printed, "the section lies", 2);
        let (dn, dchord) = (shift[0], shift[1]);
        let (along, across) = ((chord[0], chord[1]), (-chord[1], chord[0]));
        let dy = dchord * along.0 + dn * across.0;
        let dz = dchord * along.1 + dn * across.1;
        // The model follows the master within its 2 um noise: the motion is read within 3 um.
        assert!(
            (dy - 0.05).abs() < 0.003 && (dz + 0.4).abs() < 0.003,
            "{method}: read ({dy}, {dz}) mm:\n{printed}"
        );
        let turned = numbers_after(&printed, "nominal, turned", 1)[0];
        assert!(turned.abs() < 0.003, "{method}: {turned} deg\n{printed}");
        let before = numbers_after(&printed, "as measured:", 4);
        let after = numbers_after(&printed, "after the fit:", 4);
        assert!(before[3] > 0.7, "as measured the 0.4 mm shows: {printed}");
        assert!(after[2] < 0.003 && after[3] < 0.02, "{method}: {printed}");
        zones.push(after[3]);
        let written = std::fs::read_to_string(&out).unwrap();
        assert_eq!(written.lines().count(), 401);
        assert!(written.starts_with("y,z,deviation_mm,after_fit_mm\n"));
    }
    // The section's parameters: a rigid motion leaves them as they are; the master scaled by 1.01 about a point
    // reads 1 % longer and thicker. The scan's 400 points miss the ends' tips by some 20 um of chord.
    let scaled = dir.path().join("scaled.csv");
    let mut text_scaled = String::from("y,z\n");
    for line in text.lines().skip(1) {
        let (y, z) = line.split_once(',').unwrap();
        let (y, z): (f64, f64) = (y.parse().unwrap(), z.parse().unwrap());
        text_scaled.push_str(&format!(
            "{},{}\n",
            100.0 + (y - 100.0) * 1.01,
            200.0 + (z - 200.0) * 1.01
        ));
    }
    std::fs::write(&scaled, text_scaled).unwrap();
    // And turned by 0.1 deg (counter-clockwise in y, z) about a point: its chord angle reads 0.1 deg more.
    let turned = dir.path().join("turned.csv");
    let mut text_turned = String::from("y,z\n");
    let (sin, cos) = 0.1f64.to_radians().sin_cos();
    for line in text.lines().skip(1) {
        let (y, z) = line.split_once(',').unwrap();
        let (y, z): (f64, f64) = (
            y.parse::<f64>().unwrap() - 100.0,
            z.parse::<f64>().unwrap() - 200.0,
        );
        text_turned.push_str(&format!(
            "{},{}\n",
            100.0 + y * cos - z * sin,
            200.0 + y * sin + z * cos
        ));
    }
    std::fs::write(&turned, text_turned).unwrap();
    for (points, scale, turn) in [
        (&section, 1.0, 0.0),
        (&scaled, 1.01, 0.0),
        (&turned, 1.0, 0.1),
    ] {
        let printed = evaluate(&model, points, &[]);
        let chord = numbers_after(&printed, "chord (mm)", 3);
        let thickness = numbers_after(&printed, "max thickness, inscribed (mm)", 3);
        assert!(
            (chord[0] - scale * chord[1]).abs() < 0.03,
            "chord {chord:?} at scale {scale}:\n{printed}"
        );
        assert!(
            (thickness[0] - scale * thickness[1]).abs() < 0.01,
            "thickness {thickness:?} at scale {scale}:\n{printed}"
        );
        assert!((chord[2] - (chord[0] - chord[1])).abs() < 1e-3);
        // Camber and chord angle from the mean line: the camber scales with the section, the angle turns with it
        // (the nominal is the model fitted to the master's noisy points, within microns of it).
        let camber = numbers_after(&printed, "max camber, mean line (mm)", 3);
        assert!(
            (camber[0] - scale * camber[1]).abs() < 0.01,
            "camber {camber:?} at scale {scale}:\n{printed}"
        );
        let angle = numbers_after(&printed, "chord angle to +y (deg)", 3);
        assert!(
            (angle[2] - turn).abs() < 0.005,
            "chord angle {angle:?} turned {turn} deg:\n{printed}"
        );
    }
    assert!(
        zones[1] <= zones[0] + 1e-4,
        "minimum zone {} mm, L2 {} mm",
        zones[1],
        zones[0]
    );
}

#[test]
fn a_fit_held_within_a_limit_stops_there_says_so_and_keeps_the_rest_in_the_form() {
    let dir = tempfile::tempdir().unwrap();
    let (model, section, _) = master_and_moved(dir.path());
    for method in ["l2", "minzone"] {
        let printed = evaluate(
            &model,
            &section,
            &[
                "--method",
                method,
                "--max-dn-mm",
                "0.25",
                "--max-rotation-deg",
                "0.5",
            ],
        );
        // Where the motion puts the section along its thickness direction (the chord turned +90 deg): farther off
        // than 0.25 mm, so the fit is held there.
        let chord = numbers_after(&printed, "chord direction (y, z)", 2);
        let made = 0.05 * -chord[1] + -0.4 * chord[0];
        assert!(made.abs() > 0.3, "{made}");
        let dn = numbers_after(&printed, "the section lies", 1)[0];
        assert!(
            (dn - 0.25 * made.signum()).abs() < 1e-4, // printed to 0.1 um
            "{method}: {dn}\n{printed}"
        );
        assert!(
            printed.contains("limit along the thickness +-0.25 mm: reached")
                && printed.contains("limit turned +-0.5 deg: not reached"),
            "{method}:\n{printed}"
        );
        // What the fit could not take stays in the form, on both faces: a band about twice as wide.
        let after = numbers_after(&printed, "after the fit:", 4);
        let rest = made.abs() - 0.25;
        assert!(
            after[3] > 1.5 * rest,
            "{method}: zone {} mm for {rest} mm left\n{printed}",
            after[3]
        );
    }
    let refused = zeroset(&[
        "evaluate",
        "--model",
        model.to_str().unwrap(),
        "--points",
        section.to_str().unwrap(),
        "--fit",
        "translation",
        "--max-rotation-deg",
        "0.1",
    ]);
    assert!(
        !refused.success
            && refused.stderr.contains("max_rotation_deg")
            && refused.stderr.contains("--max-rotation-deg"),
        "{}",
        refused.stderr
    );
}

#[test]
fn a_section_with_a_sharp_edge_is_evaluated_against_its_faces() {
    // The nominal: a NACA 6412 of 250 mm chord scanned with 2 um of noise and fitted face by face. The measured
    // section: another scan of it (another noise draw), 0.3 mm up and 0.05 mm along y, turned 0.05 deg about
    // the chord's middle.
    let dir = tempfile::tempdir().unwrap();
    let foil = Naca4::from_digits("6412", 250.0, true).unwrap();
    let master = dir.path().join("master.csv");
    naca_csv(&master, &foil, 400, 0.0, 0.002, 61);
    let model = dir.path().join("faces.json");
    let (_, saved) = fit_ip(master.to_str().unwrap(), &[], &model);
    assert_eq!(saved["model"]["kind"], "ip-faces");
    let scan = dir.path().join("scan.csv");
    naca_csv(&scan, &foil, 400, 0.0, 0.002, 62);
    let (sin, cos) = 0.05f64.to_radians().sin_cos();
    let text = std::fs::read_to_string(&scan).unwrap();
    let mut moved = String::from("y,z\n");
    for line in text.lines().skip(1) {
        let (y, z) = line.split_once(',').unwrap();
        let (y, z) = (y.parse::<f64>().unwrap() - 125.0, z.parse::<f64>().unwrap());
        moved.push_str(&format!(
            "{},{}\n",
            125.0 + y * cos - z * sin + 0.05,
            y * sin + z * cos + 0.3
        ));
    }
    let section = dir.path().join("moved.csv");
    std::fs::write(&section, moved).unwrap();
    let printed = evaluate(&model, &section, &[]);
    let shift = numbers_after(&printed, "the section lies", 2);
    let chord = numbers_after(&printed, "chord direction (y, z)", 2);
    let (dn, dchord) = (shift[0], shift[1]);
    let dy = dchord * chord[0] - dn * chord[1];
    let dz = dchord * chord[1] + dn * chord[0];
    // The pivot is the measured chord's middle, turned with the section: its own shift is the motion's there.
    let pivot = numbers_after(&printed, "about the chord's middle", 2);
    let (py, pz) = (pivot[0] - 125.0 - 0.05, pivot[1] - 0.3);
    let (ey, ez) = (py - (py * cos + pz * sin), pz - (-py * sin + pz * cos));
    assert!(
        (dy - 0.05 - ey).abs() < 0.003 && (dz - 0.3 - ez).abs() < 0.003,
        "read ({dy}, {dz}) mm:\n{printed}"
    );
    let turned = numbers_after(&printed, "nominal, turned", 1)[0];
    assert!((turned - 0.05).abs() < 0.003, "{turned} deg\n{printed}");
    let after = numbers_after(&printed, "after the fit:", 4);
    assert!(after[2] < 0.003 && after[3] < 0.02, "{printed}");
    // The parameters against the faces' nominal: the chord (from the sharp edge to the nose's farthest point, on
    // a cambered section a little off the nose's own x = 0) within 5 um of the true section's.
    let true_chord = foil
        .points(200_000)
        .iter()
        .map(|p| (p[0] - 250.0).hypot(p[1]))
        .fold(0.0, f64::max);
    let chord_mm = numbers_after(&printed, "chord (mm)", 3);
    assert!(
        (chord_mm[1] - true_chord).abs() < 0.005,
        "{chord_mm:?}, the true {true_chord}\n{printed}"
    );
    assert!(chord_mm[2].abs() < 0.005, "{chord_mm:?}\n{printed}");
}
