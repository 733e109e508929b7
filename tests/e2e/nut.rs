//! The station with a supershape reference, end to end: the simulator's nut (config/sims/nut.toml) taught as a
//! superformula prism from three horizontal sections, then a second nut of the batch (config/sims/nut-b.toml,
//! 0.2% smaller) inspected against it, every deviation checked against the simulator's analytic master nut.

use std::collections::BTreeMap;

use nalgebra::Point3;
use zeroset::report::PartReport;
use zeroset_sim::config::SimConfig;

use crate::daemon::Station;
use crate::support::{config, zeroset};

/// The agreement asked of the station between measured and true deviations, mm (as for the propeller).
const AGREEMENT_MM: f64 = 0.005;

/// Per profile: the true deviation of each reported surface point, its signed distance to the master nut.
fn ground_truth(report: &PartReport) -> BTreeMap<String, Vec<f64>> {
    let sim =
        SimConfig::load(config("sims/nut.toml").as_ref()).expect("the master's simulator config");
    let master = sim.parts["nut"].build().expect("the master nut");
    report.instances[0]
        .profiles
        .iter()
        .map(|profile| {
            let truth = profile
                .points
                .iter()
                .map(|p| master.nearest(&Point3::from(p.surface)).signed_distance)
                .collect();
            (profile.name.clone(), truth)
        })
        .collect()
}

fn mean_and_rms(values: &[f64]) -> (f64, f64) {
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    (mean, (values.iter().map(|v| v * v).sum::<f64>() / n).sqrt())
}

#[test]
fn a_nut_taught_as_a_supershape_measures_the_next_nut_of_the_batch() {
    let master = Station::start_as("nut.toml", "station-nut.toml");
    let out = master.cli_ok(&["teach", "nut"]);
    assert!(out.contains("reference saved"), "{out}");
    // The prism follows the master's sections to the machine's noise (2 um).
    for profile in ["h06", "h12", "h19"] {
        let line = out
            .lines()
            .find(|l| l.trim_start().starts_with(profile))
            .unwrap_or_else(|| panic!("a fit line for {profile}:\n{out}"));
        let rms: f64 = line
            .split("fit RMS ")
            .nth(1)
            .and_then(|rest| rest.split(' ').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("an RMS in {line:?}"));
        assert!(rms < 0.003, "{line}");
    }
    let reference: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(master.reference_of("nut")).expect("the reference is saved"),
    )
    .expect("JSON");
    assert_eq!(reference["model"]["model"]["kind"], "supershape");
    let size = reference["model"]["model"]["solid"]["shape"]["scale"][0]
        .as_f64()
        .expect("a size");
    assert!(
        (size - 40.08).abs() < 0.002,
        "fitted size {size} mm, made 40.08 mm"
    );

    // The inspection's moves against the taught nut: descent, contact scan, lift-off and way out per profile.
    let sweep = master.root.path().join("sweep");
    let out = master.cli_ok(&["sweep", "nut", "--out", &sweep.display().to_string()]);
    // The header states the chord tolerance to the micrometre and the stylus's ball as a radius.
    let header = out.lines().next().unwrap();
    let chord = header
        .split("chord tolerance ")
        .nth(1)
        .and_then(|t| t.split(" mm").next())
        .unwrap_or_else(|| panic!("{header}"));
    assert!(
        chord.split('.').nth(1).is_some_and(|d| d.len() == 3),
        "{header}"
    );
    assert!(header.contains("ball radius 1.5 mm"), "{header}");
    let rows: Vec<&str> = out.lines().filter(|l| l.ends_with(" ok")).collect();
    assert!(rows.len() >= 12 && !out.contains("REFUSED"), "{out}");
    assert!(
        std::fs::read_to_string(sweep.join("clearance.csv"))
            .unwrap()
            .lines()
            .count()
            > rows.len()
    );
    assert!(std::fs::read_to_string(sweep.join("silhouette.svg"))
        .unwrap()
        .contains("<polyline"));

    // The reference's model as a model file, meshed: closed, in mm.
    let model = master.root.path().join("nut-model.json");
    std::fs::write(&model, reference["model"].to_string()).expect("the model file");
    let stl = master.root.path().join("nut.stl");
    let meshed = zeroset(&[
        "mesh",
        "--model",
        &model.display().to_string(),
        "--out",
        &stl.display().to_string(),
    ]);
    assert!(
        meshed.success && meshed.stdout.contains(", closed,"),
        "{}{}",
        meshed.stdout,
        meshed.stderr
    );
    assert!(
        std::fs::metadata(&stl).unwrap().len() > 84 + 50 * 1000,
        "a binary STL of many triangles"
    );

    let batch = Station::start_as("nut-b.toml", "station-nut.toml");
    std::fs::create_dir_all(batch.data().join("references")).expect("a references folder");
    std::fs::copy(master.reference_of("nut"), batch.reference_of("nut")).expect("copied");
    let out = batch.inspected(&["inspect", "nut", "--serial", "NUT-2"]);
    assert!(out.contains("PASS"), "{out}");
    let (dir, report) = batch.report_of("nut", "NUT-2");
    assert!(
        report.distance.contains("supershape"),
        "{}",
        report.distance
    );
    assert!(dir.join("report.qif").is_file() && dir.join("report.html").is_file());
    let truth = ground_truth(&report);
    for profile in &report.instances[0].profiles {
        let measured: Vec<f64> = profile.points.iter().map(|p| p.deviation_mm).collect();
        let expected = &truth[&profile.name];
        let (mean, rms) = mean_and_rms(&measured);
        let (true_mean, true_rms) = mean_and_rms(expected);
        // 0.2% of 40 to 43.6 mm inside the master: about -0.08 mm everywhere.
        assert!(
            (-0.09..-0.075).contains(&true_mean),
            "{}: the truth says {true_mean}",
            profile.name
        );
        assert!(
            (mean - true_mean).abs() < AGREEMENT_MM && (rms - true_rms).abs() < AGREEMENT_MM,
            "{}: mean {mean:+.5} (truth {true_mean:+.5}), RMS {rms:.5} (truth {true_rms:.5}) mm",
            profile.name
        );
        let worst = measured
            .iter()
            .zip(expected)
            .map(|(m, t)| (m - t).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "{}: mean {mean:+.5} (truth {true_mean:+.5}), RMS {rms:.5} (truth {true_rms:.5}), worst point {worst:.5} mm",
            profile.name
        );
        // Point by point: the truth is taken at the very measured point, so the noise cancels; what is left
        // is the model's error and the compensation's (0.4 um here).
        assert!(
            worst < 0.002,
            "{}: a point is {worst} mm off the truth",
            profile.name
        );
    }
}
