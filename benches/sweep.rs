//! Swept-stylus throughput: clearance checks per second for a blade-like inspection plan (moves around a twisted
//! NACA 0012 blade mesh, checked by conservative advancement against the mesh), and the time to trace the
//! perspective silhouette of a ball swept along an arc.
//!
//!     cargo bench --bench sweep

use std::f64::consts::TAU;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{Point3, Vector2, Vector3};
use zeroset::geometry::sweep::clearance::check_plan;
use zeroset::geometry::sweep::mesh::MeshPart;
use zeroset::geometry::sweep::motion::Motion;
use zeroset::geometry::sweep::silhouette::ball_silhouette;
use zeroset::geometry::sweep::stylus::Stylus;

const CHORD: f64 = 60.0;
const SPAN: f64 = 80.0;
const TWIST_RAD: f64 = 0.17;
const SECTIONS: usize = 41;
const STATIONS_PER_SIDE: usize = 100;

/// NACA 00xx half thickness at chord fraction x (closed-trailing-edge coefficient).
fn naca_half_thickness(x: f64, thickness: f64) -> f64 {
    5.0 * thickness
        * (0.2969 * x.sqrt() - 0.1260 * x - 0.3516 * x * x + 0.2843 * x.powi(3)
            - 0.1036 * x.powi(4))
}

/// The blade section at height z: counter-clockwise points about mid-chord, turned by the twist.
fn section(z: f64) -> Vec<Vector2<f64>> {
    let angle = TWIST_RAD * z / SPAN;
    let (s, c) = angle.sin_cos();
    let mut pts = Vec::new();
    // Lower surface from the trailing edge to the leading edge, then the upper surface back (cosine spacing).
    for i in 0..STATIONS_PER_SIDE {
        let x = 0.5 * (1.0 + (TAU / 2.0 * i as f64 / STATIONS_PER_SIDE as f64).cos());
        pts.push(Vector2::new(x, -naca_half_thickness(x, 0.12)));
    }
    for i in 0..STATIONS_PER_SIDE {
        let x = 0.5 * (1.0 - (TAU / 2.0 * i as f64 / STATIONS_PER_SIDE as f64).cos());
        pts.push(Vector2::new(x, naca_half_thickness(x, 0.12)));
    }
    pts.dedup_by(|a, b| (*a - *b).norm() < 1e-12);
    // Lower surface to the left, upper to the right is clockwise: reverse for outward-facing triangles.
    pts.reverse();
    pts.into_iter()
        .map(|p| {
            let q = (p - Vector2::new(0.5, 0.0)) * CHORD;
            Vector2::new(c * q.x - s * q.y, s * q.x + c * q.y)
        })
        .collect()
}

/// The blade as a closed mesh: sections joined by quads, the ends closed by fans about the centroid.
fn blade() -> MeshPart {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    let n = section(0.0).len();
    for k in 0..SECTIONS {
        let z = SPAN * k as f64 / (SECTIONS - 1) as f64;
        vertices.extend(section(z).into_iter().map(|p| Point3::new(p.x, p.y, z)));
    }
    for k in 0..SECTIONS - 1 {
        for i in 0..n {
            let (a, b) = (k * n + i, k * n + (i + 1) % n);
            triangles.push([a, b, b + n]);
            triangles.push([a, b + n, a + n]);
        }
    }
    for (k, bottom) in [(0, true), (SECTIONS - 1, false)] {
        let centre = vertices.len();
        vertices.push(Point3::new(
            0.0,
            0.0,
            SPAN * k as f64 / (SECTIONS - 1) as f64,
        ));
        for i in 0..n {
            let (a, b) = (k * n + i, k * n + (i + 1) % n);
            triangles.push(if bottom {
                [centre, b, a]
            } else {
                [centre, a, b]
            });
        }
    }
    MeshPart::new(vertices, triangles, 0.0).expect("the blade mesh is valid")
}

/// Around the blade at several heights (the shank reaching up past the twisted sections above): an ellipse of
/// line moves, an arc around the leading edge, and
/// approach / retract moves to 3 mm from the surface along the section's normal.
fn plan(stylus: &Stylus) -> Vec<Motion> {
    let clear = stylus.ball_radius_mm + 3.0;
    let mut moves = Vec::new();
    for level in 0..10 {
        let z = 6.0 + 7.0 * level as f64;
        let ring: Vec<Point3<f64>> = (0..=16)
            .map(|i| {
                let a = TAU * i as f64 / 16.0;
                Point3::new(
                    (0.5 * CHORD + 8.0) * a.cos(),
                    (0.06 * CHORD + 12.0) * a.sin(),
                    z,
                )
            })
            .collect();
        moves.extend(ring.windows(2).map(|w| Motion::line(w[0], w[1])));
        moves.push(
            Motion::arc(
                Point3::new(-20.0, 0.0, z),
                Vector3::z(),
                Point3::new(-20.0, -16.0, z),
                -3.0,
            )
            .expect("arc off its axis"),
        );
        let pts = section(z);
        for i in (7..pts.len()).step_by(pts.len() / 8) {
            let tangent = pts[(i + 1) % pts.len()] - pts[i - 1];
            let normal = Vector2::new(tangent.y, -tangent.x).normalize();
            let near = pts[i] + normal * clear;
            let far = pts[i] + normal * (clear + 8.0);
            let (near, far) = (Point3::new(near.x, near.y, z), Point3::new(far.x, far.y, z));
            moves.push(Motion::line(far, near));
            moves.push(Motion::line(near, far));
        }
    }
    moves
}

fn clearance(c: &mut Criterion) {
    let part = blade();
    let stylus = Stylus::new(1.5, 0.75, 20.0).expect("stylus");
    let moves = plan(&stylus);
    let margin = 0.5;
    let accepted = check_plan(&stylus, &moves, &part, margin).expect("the plan keeps its margin");
    eprintln!(
        "blade: {} triangles, plan of {} moves, closest {:.3} mm (move {}), {} distance evaluations",
        part.triangle_count(),
        moves.len(),
        accepted.min_distance_mm,
        accepted.closest_move,
        accepted.moves.iter().map(|m| m.samples).sum::<usize>()
    );
    let mut group = c.benchmark_group("swept stylus");
    group.throughput(Throughput::Elements(moves.len() as u64));
    group.bench_function("check_plan around a blade (moves)", |b| {
        b.iter(|| check_plan(&stylus, &moves, &part, margin).map(|p| p.min_distance_mm))
    });
    group.finish();

    let arc = Motion::arc(
        Point3::origin(),
        Vector3::z(),
        Point3::new(30.0, 0.0, 0.0),
        1.2,
    )
    .expect("arc");
    let eye = Point3::new(60.0, -80.0, 50.0);
    let components = ball_silhouette(&arc, 2.0, eye, 0.1).expect("silhouette");
    eprintln!(
        "silhouette: {} component(s), {} points",
        components.len(),
        components
            .iter()
            .flat_map(|c| &c.pieces)
            .map(|p| p.points.len())
            .sum::<usize>()
    );
    let mut group = c.benchmark_group("swept ball silhouette");
    group.bench_function("arc, step 0.1 mm", |b| {
        b.iter(|| ball_silhouette(&arc, 2.0, eye, 0.1).map(|c| c.len()))
    });
    group.finish();
}

criterion_group!(benches, clearance);
criterion_main!(benches);
