//! Tests of the swept stylus: closed forms, the envelope, clearance, the numerical tracer and the silhouette.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::{Point3, Vector3};

use super::charts::SpherePoint;
use super::clearance::{check_move, check_plan, RESOLUTION_MM};
use super::envelope::{ArcSweptBall, Capsule, End};
use super::mesh::MeshPart;
use super::motion::{Motion, ScanPath};
use super::part::PartDistance;
use super::silhouette::{ball_silhouette, silhouette_svg, traced_characteristic, PieceKind, View};
use super::stylus::Stylus;

fn p(x: f64, y: f64, z: f64) -> Point3<f64> {
    Point3::new(x, y, z)
}

/// A closed prism: the counter-clockwise polygon (in x, y) extruded over z in [z0, z1], outward triangles.
fn prism(polygon: &[(f64, f64)], z0: f64, z1: f64) -> MeshPart {
    let n = polygon.len();
    let mut vertices: Vec<Point3<f64>> = polygon.iter().map(|&(x, y)| p(x, y, z0)).collect();
    vertices.extend(polygon.iter().map(|&(x, y)| p(x, y, z1)));
    let mut triangles = Vec::new();
    for i in 1..n - 1 {
        triangles.push([0, i + 1, i]);
        triangles.push([n, n + i, n + i + 1]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([i, j, n + j]);
        triangles.push([i, n + j, n + i]);
    }
    MeshPart::new(vertices, triangles, 0.0).unwrap()
}

/// Gauss-Legendre nodes and weights on [-1, 1] (Newton's method on the Legendre polynomial).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|i| {
            let mut x = (PI * (i as f64 - 0.25) / (n as f64 + 0.5)).cos();
            loop {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                let dp = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let dx = p1 / dp;
                x -= dx;
                if dx.abs() < 1e-16 {
                    return (x, 2.0 / ((1.0 - x * x) * dp * dp));
                }
            }
        })
        .collect()
}

#[test]
fn sweep_capsule_point_and_segment_distances_match_closed_forms() {
    let cap = Capsule {
        a: p(0.0, 0.0, 0.0),
        b: p(10.0, 0.0, 0.0),
        radius_mm: 2.0,
    };
    let close = |a: f64, b: f64| assert!((a - b).abs() < 1e-14, "{a} vs {b}");
    close(cap.point_distance(&p(5.0, 3.0, 4.0)), 3.0);
    close(cap.point_distance(&p(13.0, 4.0, 0.0)), 3.0);
    close(cap.point_distance(&p(-3.0, 0.0, 0.0)), 1.0);
    close(cap.point_distance(&p(5.0, 1.0, 0.0)), -1.0);
    close(
        cap.segment_distance(&p(2.0, 0.0, 7.0), &p(8.0, 0.0, 7.0)),
        5.0,
    );
    close(
        cap.segment_distance(&p(4.0, -5.0, 6.0), &p(4.0, 5.0, 6.0)),
        4.0,
    );
    close(
        cap.segment_distance(&p(4.0, -5.0, 0.0), &p(4.0, 5.0, 0.0)),
        -2.0,
    );
    close(
        cap.segment_distance(&p(12.0, 0.0, 0.0), &p(20.0, 0.0, 0.0)),
        0.0,
    );
    // Skew segment whose closest point is an end of both: (13, 3, 4) to b = (10, 0, 0): sqrt(34).
    close(
        cap.segment_distance(&p(13.0, 3.0, 4.0), &p(20.0, 9.0, 9.0)),
        34f64.sqrt() - 2.0,
    );
    close(cap.volume(), PI * 4.0 * (10.0 + 8.0 / 3.0));

    // Random segments against a dense sampling: the exact distance is never above the sampled minimum and at
    // most the sampling's half spacing below it.
    let mut seed = 7u64;
    let mut rand = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 20.0 - 5.0
    };
    for _ in 0..50 {
        let (a, b) = (p(rand(), rand(), rand()), p(rand(), rand(), rand()));
        let exact = cap.segment_distance(&a, &b);
        let samples = 20_000;
        let sampled = (0..=samples)
            .map(|i| cap.point_distance(&a.lerp(&b, i as f64 / samples as f64)))
            .fold(f64::INFINITY, f64::min);
        let half_spacing = 0.5 * (b - a).norm() / samples as f64;
        if sampled > 0.0 {
            assert!(
                exact <= sampled + 1e-12 && exact >= sampled - half_spacing,
                "{exact} vs {sampled}"
            );
        } else {
            assert!(exact <= 0.0);
        }
    }
}

