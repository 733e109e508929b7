use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use super::super::csg::{Node, Solid};
use super::super::deform::{Deformation, Deformations};
use super::super::formula::Superformula;
use super::super::rfunc::{Boolean, RFunction};
use super::super::shape::Supershape;
use super::{Foot, FootKind, SolidDistance};

fn pose() -> Deformation {
    Deformation::Rigid(Isometry3::from_parts(
        Translation3::new(3.0, -7.0, 11.0),
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.7)
            * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.4),
    ))
}

fn sphere(radius: f64, place: Vec<Deformation>) -> Node {
    Node::supershape(
        Supershape {
            scale: [radius; 3],
            ..Supershape::sphere()
        },
        Deformations(place),
    )
}

fn formula(m: f64, n1: f64, n2: f64, n3: f64) -> Superformula {
    Superformula::new(m, n1, n2, n3, 1.0, 1.0).unwrap()
}

/// Unit directions spread over the sphere, none on a coordinate axis.
fn directions(count: usize) -> impl Iterator<Item = Vector3<f64>> {
    (0..count).map(move |i| {
        // A Fibonacci lattice, shifted off the poles.
        let z = 1.0 - (2.0 * i as f64 + 1.0) / count as f64;
        let angle = i as f64 * 2.399_963_229_728_653 + 0.1;
        let r = (1.0 - z * z).sqrt();
        Vector3::new(r * angle.cos(), r * angle.sin(), z)
    })
}

/// The checks every foot must pass: on the surface (the tree's function vanishes there) and, on a
/// face, p - foot along the outward normal with the distance's sign.
fn check_foot(solid: &Solid, p: &Point3<f64>, foot: &Foot) {
    let value = solid.value(&foot.point);
    assert!(value.abs() < 1e-9, "value {value} at foot {foot:?}");
    assert!((foot.normal.norm() - 1.0).abs() < 1e-12);
    let offset = p - foot.point;
    assert!((offset.norm() - foot.distance_mm.abs()).abs() < 1e-12);
    if foot.kind == FootKind::Face && offset.norm() > 1e-9 {
        let along = offset.dot(&foot.normal);
        assert!(
            (along - foot.distance_mm).abs() < 1e-9 * (1.0 + along.abs()),
            "p - foot {offset} is not the signed distance {} along the normal {}",
            foot.distance_mm,
            foot.normal
        );
    }
}

#[test]
fn a_sphere_reads_its_norm_minus_radius() {
    let radius = 7.5;
    let centre = Point3::new(3.0, -7.0, 11.0);
    let solid = Solid::new(sphere(radius, vec![pose()]));
    let distance = SolidDistance::new(&solid);
    let mut count = 0;
    for (k, direction) in directions(40).enumerate() {
        let offset = [0.001, -0.001, 0.05, -0.05, 1.0, -3.0, 10.0, -7.0][k % 8];
        let p = centre + direction * (radius + offset);
        let foot = distance.foot(&p).expect("a foot");
        assert!(
            (foot.distance_mm - offset).abs() < 1e-9,
            "{p}: {} for {offset}",
            foot.distance_mm
        );
        assert!((foot.point - (centre + direction * radius)).norm() < 1e-9);
        check_foot(&solid, &p, &foot);
        count += 1;
    }
    assert_eq!(count, 40);
}

/// A dense parametric sampling of one supershape in the model frame, refined locally: the nearest
/// point by brute force, independent of the Newton solver.
struct BruteForce {
    shape: Supershape,
    place: Deformations,
    /// (theta, phi, point) on a 720 x 361 grid.
    cloud: Vec<(f64, f64, Point3<f64>)>,
}

impl BruteForce {
    fn new(shape: Supershape, place: Deformations) -> Self {
        let (columns, rows) = (720, 360);
        let mut cloud = Vec::new();
        for i in 0..columns {
            for j in 0..=rows {
                let theta = -PI + TAU * i as f64 / columns as f64;
                let phi = -FRAC_PI_2 + PI * j as f64 / rows as f64;
                cloud.push((theta, phi, place.apply(&shape.point(theta, phi))));
            }
        }
        Self {
            shape,
            place,
            cloud,
        }
    }

