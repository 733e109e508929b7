//! Time to write every report file of one inspected part: report.json, deviations.csv, summary.txt, report.html
//! (with its plots) and report.qif, for 3 blades x 5 profiles x 2 000 points per profile, plus the history entry.
//!
//! Run: `cargo bench --bench report`.

use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use zeroset::analysis::stats::{RunningStats, Tolerance, Verdict};
use zeroset::report::{
    write_html, write_qif, write_report, InstanceReport, MachineUse, PartReport, PointRecord,
    ProfileReport, ReferenceUse, Store, STORE_FILE,
};

const POINTS: usize = 2000;
const TOLERANCE: Tolerance = Tolerance {
    lower_mm: -0.1,
    upper_mm: 0.1,
};

/// An elliptical section of blade `blade` at radius `x`, shifted by `shift` mm along z (like blades B and C).
fn profile(blade: usize, x: f64, shift: f64) -> ProfileReport {
    let turn = blade as f64 * std::f64::consts::TAU / 3.0;
    let (sin, cos) = turn.sin_cos();
    let mut stats = RunningStats::default();
    let points: Vec<PointRecord> = (0..POINTS)
        .map(|k| {
            let t = std::f64::consts::TAU * k as f64 / POINTS as f64;
            let (u, v) = (60.0 * t.cos(), 8.0 * t.sin() + shift);
            let surface = [x * cos - u * sin, x * sin + u * cos, v];
            let (nu, nv) = (8.0 * t.cos(), 60.0 * t.sin());
            let length = (nu * nu + nv * nv).sqrt();
            let normal = [-nu / length * sin, nu / length * cos, nv / length];
            let deviation_mm = shift * normal[2] + 0.002 * (7.0 * t).sin();
            stats.push(deviation_mm, surface);
            PointRecord {
                centre: [
                    surface[0] + normal[0],
                    surface[1] + normal[1],
                    surface[2] + normal[2],
                ],
                normal,
                surface,
                deviation_mm,
                off_plane_mm: 0.0,
                quality: 0.0,
                flagged: false,
                after_fit_mm: None,
            }
        })
        .collect();
    let summary = stats.summary().unwrap();
    let outside = points
        .iter()
        .filter(|p| !TOLERANCE.contains(p.deviation_mm))
        .count();
    ProfileReport {
        name: format!("r{x}"),
        x_mm: x,
        machine: "cmm1".into(),
        scanned_at: "2026-11-23T10:00:00Z".into(),
        stats: summary,
        verdict: TOLERANCE.verdict(&summary, outside),
        best_fits: Vec::new(),
        parameters: None,
        distribution: None,
        points,
    }
}

fn report() -> PartReport {
    let instances: Vec<InstanceReport> = ["A", "B", "C"]
        .iter()
        .enumerate()
        .map(|(blade, name)| {
            let shift = [0.0, -0.7, 0.7][blade];
            let profiles: Vec<ProfileReport> = (1..=5)
                .map(|k| profile(blade, 100.0 * k as f64, shift))
                .collect();
            let mut stats = RunningStats::default();
            for p in &profiles {
                for point in &p.points {
                    stats.push(point.deviation_mm, point.surface);
                }
            }
            let summary = stats.summary().unwrap();
            let outside = profiles
                .iter()
                .flat_map(|p| &p.points)
                .filter(|p| !TOLERANCE.contains(p.deviation_mm))
                .count();
            InstanceReport {
                name: name.to_string(),
                stats: summary,
                verdict: TOLERANCE.verdict(&summary, outside),
                index_deg: None,
                angular_spacing_deg: None,
                blade_pitch_mm: None,
                profiles,
            }
        })
        .collect();
    PartReport {
        format: zeroset::report::FORMAT.into(),
        version: zeroset::report::VERSION,
        units: "mm".into(),
        part: "propeller".into(),
        serial: "BENCH-1".into(),
        job: "bench".into(),
        started: "2026-11-23T10:00:00Z".into(),
        finished: "2026-11-23T10:10:00Z".into(),
        machines: vec![MachineUse {
            name: "cmm1".into(),
            ball_radius_mm: 1.0,
            profiles_scanned: 15,
        }],
        reference: ReferenceUse {
            path: "references/propeller.json".into(),
            taught_at: "2026-11-23T09:00:00Z".into(),
            model: "implicit polynomial of degree 8 per profile".to_string(),
        },
        distance: "exact".into(),
        compensation: "ball radius along the normal".into(),
        tolerance: TOLERANCE,
        rescans: Vec::new(),
        iso484: None,
        propeller_pitch_mm: None,
        verdict: Verdict::combine(instances.iter().map(|i| &i.verdict)),
        instances,
    }
}

fn write_all(dir: &Path, report: &PartReport) {
    write_html(dir, report).unwrap();
    write_qif(dir, report).unwrap();
    write_report(dir, report).unwrap();
    let mut store = Store::open(&dir.join(STORE_FILE)).unwrap();
    store.record(report, dir).unwrap();
}

fn bench(c: &mut Criterion) {
    let report = report();
    let dir = tempfile::tempdir().unwrap();
    let mut group = c.benchmark_group("report");
    group.sample_size(10);
    group.bench_function("all files, 3 blades x 5 profiles x 2000 points", |b| {
        b.iter(|| write_all(dir.path(), &report))
    });
    group.bench_function("report.html", |b| {
        b.iter(|| write_html(dir.path(), &report).unwrap())
    });
    group.bench_function("report.qif", |b| {
        b.iter(|| write_qif(dir.path(), &report).unwrap())
    });
    group.bench_function("report.json, deviations.csv, summary.txt", |b| {
        b.iter(|| write_report(dir.path(), &report).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