#[test]
fn sweep_mesh_distances_are_exact_and_signed() {
    let cube = prism(
        &[(45.0, -5.0), (55.0, -5.0), (55.0, 5.0), (45.0, 5.0)],
        -5.0,
        5.0,
    );
    assert!(cube.is_signed());
    let close = |a: f64, b: f64| assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    close(cube.distance(&p(50.0, 0.0, 8.0)), 3.0);
    close(cube.distance(&p(58.0, 9.0, 5.0)), 5.0);
    close(cube.distance(&p(58.0, 9.0, 17.0)), 13.0);
    close(cube.distance(&p(50.0, 1.0, 0.0)), -4.0);
    close(cube.distance(&p(46.0, 4.5, 4.0)), -0.5);
    let through = cube.segment_proximity(&p(40.0, 0.0, 0.0), &p(60.0, 0.0, 0.0));
    assert!(through.distance_mm.abs() < 1e-12);
    close(
        cube.segment_proximity(&p(48.0, 0.0, 0.0), &p(52.0, 1.0, 1.0))
            .distance_mm,
        -3.0,
    );
    let above = cube.segment_proximity(&p(40.0, 0.0, 7.0), &p(60.0, 0.0, 9.0));
    // Nearest to the top edge x = 45, z = 5: the distance between the two lines, 2.5 / sqrt(1.01).
    close(above.distance_mm, 2.5 / 1.01f64.sqrt());
    close(above.part_point.x, 45.0);
    close(above.part_point.z, 5.0);
    // An open mesh (the cube without its top) is unsigned.
    let open = MeshPart::new(
        cube.vertices().to_vec(),
        vec![[0, 2, 1], [0, 3, 2], [0, 1, 5], [0, 5, 4]],
        0.0,
    )
    .unwrap();
    assert!(!open.is_signed());
    // Inverted triangles are refused rather than read with every sign turned.
    let inverted: Vec<[usize; 3]> = (0..cube.triangle_count())
        .map(|i| {
            let [a, b, c] = cube.triangle(i);
            [a, c, b]
        })
        .collect();
    assert!(matches!(
        MeshPart::new(cube.vertices().to_vec(), inverted, 0.0),
        Err(super::mesh::MeshError::InsideOut(v)) if (v + 1000.0).abs() < 1e-9
    ));
    // The chord tolerance is subtracted.
    let coarse = MeshPart::new(cube.vertices().to_vec(), vec![[0, 2, 1], [0, 3, 2]], 0.25).unwrap();
    close(coarse.distance(&p(50.0, 0.0, -8.0)), 2.75);
}

#[test]
fn sweep_mesh_segment_search_agrees_with_brute_force() {
    let wedge = trailing_edge();
    let mut seed = 11u64;
    let mut rand = |lo: f64, hi: f64| {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        lo + (hi - lo) * ((seed >> 11) as f64 / (1u64 << 53) as f64)
    };
    for _ in 0..200 {
        let a = p(rand(-5.0, 25.0), rand(-6.0, 6.0), rand(-3.0, 13.0));
        let b = p(rand(-5.0, 25.0), rand(-6.0, 6.0), rand(-3.0, 13.0));
        let brute = (0..wedge.triangle_count())
            .map(|i| {
                let [t0, t1, t2] = wedge.triangle(i).map(|k| wedge.vertices()[k]);
                let (s, q) = super::closest::closest_segment_triangle(&a, &b, [&t0, &t1, &t2]);
                (s - q).norm()
            })
            .fold(f64::INFINITY, f64::min);
        let found = wedge.segment_proximity(&a, &b);
        assert!(
            (found.distance_mm.abs() - brute).abs() < 1e-12,
            "{} vs {brute}",
            found.distance_mm
        );
        let sign_of_a = wedge.distance(&a).signum();
        if brute > 0.0 {
            assert_eq!(found.distance_mm.signum(), sign_of_a);
        }
    }
}

