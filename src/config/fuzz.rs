//! The bodies of the fuzz targets over the configuration loaders, one function per target: cargo-fuzz's
//! targets (`fuzz/fuzz_targets/`, nightly) and the stable mutation run (`tests/fuzz_targets.rs`) both call
//! these, so the two runs check the same things. Each panics on a failed check, which is how a fuzzer
//! learns of it.
//!
//! Public (hidden from the docs) because both callers are outside the crate and what they check is
//! crate-private (`from_text` parses without touching the file system, so the fuzzer can run millions of
//! texts; the checks the station relies on after loading). A cargo feature would keep them out of release
//! builds, but then the plain `cargo test` of CI could not reach them.

use std::path::{Component, Path};
use std::time::Duration;

use nalgebra::Isometry3;
use zeroset_drivers::machine::Xyz;
use zeroset_drivers::wire::Number;

use super::{ConfigError, PartConfig, StationConfig};
use crate::plan::Plan;

/// Where the fuzzed station file is said to be, for its errors to name.
const STATION_FILE: &str = "/fuzz/config/station.toml";
/// Where the fuzzed part file is said to be.
const PART_FILE: &str = "/fuzz/config/parts/part.toml";

/// A station file's text as [`StationConfig::load`] reads it. A file it accepts: writes back to TOML that
/// reads as the same configuration; gives timeouts that make `Duration`s (the machine workers build them)
/// and a rigid placement of the part; and has only absolute, plain paths once resolved. A file it refuses
/// is refused with a message that names the file.
pub fn station_config(data: &[u8]) {
    // `load` reads with `read_to_string`, which refuses a file that is not UTF-8 before parsing.
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new(STATION_FILE);
    let mut config = match StationConfig::from_text(text, path) {
        Ok(config) => config,
        Err(error) => return check_refusal(&error, path),
    };
    let written = toml::to_string(&config)
        .unwrap_or_else(|e| panic!("an accepted station does not write as TOML: {e}\n{config:?}"));
    let reread = StationConfig::from_text(&written, path).unwrap_or_else(|e| {
        panic!("an accepted station, written back, is refused: {e}\n{written}")
    });
    assert_eq!(reread, config, "written back as\n{written}");
    for machine in &config.machines {
        for seconds in [machine.ack_timeout_s, machine.reply_timeout_s] {
            assert!(
                Duration::try_from_secs_f64(seconds).is_ok(),
                "machine {}: timeout {seconds} s accepted",
                machine.name
            );
        }
    }
    assert_rigid(&config.part_to_machine.isometry());
    let folder = path.parent().expect("the file has a folder");
    config.resolve_paths(folder);
    let paths = [
        &config.folders.data,
        &config.folders.reports,
        &config.folders.logs,
        &config.control.socket,
        &config.parts,
    ];
    let ports = config.machines.iter().map(|machine| &machine.port);
    for resolved in paths.into_iter().chain(ports) {
        assert!(
            resolved.is_absolute()
                && resolved
                    .components()
                    .all(|c| !matches!(c, Component::CurDir | Component::ParentDir)),
            "{} resolves to {}",
            folder.display(),
            resolved.display()
        );
    }
}

/// A part file's text as [`PartConfig::load`] reads it. A file it accepts: writes back to TOML that reads as
/// the same part; and plans rigid placements of its instances and, for every instance's profiles, teach scans whose every coordinate is finite
/// and can be sent to a machine (the station sends them as I++ numbers). A file it refuses is refused with a
/// message that names the file.
pub fn part_config(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new(PART_FILE);
    let part = match PartConfig::from_text(text, path) {
        Ok(part) => part,
        Err(error) => return check_refusal(&error, path),
    };
    let written = toml::to_string(&part)
        .unwrap_or_else(|e| panic!("an accepted part does not write as TOML: {e}\n{part:?}"));
    let reread = PartConfig::from_text(&written, path)
        .unwrap_or_else(|e| panic!("an accepted part, written back, is refused: {e}\n{written}"));
    assert_eq!(reread, part, "written back as\n{written}");
    let plan = Plan::new(&part, Isometry3::identity());
    for key in plan.inspect_scans() {
        assert_rigid(&plan.instance_to_machine(key.instance));
        let scan = plan.in_plane_scan(key);
        // InPlaneScan's own rule: the heading is a point apart from the start.
        assert_ne!(
            scan.direction,
            scan.start,
            "{}: the teach scan has no heading",
            plan.describe(key)
        );
        let points = [
            scan.start,
            scan.start_normal,
            scan.plane_normal,
            scan.direction,
            scan.end,
            scan.end_normal,
        ];
        for value in points
            .iter()
            .flat_map(|p: &Xyz| [p.x, p.y, p.z])
            .chain([scan.spacing.max_distance(), scan.stop_diameter])
        {
            Number::from_f64(value).unwrap_or_else(|e| {
                panic!(
                    "{}: the teach scan holds {value}, which cannot be sent ({e})\n{scan:?}",
                    plan.describe(key)
                )
            });
        }
    }
}

/// A refusal names the file and says more than that.
fn check_refusal(error: &ConfigError, path: &Path) {
    let message = error.to_string();
    let named = format!("{}: ", path.display());
    assert!(
        message.starts_with(&named) && message.len() > named.len(),
        "a refusal that does not name the file or says nothing: {message:?}"
    );
}

/// A placement is a rigid motion: finite, its rotation a unit quaternion.
fn assert_rigid(isometry: &Isometry3<f64>) {
    let matrix = isometry.to_homogeneous();
    assert!(
        matrix.iter().all(|v| v.is_finite()),
        "placement {matrix} is not finite"
    );
    let norm = isometry.rotation.quaternion().norm();
    assert!(
        (norm - 1.0).abs() < 1e-9,
        "placement {matrix} is not a rotation (quaternion norm {norm})"
    );
}
