//! Running the real binary and reading what it wrote.

use std::path::{Path, PathBuf};
use std::process::Command;

use nalgebra::Vector2;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use zeroset_sim::naca::Naca4;

pub fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn config(relative: &str) -> String {
    repo().join("config").join(relative).display().to_string()
}

/// config/parts/propeller.toml written into `dir` as changed by `edit` (the whole part table), for a station
/// whose `parts` folder is `dir`.
pub fn propeller_part_edited(dir: &Path, edit: impl FnOnce(&mut toml::Table)) {
    let text = std::fs::read_to_string(repo().join("config/parts/propeller.toml")).unwrap();
    let mut table: toml::Table = toml::from_str(&text).unwrap();
    edit(&mut table);
    std::fs::write(dir.join("propeller.toml"), toml::to_string(&table).unwrap()).unwrap();
}

/// What a run of the binary printed, and how it exited.
pub struct Run {
    pub success: bool,
    /// The exit code (`None` when killed by a signal).
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

pub fn zeroset(args: &[&str]) -> Run {
    let output = Command::new(env!("CARGO_BIN_EXE_zeroset"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("the zeroset binary runs");
    Run {
        success: output.status.success(),
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// Runs `zeroset ARGS` with its standard output already closed, as `| head` leaves it once it has its lines (closed
/// before the start, so that a quick command cannot write all it has into the pipe's buffer first).
pub fn zeroset_with_stdout_closed(args: &[&str]) -> Run {
    let (reader, writer) = std::io::pipe().expect("a pipe");
    drop(reader);
    let output = Command::new(env!("CARGO_BIN_EXE_zeroset"))
        .args(args)
        .current_dir(repo())
        .stdout(writer)
        .output()
        .expect("the zeroset binary runs");
    Run {
        success: output.status.success(),
        code: output.status.code(),
        stdout: String::new(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// Runs and insists on success, showing what it printed otherwise.
pub fn zeroset_ok(args: &[&str]) -> String {
    let run = zeroset(args);
    assert!(
        run.success,
        "zeroset {args:?} failed:\n{}\n{}",
        run.stdout, run.stderr
    );
    run.stdout
}

/// The deviation_mm column of a deviations file (None where a point has no deviation), with the header checked.
pub fn deviations(path: &Path) -> Vec<Option<f64>> {
    let text = std::fs::read_to_string(path).expect("deviations file");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let column = header
        .iter()
        .position(|c| *c == "deviation_mm")
        .expect("a deviation_mm column");
    lines
        .map(|l| {
            let field = l.split(',').nth(column).expect("field");
            (!field.is_empty()).then(|| field.parse().expect("a number"))
        })
        .collect()
}

pub fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

/// Runs `zeroset deviate` with the exact distance unless `distance` names another, and returns the deviation_mm
/// column it wrote (None where a point has no deviation) with what it printed.
pub fn deviate(
    model: &Path,
    points: &str,
    distance: Option<&str>,
    out: &Path,
) -> (Vec<Option<f64>>, String) {
    let mut args = vec![
        "deviate",
        "--model",
        model.to_str().unwrap(),
        "--points",
        points,
        "--out",
        out.to_str().unwrap(),
    ];
    if let Some(method) = distance {
        args.extend(["--distance", method]);
    }
    let printed = zeroset_ok(&args);
    (deviations(out), printed)
}

/// Runs `zeroset fit ip` with the extra arguments and returns what it printed and the model file it wrote.
pub fn fit_ip(points: &str, extra: &[&str], out: &Path) -> (String, serde_json::Value) {
    let mut args = vec![
        "fit",
        "ip",
        "--points",
        points,
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let printed = zeroset_ok(&args);
    let saved =
        serde_json::from_str(&std::fs::read_to_string(out).expect("the model file")).expect("JSON");
    (printed, saved)
}

/// Points of a NACA section with a sharp trailing edge written as a y,z file: `count` round it, each moved along
/// its normal by `offset` mm and by seeded Gaussian noise of `sigma` mm.
pub fn naca_csv(path: &Path, foil: &Naca4, count: usize, offset: f64, sigma: f64, seed: u64) {
    let points: Vec<Vector2<f64>> = foil.points(count).into_iter().map(Vector2::from).collect();
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let noise = Normal::new(0.0, sigma.max(f64::MIN_POSITIVE)).unwrap();
    let n = points.len();
    let mut text = String::from("y,z\n");
    for i in 0..n {
        let tangent = points[(i + 1) % n] - points[(i + n - 1) % n];
        let normal = Vector2::new(tangent.y, -tangent.x).normalize();
        let p = points[i] + normal * (offset + noise.sample(&mut rng));
        text.push_str(&format!("{:.7},{:.7}\n", p.x, p.y));
    }
    std::fs::write(path, text).unwrap();
}