#[test]
fn sweep_motions_twist_and_speed_bound_agree_with_the_pose() {
    let stylus = Stylus::new(1.5, 0.5, 30.0)
        .unwrap()
        .with_extension(2.0, 20.0)
        .unwrap()
        .with_axis(Vector3::new(0.2, 0.1, 1.0))
        .unwrap();
    let reach = stylus.reach_mm();
    assert!((reach - 52.0).abs() < 1e-12);
    let motions = [
        Motion::line(p(1.0, 2.0, 3.0), p(-20.0, 7.0, 40.0)),
        Motion::arc(
            p(5.0, 5.0, 0.0),
            Vector3::new(0.3, -0.2, 1.0),
            p(30.0, 5.0, 2.0),
            -2.5,
        )
        .unwrap(),
        Motion::rotary_index(p(100.0, 50.0, 0.0), p(60.0, 20.0, 40.0), 0.3, 1.9),
        Motion::Scan(
            ScanPath::new(
                vec![p(0.0, 0.0, 0.0), p(10.0, 0.0, 0.0), p(10.0, 5.0, 2.0)],
                false,
            )
            .unwrap(),
        ),
    ];
    let body_points: Vec<Point3<f64>> = stylus
        .capsules()
        .iter()
        .flat_map(|c| {
            let tip = c.b + Vector3::new(1.0, -1.0, 0.5).normalize() * c.radius_mm;
            [c.a, c.b, tip]
        })
        .collect();
    for motion in &motions {
        let bound = motion.max_point_speed(reach);
        for k in 0..=20 {
            let t = (k as f64 / 20.0).clamp(1e-4, 1.0 - 1e-4);
            let h = 1e-6;
            let (pose, twist) = (motion.pose(t), motion.twist(t));
            for x in &body_points {
                let fd = (motion.pose(t + h) * x - motion.pose(t - h) * x) / (2.0 * h);
                let v = twist.point_velocity(&motion.centre(t), &(pose * x));
                assert!(
                    (fd - v).norm() < 1e-6 * (1.0 + v.norm()),
                    "{motion:?} t={t}: {fd} vs {v}"
                );
                assert!(
                    v.norm() <= bound * (1.0 + 1e-12),
                    "{motion:?}: speed {} > {bound}",
                    v.norm()
                );
            }
        }
    }
    // The rotary index: the table turns +90 degrees, so relative to the part the stylus turns -90 degrees.
    let index = Motion::rotary_index(p(0.0, 0.0, 0.0), p(0.0, 50.0, 5.0), 0.0, FRAC_PI_2);
    assert!((index.centre(1.0) - p(50.0, 0.0, 5.0)).norm() < 1e-12);
}