    fn distance(&self, p: &Point3<f64>) -> f64 {
        let mut nearest: Vec<(f64, f64, f64)> = self
            .cloud
            .iter()
            .map(|(theta, phi, x)| ((x - p).norm(), *theta, *phi))
            .collect();
        nearest.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Zoom into the five nearest samples: each level a 21 x 21 grid over +-2 steps, the step
        // divided by 5, down to 1e-8 rad.
        nearest
            .iter()
            .take(5)
            .map(|&start| {
                let (mut best, mut step) = (start, (TAU / 720.0, PI / 360.0));
                for _ in 0..9 {
                    let centre = best;
                    for i in -10..=10 {
                        for j in -10..=10 {
                            let theta = centre.1 + i as f64 * step.0 / 5.0;
                            let phi =
                                (centre.2 + j as f64 * step.1 / 5.0).clamp(-FRAC_PI_2, FRAC_PI_2);
                            let d = (self.place.apply(&self.shape.point(theta, phi)) - p).norm();
                            if d < best.0 {
                                best = (d, theta, phi);
                            }
                        }
                    }
                    step = (step.0 / 5.0, step.1 / 5.0);
                }
                best.0
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The outward unit normal at (theta, phi), from central differences of the parametric form.
    fn normal(&self, theta: f64, phi: f64) -> Vector3<f64> {
        let at = |t: f64, f: f64| self.place.apply(&self.shape.point(t, f));
        let h = 1e-5;
        let d_theta = at(theta + h, phi) - at(theta - h, phi);
        let d_phi = at(theta, phi + h) - at(theta, phi - h);
        d_theta.cross(&d_phi).normalize()
    }
}

fn compare_with_brute_force(shape: Supershape, place: Vec<Deformation>, offsets: &[f64]) {
    let place = Deformations(place);
    let solid = Solid::new(Node::supershape(shape, place.clone()));
    let distance = SolidDistance::new(&solid);
    let brute = BruteForce::new(shape, place);
    let mut k = 0;
    for i in 0..6 {
        for j in 0..3 {
            let (theta, phi) = (-2.9 + 1.07 * i as f64, -1.1 + 1.03 * j as f64);
            let surface = brute.place.apply(&shape.point(theta, phi));
            let offset = offsets[k % offsets.len()];
            k += 1;
            let p = surface + brute.normal(theta, phi) * offset;
            let foot = distance.foot(&p).expect("a foot");
            let expected = brute.distance(&p) * if solid.contains(&p) { -1.0 } else { 1.0 };
            assert!(
                (foot.distance_mm - expected).abs() < 1e-6,
                "({theta}, {phi}) offset {offset}: {} vs brute force {expected}",
                foot.distance_mm
            );
            assert!(offset.abs() > 1.0 || (expected - offset).abs() < 1e-6);
            check_foot(&solid, &p, &foot);
        }
    }
}

#[test]
fn an_ellipsoid_matches_brute_force() {
    let ellipsoid = Supershape {
        scale: [6.0, 10.0, 16.0],
        ..Supershape::sphere()
    };
    compare_with_brute_force(
        ellipsoid,
        vec![pose()],
        &[0.001, -0.001, 0.2, -0.5, 3.0, -2.0, 10.0],
    );
}

#[test]
fn a_posed_twisted_supershape_matches_brute_force() {
    // Five rounded lobes with concave flanks, twisted about its axis and posed.
    let lobes = Supershape {
        r1: formula(5.0, 4.0, 7.0, 7.0),
        r2: formula(4.0, 3.0, 3.0, 3.0),
        scale: [12.0, 12.0, 8.0],
    };
    compare_with_brute_force(
        lobes,
        vec![Deformation::Twist { rate: 0.03 }, pose()],
        &[0.001, -0.001, 0.05, -0.3, 2.0, -1.0, 10.0],
    );
}

/// A sphere of radius 10 cut by the slab |z| <= 5, posed: flat faces on |z| = 5 and sharp circular
/// edges of radius sqrt(75) where they meet the sphere.
fn truncated_sphere() -> (Solid, Deformation) {
    let mut cut = Node::boolean(
        Boolean::Intersection,
        RFunction::P(2),
        sphere(10.0, vec![]),
        Node::cuboid([20.0, 20.0, 5.0], Deformations::default()),
    );
    cut.place = Deformations(vec![pose()]);
    (Solid::new(cut), pose())
}

#[test]
fn a_box_truncation_has_flat_faces_and_sharp_edges() {
    let (solid, pose) = truncated_sphere();
    let distance = SolidDistance::new(&solid);
    let edge_radius = 75f64.sqrt();
    let local = |rho: f64, angle: f64, z: f64| {
        pose.apply(&Point3::new(rho * angle.cos(), rho * angle.sin(), z))
    };
    for (k, angle) in [0.3, 1.9, 4.0].into_iter().enumerate() {
        // Near the flat face: the distance is z - 5.
        for d in [0.001, -0.001, 0.4, -0.4, 2.0] {
            let p = local(2.0 + k as f64, angle, 5.0 + d);
            let foot = distance.foot(&p).unwrap();
            assert!((foot.distance_mm - d).abs() < 1e-9, "{d}: {foot:?}");
            assert_eq!(foot.kind, FootKind::Face);
            check_foot(&solid, &p, &foot);
        }
        // Outside, in the edge's normal cone (between the face normal (0, 1) and the sphere's
        // (sqrt 75, 5) / 10 in the (rho, z) half-plane): the distance to the circle.
        for (t, direction) in [(0.001, 0.6), (0.3, 0.9), (2.0, 1.3)] {
            let (rho, z) = (
                edge_radius + t * f64::cos(direction),
                5.0 + t * f64::sin(direction),
            );
            let p = local(rho, angle, z);
            let foot = distance.foot(&p).unwrap();
            assert!((foot.distance_mm - t).abs() < 1e-9, "{t}: {foot:?}");
            assert_eq!(foot.kind, FootKind::Edge);
            assert!((foot.point - local(edge_radius, angle, 5.0)).norm() < 1e-9);
            check_foot(&solid, &p, &foot);
            // The normal lies in the cone spanned by the two faces' normals.
            let rotation = match pose {
                Deformation::Rigid(iso) => iso.rotation,
                _ => unreachable!(),
            };
            let face = rotation * Vector3::z();
            let ball = rotation
                * Vector3::new(
                    edge_radius * angle.cos() / 10.0,
                    edge_radius * angle.sin() / 10.0,
                    0.5,
                );
            let (a, b) = cone_weights(&foot.normal, &face, &ball);
            assert!(a > 0.0 && b > 0.0, "{a} {b}");
        }
        // Inside near the edge: the nearer of the face and the sphere.
        for (rho, z) in [(8.5, 4.9), (8.6, 4.6), (8.0, 4.99)] {
            let p = local(rho, angle, z);
            let expected = -(5.0 - z).min(10.0 - rho.hypot(z));
            let foot = distance.foot(&p).unwrap();
            assert!((foot.distance_mm - expected).abs() < 1e-9, "{foot:?}");
            check_foot(&solid, &p, &foot);
        }
    }
}

/// Weights (a, b) with a n1 + b n2 = v, which must hold exactly for v in the span.
fn cone_weights(v: &Vector3<f64>, n1: &Vector3<f64>, n2: &Vector3<f64>) -> (f64, f64) {
    let m = nalgebra::Matrix3x2::from_columns(&[*n1, *n2]);
    let weights = (m.transpose() * m).try_inverse().unwrap() * m.transpose() * v;
    assert!((m * weights - v).norm() < 1e-9, "{v} not in the span");
    (weights[0], weights[1])
}

#[test]
fn a_bore_reads_the_distance_to_its_wall_positive() {
    // A plate |z| <= 5 minus a ball of radius 8: a spherical bore through the plate, meeting its
    // faces in circles of radius sqrt(39).
    let mut plate = Node::boolean(
        Boolean::Difference,
        RFunction::P(2),
        Node::cuboid([20.0, 20.0, 5.0], Deformations::default()),
        sphere(8.0, vec![]),
    );
    plate.place = Deformations(vec![pose()]);
    let solid = Solid::new(plate);
    let distance = SolidDistance::new(&solid);
    let rim = 39f64.sqrt();
    for angle in [0.2f64, 2.5, 4.4] {
        let local =
            |rho: f64, z: f64| pose().apply(&Point3::new(rho * angle.cos(), rho * angle.sin(), z));
        // In the bore near its wall: the distance to the wall, positive (no material there).
        for (rho, z) in [(7.9, 0.0), (7.999, 1.0), (6.0, 4.5), (3.0, 0.0)] {
            let p = local(rho, z);
            let foot = distance.foot(&p).unwrap();
            let expected = 8.0 - rho.hypot(z);
            assert!((foot.distance_mm - expected).abs() < 1e-9, "{foot:?}");
            assert_eq!(foot.kind, FootKind::Face);
            check_foot(&solid, &p, &foot);
            // The outward normal of the material points into the bore, towards its centre.
            let inwards = (local(0.0, 0.0) - foot.point).normalize();
            assert!((foot.normal - inwards).norm() < 1e-9);
        }
        // In the material next to the wall: negative.
        let p = local(8.3, 0.5);
        let foot = distance.foot(&p).unwrap();
        assert!((foot.distance_mm + (8.3f64.hypot(0.5) - 8.0)).abs() < 1e-9);
        // Above the plate over the bore's mouth, the nearest point is the rim.
        for (rho, z) in [(6.0, 5.3), (6.2, 5.01)] {
            let p = local(rho, z);
            let foot = distance.foot(&p).unwrap();
            let expected = (rho - rim).hypot(z - 5.0);
            assert!((foot.distance_mm - expected).abs() < 1e-9, "{foot:?}");
            assert_eq!(foot.kind, FootKind::Edge);
            check_foot(&solid, &p, &foot);
        }
    }
}

#[test]
fn inside_a_union_the_crease_is_nearer_than_the_hidden_spheres() {
    // Two balls of radius 5 centred at x = -3 and 3: their surfaces meet on the circle x = 0,
    // radius 4, a concave crease seen from inside.
    let union = Node::boolean(
        Boolean::Union,
        RFunction::Alpha(0.5),
        sphere(
            5.0,
            vec![Deformation::Rigid(Isometry3::translation(-3.0, 0.0, 0.0))],
        ),
        sphere(
            5.0,
            vec![Deformation::Rigid(Isometry3::translation(3.0, 0.0, 0.0))],
        ),
    );
    let solid = Solid::new(union);
    let distance = SolidDistance::new(&solid);
    let centres = [Point3::new(-3.0, 0.0, 0.0), Point3::new(3.0, 0.0, 0.0)];
    for angle in [0.5, 2.0, 3.7] {
        for x in [0.0, 0.15, -0.4] {
            for t in [0.001, 0.1, 0.5] {
                let rho = 4.0 - t;
                let p = Point3::new(x, rho * f64::cos(angle), rho * f64::sin(angle));
                // Candidates: each sphere's nearest point where the other ball does not hide it,
                // and the crease circle.
                let mut expected = x.hypot(rho - 4.0);
                for (k, centre) in centres.iter().enumerate() {
                    let foot = centre + (p - centre).normalize() * 5.0;
                    if (foot - centres[1 - k]).norm() >= 5.0 {
                        expected = expected.min(5.0 - (p - centre).norm());
                    }
                }
                let foot = distance.foot(&p).unwrap();
                assert!(
                    (foot.distance_mm + expected).abs() < 1e-9,
                    "{p}: {} vs {}",
                    foot.distance_mm,
                    -expected
                );
                if x == 0.0 {
                    assert_eq!(foot.kind, FootKind::Edge);
                    // Below the crease, every sphere's own nearest point is hidden in the other.
                    assert!(expected < 5.0 - (p - centres[0]).norm() + 1.0);
                }
                check_foot(&solid, &p, &foot);
            }
        }
    }
}

/// A hexagonal prism with rounded corners cut by the slab |z| <= 6, minus a cylindrical bore of
/// radius 5, posed.
fn hex_nut() -> (Solid, Supershape, Supershape, Deformations) {
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
    let place = Deformations(vec![pose()]);
    nut.place = place.clone();
    (Solid::new(nut), prism, bore, place)
}

#[test]
fn a_hex_nut_reads_offsets_along_the_wall_normals() {
    let (solid, prism, bore, place) = hex_nut();
    let distance = SolidDistance::new(&solid);
    let mut checked = 0;
    // Wall points at latitudes up to 0.4 rad stay below |z| = 4.7, over 1 mm from the faces.
    for (shape, material_inside) in [(prism, true), (bore, false)] {
        let wall = BruteForce {
            shape,
            place: place.clone(),
            cloud: Vec::new(),
        };
        for i in 0..24 {
            for phi in [-0.4, -0.1, 0.25] {
                let theta = -PI + TAU * (i as f64 + 0.3) / 24.0;
                let x = place.apply(&shape.point(theta, phi));
                // The parametric normal points out of the primitive; out of the material it is
                // reversed on the bore.
                let outward = wall.normal(theta, phi) * if material_inside { 1.0 } else { -1.0 };
                for offset in [0.05, -0.05] {
                    let p = x + outward * offset;
                    let foot = distance.foot(&p).unwrap();
                    assert!(
                        (foot.distance_mm - offset).abs() < 1e-6,
                        "{theta} {phi} {offset}: {foot:?}"
                    );
                    assert!((foot.point - x).norm() < 1e-6);
                    check_foot(&solid, &p, &foot);
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 2 * 24 * 3 * 2);
}

#[test]
fn a_section_reads_the_distance_within_its_plane() {
    // A ball of radius 7.5 centred at (3, -7, 11), cut by the plane z = 13: a circle of radius
    // sqrt(7.5^2 - 2^2) about (3, -7).
    let centre = Point3::new(3.0, -7.0, 11.0);
    let solid = Solid::new(sphere(
        7.5,
        vec![Deformation::Rigid(Isometry3::translation(3.0, -7.0, 11.0))],
    ));
    let distance = SolidDistance::new(&solid);
    let circle = (7.5f64.powi(2) - 4.0).sqrt();
    for (k, angle) in [0.3f64, 1.7, 3.1, 5.0].into_iter().enumerate() {
        let d = [0.001, -0.05, 1.0, -2.0][k];
        let radial = Vector3::new(angle.cos(), angle.sin(), 0.0);
        let p = centre + radial * (circle + d) + Vector3::new(0.0, 0.0, 2.0);
        let foot = distance.foot_in_section(&p).unwrap();
        assert!((foot.distance_mm - d).abs() < 1e-9, "{d}: {foot:?}");
        assert!((foot.point.z - 13.0).abs() < 1e-12);
        assert!((foot.normal - radial).norm() < 1e-9);
        assert!(solid.value(&foot.point).abs() < 1e-12);
        // Out of the plane the surface comes nearer: the 3-D distance is not the section's.
        let across = distance.foot(&p).unwrap().distance_mm;
        assert!((across - ((circle + d).hypot(2.0) - 7.5)).abs() < 1e-9);
        assert!((across - d).abs() > 0.02 * d.abs());
    }
}

#[test]
fn a_section_of_a_union_meets_the_crease_where_it_pierces_the_plane() {
    // The two balls of radius 5 at x = -3 and 3 cut by z = 0.3: two circles of radius
    // sqrt(25 - 0.09) meeting at x = 0, y = +-sqrt(25 - 0.09 - 9).
    let union = Node::boolean(
        Boolean::Union,
        RFunction::P(2),
        sphere(
            5.0,
            vec![Deformation::Rigid(Isometry3::translation(-3.0, 0.0, 0.0))],
        ),
        sphere(
            5.0,
            vec![Deformation::Rigid(Isometry3::translation(3.0, 0.0, 0.0))],
        ),
    );
    let solid = Solid::new(union);
    let distance = SolidDistance::new(&solid);
    let z = 0.3;
    let radius = (25.0f64 - z * z).sqrt();
    let crease = (radius * radius - 9.0).sqrt();
    let centres = [Point3::new(-3.0, 0.0, z), Point3::new(3.0, 0.0, z)];
    for side in [1.0, -1.0] {
        for x in [0.0, 0.2] {
            for t in [0.001, 0.1, 0.5] {
                let p = Point3::new(x, side * (crease - t), z);
                let mut expected = x.hypot(t);
                for (k, centre) in centres.iter().enumerate() {
                    let foot = centre + (p - centre).normalize() * radius;
                    if (foot - centres[1 - k]).norm() >= radius {
                        expected = expected.min(radius - (p - centre).norm());
                    }
                }
                let foot = distance.foot_in_section(&p).unwrap();
                assert!(
                    (foot.distance_mm + expected).abs() < 1e-9,
                    "{p}: {} vs {}",
                    foot.distance_mm,
                    -expected
                );
                assert!((foot.point.z - z).abs() < 1e-12 && foot.normal.z.abs() < 1e-12);
                if x == 0.0 {
                    assert_eq!(foot.kind, FootKind::Edge);
                }
                assert!(solid.value(&foot.point).abs() < 1e-9);
            }
        }
    }
}

#[test]
fn around_a_hex_nut_no_boundary_sample_is_nearer_than_the_foot() {
    // Points anywhere round the nut, near and far from faces, edges and the bore: the exact
    // distance can exceed the distance to no boundary point, and falls short of the nearest of
    // a fine independent sampling by at most that sampling's gap.
    let (solid, _, _, _) = hex_nut();
    let distance = SolidDistance::new(&solid);
    let fine = SolidDistance::with_spacing(&solid, 0.15);
    assert!(fine.samples.gap < 0.5 * distance.samples.gap);
    let bounds = solid.bounds();
    let span = bounds.max - bounds.min;
    let mut below = 0;
    for i in 0..300 {
        let u = Vector3::new(
            (i as f64 * 0.618_034).fract(),
            (i as f64 * 0.754_878).fract(),
            (i as f64 * 0.569_840).fract(),
        );
        let p = bounds.min - span * 0.1 + span.component_mul(&u) * 1.2;
        let foot = distance.foot(&p).expect("a foot");
        check_foot(&solid, &p, &foot);
        assert_eq!(foot.distance_mm > 0.0, !solid.contains(&p), "{p}");
        let nearest_sample = fine
            .samples
            .tree
            .nearest_neighbor([p.x, p.y, p.z])
            .map(|s| (Point3::from(s.point) - p).norm())
            .unwrap();
        let exact = foot.distance_mm.abs();
        assert!(
            exact <= nearest_sample + 1e-9,
            "{p}: {exact} > {nearest_sample}"
        );
        assert!(
            exact >= nearest_sample - fine.samples.gap,
            "{p}: {exact} vs {nearest_sample}"
        );
        below += usize::from(exact < nearest_sample - 1e-6);
    }
    // The samples are only near the foot: most exact distances are strictly below them.
    assert!(below > 250, "{below}");
}

#[test]
fn where_a_box_edge_pierces_a_ball_the_vertex_is_nearest() {
    // A ball of radius 10 cut to the square prism |x|, |y| <= 5: the prism's edge x = y = 5 leaves
    // the ball at the vertex (5, 5, sqrt 50), where the faces x = 5, y = 5 and the sphere meet.
    let mut cut = Node::boolean(
        Boolean::Intersection,
        RFunction::P(2),
        sphere(10.0, vec![]),
        Node::cuboid([5.0, 5.0, 20.0], Deformations::default()),
    );
    cut.place = Deformations(vec![pose()]);
    let solid = Solid::new(cut);
    let distance = SolidDistance::new(&solid);
    let vertex = Point3::new(5.0, 5.0, 50f64.sqrt());
    let ball_normal = vertex.coords / 10.0;
    for (a, b, c) in [(1.0, 1.0, 1.0), (0.2, 1.0, 0.5), (1.0, 0.3, 2.0)] {
        // Any positive combination of the three normals is in the vertex's normal cone.
        let direction = (Vector3::x() * a + Vector3::y() * b + ball_normal * c).normalize();
        for t in [0.001, 0.3, 2.0] {
            let p = pose().apply(&(vertex + direction * t));
            let foot = distance.foot(&p).unwrap();
            assert!((foot.distance_mm - t).abs() < 1e-9, "{t}: {foot:?}");
            assert_eq!(foot.kind, FootKind::Vertex);
            assert!((foot.point - pose().apply(&vertex)).norm() < 1e-9);
            check_foot(&solid, &p, &foot);
        }
    }
}
