//! Exact signed distance to a supershape CSG solid (issue 5, item 4): distances per second on one
//! core for a hex nut (a rounded hexagonal prism truncated by a box, minus a bore, posed), for points
//! within 0.2 mm of its walls as planar profile scans give them; and the one-off preparation.
//!
//!     cargo bench --bench supershape_distance

use std::f64::consts::TAU;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use zeroset::geometry::supershape::csg::{Node, Solid};
use zeroset::geometry::supershape::deform::{Deformation, Deformations};
use zeroset::geometry::supershape::distance::SolidDistance;
use zeroset::geometry::supershape::formula::Superformula;
use zeroset::geometry::supershape::rfunc::{Boolean, RFunction};
use zeroset::geometry::supershape::shape::Supershape;

fn formula(m: f64, n1: f64, n2: f64, n3: f64) -> Superformula {
    Superformula::new(m, n1, n2, n3, 1.0, 1.0).expect("valid superformula")
}

/// The nut of the module's tests: across flats about 21 mm, 12 mm thick, bore radius 5 mm.
fn hex_nut(place: &Isometry3<f64>) -> Solid {
    let prism = Supershape {
        r1: formula(6.0, 12.0, 6.0, 6.0),
        r2: formula(4.0, 20.0, 20.0, 20.0),
        scale: [12.0, 12.0, 10.0],
    };
    let bore = Supershape {
        r1: Superformula::circle(),
        r2: formula(4.0, 20.0, 20.0, 20.0),
        scale: [5.0, 5.0, 12.0],
    };
    let body = Node::boolean(
        Boolean::Intersection,
        RFunction::P(2),
        Node::supershape(prism, Deformations::default()),
        Node::cuboid([20.0, 20.0, 6.0], Deformations::default()),
    );
    let mut nut = Node::boolean(
        Boolean::Difference,
        RFunction::P(2),
        body,
        Node::supershape(bore, Deformations::default()),
    );
    nut.place = Deformations(vec![Deformation::Rigid(*place)]);
    Solid::new(nut)
}

/// Profiles at five heights, 400 points each round the outer wall and 200 round the bore, each
/// moved off the surface along its ray by a deviation within +-0.2 mm.
fn scan(solid: &Solid, place: &Isometry3<f64>) -> Vec<Point3<f64>> {
    let mut points = Vec::new();
    for z in [-5.0, -2.5, 0.0, 2.5, 5.0] {
        for (count, from, to) in [(400, 6.0, 20.0), (200, 0.0, 6.0)] {
            for i in 0..count {
                let angle = TAU * i as f64 / count as f64;
                let ray = |r: f64| place * Point3::new(r * angle.cos(), r * angle.sin(), z);
                // Bisection for the wall crossing between `from` and `to`.
                let (mut a, mut b) = (from, to);
                let inside_at_a = solid.contains(&ray(a));
                for _ in 0..60 {
                    let mid = 0.5 * (a + b);
                    if solid.contains(&ray(mid)) == inside_at_a {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                let deviation = 0.2 * ((i as f64 * 0.618_034).fract() * 2.0 - 1.0);
                points.push(ray(a + deviation));
            }
        }
    }
    points
}

fn distances(c: &mut Criterion) {
    let place = Isometry3::from_parts(
        Translation3::new(120.0, -40.0, 15.0),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.3),
    );
    let solid = hex_nut(&place);
    let distance = SolidDistance::new(&solid);
    let points = scan(&solid, &place);
    let mut group = c.benchmark_group("supershape CSG distance, hex nut");
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("exact foot, scan points within 0.2 mm", |b| {
        b.iter(|| {
            points
                .iter()
                .map(|p| distance.foot(p).map_or(0.0, |f| f.distance_mm))
                .sum::<f64>()
        })
    });
    group.finish();
    let mut group = c.benchmark_group("supershape CSG distance, preparation");
    group.sample_size(10);
    group.bench_function("SolidDistance::new (hex nut)", |b| {
        b.iter(|| SolidDistance::new(&solid))
    });
    group.finish();
}

criterion_group!(benches, distances);
criterion_main!(benches);