#[test]
fn sweep_arc_envelope_volume_and_surface_residuals() {
    let sweep = ArcSweptBall {
        centre: p(1.0, 2.0, 3.0),
        axis: nalgebra::Unit::new_normalize(Vector3::new(0.2, -0.3, 1.0)),
        start: p(26.0, 2.0, 4.0),
        angle_rad: 2.0,
        ball_radius_mm: 3.0,
    };
    let (r, big_r, theta) = (3.0, sweep.path_radius_mm(), 2.0);
    let pappus = PI * r * r * big_r * theta + 4.0 / 3.0 * PI * r.powi(3);
    assert!((sweep.volume().unwrap() - pappus).abs() < 1e-14 * pappus);

    // Volume by the divergence theorem over the closed-form envelope: V = 1/3 of the integral of <X, n> dA over
    // the torus section and the two caps (Gauss-Legendre across, the trapezoidal rule around: both spectrally
    // accurate on these smooth, periodic integrands).
    let gl = gauss_legendre(40);
    let around = 128;
    let mut volume = 0.0;
    for &(x, wx) in &gl {
        for k in 0..around {
            let angle = TAU * k as f64 / around as f64;
            let w_around = TAU / around as f64;
            let tube = sweep.tube_sample(0.5 * (x + 1.0), angle);
            volume += tube.point.coords.dot(&tube.normal) * tube.area_density * 0.5 * wx * w_around;
            for end in [End::Start, End::End] {
                let cap = sweep.cap_sample(end, FRAC_PI_2 * 0.5 * (x + 1.0), angle);
                volume += cap.point.coords.dot(&cap.normal)
                    * cap.area_density
                    * FRAC_PI_2
                    * 0.5
                    * wx
                    * w_around;
            }
        }
    }
    volume /= 3.0;
    assert!(
        (volume - pappus).abs() < 1e-9 * pappus,
        "{volume} vs {pappus}"
    );

    // Every envelope point is exactly r from the centre path, and on the tube its normal is perpendicular to the
    // direction of travel (F = 0).
    let mut worst: f64 = 0.0;
    for i in 0..=50 {
        for k in 0..64 {
            let (t, angle) = (i as f64 / 50.0, TAU * k as f64 / 64.0);
            let tube = sweep.tube_sample(t, angle);
            worst = worst.max((sweep.distance_to_path(&tube.point) - r).abs());
            let (_, direction, _) = sweep.characteristic_circle(t);
            assert!(tube.normal.dot(&direction).abs() < 1e-14);
            for end in [End::Start, End::End] {
                let cap = sweep.cap_sample(end, FRAC_PI_2 * i as f64 / 50.0, angle);
                worst = worst.max((sweep.distance_to_path(&cap.point) - r).abs());
            }
        }
    }
    assert!(worst < 1e-12, "surface residual {worst}");
    // Inside and outside: the path's own points are r deep, a point on the axis is sqrt(R^2 + h^2) - r away.
    assert!((sweep.point_distance(&sweep.ball_centre(0.3)) + r).abs() < 1e-12);
    let on_axis = sweep.centre + sweep.axis.into_inner() * 7.0;
    let h = 7.0 - (sweep.start - sweep.centre).dot(&sweep.axis);
    assert!((sweep.point_distance(&on_axis) - ((big_r * big_r + h * h).sqrt() - r)).abs() < 1e-12);
}

/// A 0.3 mm trailing edge: a wedge tapering from 3 mm to 0.3 mm over 20 mm, 10 mm tall.
fn trailing_edge() -> MeshPart {
    prism(
        &[(0.0, -1.5), (20.0, -0.15), (20.0, 0.15), (0.0, 1.5)],
        0.0,
        10.0,
    )
}

#[test]
fn sweep_clearance_catches_a_clipped_trailing_edge_that_sampling_misses() {
    let wedge = trailing_edge();
    let stylus = Stylus::new(1.0, 0.4, 30.0).unwrap();
    let depth = 0.003;
    let x = 20.0 + 1.0 - depth;
    let (y0, y1) = (-5.25, 4.75);
    let clip = Motion::line(p(x, y0, 5.0), p(x, y1, 5.0));

    // The naive check: the ball every 0.5 mm of travel.
    let naive_clear = (0..=20).all(|k| {
        let centre = clip.centre(k as f64 / 20.0);
        wedge.distance(&centre) - stylus.ball_radius_mm >= 0.0
    });
    assert!(naive_clear, "the sampled check was meant to miss the clip");

    let c = check_move(&stylus, &clip, &wedge, 0.0);
    let contact = c.first_contact_t.expect("the clip is caught");
    // First contact: the ball meets the edge (x = 20, y = -0.15) when its centre is 1 mm from it.
    let y_star = -0.15 - (1.0 - (1.0 - depth) * (1.0 - depth)).sqrt();
    let t_star = (y_star - y0) / (y1 - y0);
    assert!(
        contact >= t_star - 1e-12 && contact - t_star <= RESOLUTION_MM / 10.0 + 1e-12,
        "{contact} vs {t_star}"
    );
    assert_eq!(c.stylus_part, "ball");
    assert!(
        (c.at_point - p(20.0, -0.15, 5.0)).norm() < 1e-3,
        "{}",
        c.at_point
    );

    // In a plan with a margin, the move is refused with where and by how much.
    let approach = Motion::line(p(x, -30.0, 5.0), p(x, y0, 5.0));
    let err = check_plan(&stylus, &[approach.clone(), clip], &wedge, 0.05).unwrap_err();
    assert_eq!(err.move_index, 1);
    assert!(err.shortfall_mm >= 0.05 && err.distance_mm <= 0.0);
    assert!((err.at_point - p(20.0, -0.15, 5.0)).norm() < 1e-3);
    assert!(err.to_string().contains("move 1"), "{err}");

    // 0.2 mm clear: accepted, with the flat of the trailing edge found and a certified bound above the margin.
    let pass = Motion::line(p(21.2, y0, 5.0), p(21.2, y1, 5.0));
    let plan = check_plan(&stylus, &[approach, pass], &wedge, 0.05).unwrap();
    assert_eq!(plan.closest_move, 1);
    assert!(
        (plan.min_distance_mm - 0.2).abs() < 1e-9,
        "{}",
        plan.min_distance_mm
    );
    assert!(plan.moves[1].lower_bound_mm >= 0.05 - 0.5 * RESOLUTION_MM);
    assert!(plan.moves[1].first_contact_t.is_none());
}

#[test]
fn sweep_clearance_of_a_rotary_index_finds_the_contact_angle() {
    let cube = prism(
        &[(45.0, -5.0), (55.0, -5.0), (55.0, 5.0), (45.0, 5.0)],
        -5.0,
        5.0,
    );
    let stylus = Stylus::new(1.0, 0.4, 30.0).unwrap();
    let index = Motion::rotary_index(p(0.0, 0.0, 0.0), p(0.0, 50.0, 5.0), 0.0, FRAC_PI_2);
    let c = check_move(&stylus, &index, &cube, 0.0);
    // Relative to the part the ball centre is (50 sin a, 50 cos a, 5): it meets the cube's top edge y = 5,
    // z = 5 when 50 cos a - 5 = 1.
    let t_star = (6.0f64 / 50.0).acos() / FRAC_PI_2;
    let contact = c
        .first_contact_t
        .expect("the index swings the part into the stylus");
    let speed = index.max_point_speed(stylus.reach_mm());
    assert!(contact >= t_star - 1e-12 && contact - t_star <= RESOLUTION_MM / speed + 1e-12);
    // A contact scan along the top face ignores the ball but watches the shank.
    let scan =
        Motion::Scan(ScanPath::new(vec![p(46.0, 0.0, 6.0), p(54.0, 0.0, 6.0)], true).unwrap());
    let scanned = check_move(&stylus, &scan, &cube, 0.0);
    assert_eq!(scanned.stylus_part, "shank");
    assert!((scanned.min_distance_mm - 0.6).abs() < 1e-12);
}

#[test]
fn sweep_traced_characteristic_curves_are_the_closed_form_circles() {
    let r = 2.0;
    let step = 0.05;
    let motions = [
        // Motion along x: the characteristic circle runs through both poles of the z chart.
        Motion::line(p(1.0, 2.0, 3.0), p(31.0, 2.0, 3.0)),
        Motion::line(p(0.0, 0.0, 0.0), p(10.0, -20.0, 15.0)),
        Motion::arc(p(0.0, 0.0, 0.0), Vector3::z(), p(40.0, 0.0, 5.0), 1.5).unwrap(),
        Motion::rotary_index(p(0.0, 0.0, 0.0), p(30.0, 10.0, 5.0), 0.0, 1.0),
    ];
    for motion in &motions {
        for t in [0.0, 0.37, 1.0] {
            let curve = traced_characteristic(motion, r, t, step).unwrap();
            let (params, points, closed) = (curve.params, curve.points, curve.closed);
            assert!(closed, "{motion:?} at t = {t} did not close");
            let centre = motion.centre(t);
            let direction = motion.twist(t).centre_velocity.normalize();
            for x in &points {
                assert!(((x - centre).norm() - r).abs() < 1e-12);
                assert!(
                    (x - centre).dot(&direction).abs() < 1e-12,
                    "{}",
                    (x - centre).dot(&direction)
                );
            }
            // The traced polygon follows the whole circle: every closed-form point is within the chord's sagitta.
            let sagitta = 2.0 * step * step / (8.0 * r);
            let u = direction.cross(&Vector3::new(0.3, 0.5, 0.7)).normalize();
            let v = direction.cross(&u);
            for k in 0..360 {
                let a = TAU * k as f64 / 360.0;
                let exact = centre + (u * a.cos() + v * a.sin()) * r;
                let nearest = (0..points.len())
                    .map(|i| {
                        let (a, b) = (points[i], points[(i + 1) % points.len()]);
                        super::closest::closest_on_segment(&exact, &a, &b).0
                    })
                    .map(|q| (q - exact).norm())
                    .fold(f64::INFINITY, f64::min);
                assert!(nearest <= sagitta, "{nearest} > {sagitta}");
            }
            if motion == &motions[0] {
                assert!(
                    params.iter().any(|q| q.s.chart == 0) && params.iter().any(|q| q.s.chart == 1)
                );
            }
        }
    }
}

#[test]
fn sweep_sphere_charts_agree_and_stay_away_from_poles() {
    for n in [
        Vector3::z(),
        -Vector3::x(),
        Vector3::new(0.3, -0.4, 0.8),
        Vector3::new(-1.0, 1.0, 1e-3),
    ] {
        let s = SpherePoint::from_normal(&n);
        assert!(s.v.abs() <= FRAC_PI_2 / 2.0 + 1e-12);
        assert!((s.normal() - n.normalize()).norm() < 1e-15);
        let f = s.frame();
        // Same orientation in both charts: n_u x n_v = cos v n.
        assert!((f.n_u.cross(&f.n_v) - f.n * s.v.cos()).norm() < 1e-15);
    }
}

/// Residuals of eqs. (1) and (2) at every point of every envelope piece.
fn assert_on_silhouette(
    motion: &Motion,
    r: f64,
    eye: Point3<f64>,
    components: &[super::silhouette::SilhouetteComponent],
) {
    let sweep = super::ball_system::BallSweep {
        motion,
        radius_mm: r,
        eye: Some(eye),
    };
    for piece in components.iter().flat_map(|c| &c.pieces) {
        for q in &piece.params {
            let g = sweep.silhouette(q).value;
            assert!(g.abs() < 1e-12, "G = {g}");
            if piece.kind == PieceKind::Envelope {
                let f = sweep.envelope(q).value;
                assert!(f.abs() < 1e-12, "F = {f}");
            }
        }
    }
}

#[test]
fn sweep_silhouette_of_a_ball_on_a_line_is_the_capsule_outline() {
    let r = 2.0;
    let motion = Motion::line(p(0.0, 0.0, 0.0), p(40.0, 0.0, 0.0));
    let eye = p(20.0, -50.0, 30.0);
    let components = ball_silhouette(&motion, r, eye, 0.2).unwrap();
    assert_on_silhouette(&motion, r, eye, &components);
    // One closed outline: two envelope lines joined by an arc on each cap.
    assert_eq!(components.len(), 1);
    let kinds: Vec<PieceKind> = components[0].pieces.iter().map(|p| p.kind).collect();
    assert_eq!(
        kinds.iter().filter(|&&k| k == PieceKind::Envelope).count(),
        2
    );
    assert_eq!(
        kinds.iter().filter(|&&k| k == PieceKind::StartCap).count(),
        1
    );
    assert_eq!(kinds.iter().filter(|&&k| k == PieceKind::EndCap).count(), 1);
    assert!(components[0].t_extremes.is_empty());
    // The envelope lines are the capsule's contour generators: straight, parallel to the axis, spanning it.
    for piece in components[0]
        .pieces
        .iter()
        .filter(|p| p.kind == PieceKind::Envelope)
    {
        let (first, last) = (piece.points[0], piece.points[piece.points.len() - 1]);
        assert!(((last - first).x.abs() - 40.0).abs() < 1e-9);
        assert!((last - first).yz().norm() < 1e-9);
    }

    // From a point on the axis beyond the end, only the end cap's circle is seen.
    let on_axis = p(60.0, 0.0, 0.0);
    let components = ball_silhouette(&motion, r, on_axis, 0.2).unwrap();
    assert_on_silhouette(&motion, r, on_axis, &components);
    assert_eq!(components.len(), 1);
    assert_eq!(components[0].pieces.len(), 1);
    assert_eq!(components[0].pieces[0].kind, PieceKind::EndCap);
    assert!(components[0].pieces[0].closed);

    let view = View {
        eye,
        target: p(20.0, 0.0, 0.0),
        up: Vector3::z(),
    };
    let components = ball_silhouette(&motion, r, eye, 0.2).unwrap();
    let svg = silhouette_svg(&components, &view, 400.0);
    assert_eq!(svg.matches("<g ").count(), 1);
    assert_eq!(svg.matches("<polyline").count(), 4);
    // The drawing fills the picture less its 5 % margins along its longer (horizontal) side, centred.
    let coords: Vec<(f64, f64)> = svg
        .split("points=\"")
        .skip(1)
        .flat_map(|rest| rest.split('"').next().unwrap().split(' '))
        .map(|pair| {
            let (x, y) = pair.split_once(',').unwrap();
            (x.parse().unwrap(), y.parse().unwrap())
        })
        .collect();
    let (x_min, x_max) = coords
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
            (a.min(c.0), b.max(c.0))
        });
    let (y_min, y_max) = coords
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), c| {
            (a.min(c.1), b.max(c.1))
        });
    assert!(
        (x_min - 20.0).abs() < 2e-3 && (x_max - 380.0).abs() < 2e-3,
        "{x_min} {x_max}"
    );
    assert!((0.5 * (y_min + y_max) - 200.0).abs() < 2e-3 && y_max - y_min < 360.0);
}

#[test]
fn sweep_silhouette_of_a_ball_on_an_arc_has_a_t_extreme_point() {
    // The eye on the tangent of the arc behind its start: the envelope's silhouette begins at the time t* where
    // the eye leaves the cylinder of radius r about the tangent line (a t-extreme point), and the start cap's
    // silhouette circle is a component of its own.
    let (big_r, r, theta, behind) = (30.0, 2.0, 1.2, 25.0);
    let motion = Motion::arc(p(0.0, 0.0, 0.0), Vector3::z(), p(big_r, 0.0, 0.0), theta).unwrap();
    let eye = p(big_r, -behind, 0.0);
    let components = ball_silhouette(&motion, r, eye, 0.1).unwrap();
    assert_on_silhouette(&motion, r, eye, &components);
    assert_eq!(components.len(), 2, "{components:#?}");
    let extremes: Vec<_> = components.iter().flat_map(|c| &c.t_extremes).collect();
    assert_eq!(extremes.len(), 1);
    // |p_perp(t)|^2 = |P - c|^2 - <P - c, tangent>^2 = r^2, solved by bisection.
    let excess = |t: f64| {
        let a = theta * t;
        let d = eye - p(big_r * a.cos(), big_r * a.sin(), 0.0);
        let tangent = Vector3::new(-a.sin(), a.cos(), 0.0);
        d.norm_squared() - d.dot(&tangent).powi(2) - r * r
    };
    let (mut lo, mut hi) = (0.0, 1.0);
    assert!(excess(lo) < 0.0 && excess(hi) > 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    assert!(
        (extremes[0].param.t - lo).abs() < 1e-9,
        "{} vs {lo}",
        extremes[0].param.t
    );
    let kinds = |c: &super::silhouette::SilhouetteComponent| {
        c.pieces.iter().map(|p| p.kind).collect::<Vec<_>>()
    };
    assert!(components
        .iter()
        .any(|c| kinds(c) == vec![PieceKind::StartCap]));
}
