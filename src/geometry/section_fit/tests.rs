use rand::{Rng, SeedableRng};

use super::*;

/// A thin closed section (an ellipse 100 mm long, 12 mm thick, like a blade's) as a counter-clockwise polygon of
/// many vertices: the nominal, whose signed distance is exact.
struct Polygon {
    vertices: Vec<Vector2<f64>>,
}

impl Polygon {
    fn blade() -> Polygon {
        let n = 3000;
        Polygon {
            vertices: (0..n)
                .map(|i| {
                    let t = i as f64 / n as f64 * std::f64::consts::TAU;
                    Vector2::new(50.0 * t.cos(), 6.0 * t.sin())
                })
                .collect(),
        }
    }

    fn inside(&self, p: &Vector2<f64>) -> bool {
        let n = self.vertices.len();
        let mut inside = false;
        for i in 0..n {
            let (a, b) = (self.vertices[i], self.vertices[(i + 1) % n]);
            if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
                inside = !inside;
            }
        }
        inside
    }

    fn measure(&self, p: &Vector2<f64>) -> Measured {
        let n = self.vertices.len();
        let mut best = (f64::INFINITY, Vector2::zeros(), 0);
        for i in 0..n {
            let (a, b) = (self.vertices[i], self.vertices[(i + 1) % n]);
            let ab = b - a;
            let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let foot = a + ab * t;
            let d = (p - foot).norm();
            if d < best.0 {
                best = (d, foot, i);
            }
        }
        let (d, foot, i) = best;
        let ab = self.vertices[(i + 1) % n] - self.vertices[i];
        let segment_normal = Vector2::new(ab.y, -ab.x).normalize();
        let sign = if self.inside(p) { -1.0 } else { 1.0 };
        let normal = if d > 1e-12 {
            (p - foot) / d * sign
        } else {
            segment_normal
        };
        Measured {
            distance_mm: sign * d,
            normal,
        }
    }

    /// Every other vertex, pushed `bump(vertex)` mm outward along the outward normal there.
    fn section(&self, mut bump: impl FnMut(&Vector2<f64>) -> f64) -> Vec<Vector2<f64>> {
        let n = self.vertices.len();
        (0..n)
            .step_by(2)
            .map(|i| {
                let v = self.vertices[i];
                let tangent = self.vertices[(i + 1) % n] - self.vertices[(i + n - 1) % n];
                let outward = Vector2::new(tangent.y, -tangent.x).normalize();
                v + outward * bump(&v)
            })
            .collect()
    }
}

/// `points` moved as a section displaced by `shift` and turned by `angle_deg` about the origin.
fn displaced(points: &[Vector2<f64>], shift: Vector2<f64>, angle_deg: f64) -> Vec<Vector2<f64>> {
    let turn = Rotation2::new(angle_deg.to_radians());
    points.iter().map(|p| turn * p + shift).collect()
}

fn fit(nominal: &Polygon, points: &[Vector2<f64>], mode: FitMode, method: FitMethod) -> SectionFit {
    fit_within(nominal, points, mode, method, &FitLimits::default())
}

fn fit_within(
    nominal: &Polygon,
    points: &[Vector2<f64>],
    mode: FitMode,
    method: FitMethod,
    limits: &FitLimits,
) -> SectionFit {
    fit_section(
        points,
        Vector2::zeros(),
        Vector2::x(),
        mode,
        method,
        limits,
        |moved| moved.iter().map(|p| Some(nominal.measure(p))).collect(),
    )
    .unwrap()
}

#[test]
fn a_rigidly_moved_section_fits_back_to_its_motion_by_either_method() {
    let nominal = Polygon::blade();
    let on_nominal = nominal.section(|_| 0.0);
    let mut rng = rand::rngs::StdRng::seed_from_u64(16);
    for _ in 0..4 {
        let shift = Vector2::new(rng.gen_range(-1.0..1.0), rng.gen_range(-0.5..0.5));
        let angle = rng.gen_range(-0.5..0.5);
        let measured = displaced(&on_nominal, shift, angle);
        for method in [FitMethod::L2, FitMethod::MinZone] {
            let fitted = fit(&nominal, &measured, FitMode::Full, method);
            assert!(
                (fitted.dchord_mm - shift.x).abs() < 1e-6
                    && (fitted.dn_mm - shift.y).abs() < 1e-6
                    && (fitted.rotation_deg - angle).abs() < 1e-6,
                "{method:?}: moved by {shift:?} mm, {angle} deg; fitted {} mm, {} mm, {} deg",
                fitted.dchord_mm,
                fitted.dn_mm,
                fitted.rotation_deg
            );
            assert!(fitted.form.zone_mm < 1e-6, "{:?}", fitted.form);
            assert!(fitted.form_before.zone_mm > 0.1, "{:?}", fitted.form_before);
        }
    }
}

#[test]
fn a_twist_left_out_of_the_fit_stays_in_the_form() {
    let nominal = Polygon::blade();
    let measured = displaced(&nominal.section(|_| 0.0), Vector2::new(0.0, 0.4), 0.1);
    let shifted = fit(&nominal, &measured, FitMode::Translation, FitMethod::L2);
    assert_eq!(shifted.rotation_deg, 0.0);
    assert!((shifted.dn_mm - 0.4).abs() < 1e-3, "{}", shifted.dn_mm);
    // 0.1 deg over 50 mm either side of the pivot: some 77 um left near the ends, which the full fit removes.
    assert!(shifted.form.zone_mm > 0.14, "{:?}", shifted.form);
    let full = fit(&nominal, &measured, FitMode::Full, FitMethod::L2);
    assert!(full.form.zone_mm < 1e-6, "{:?}", full.form);
    let none = fit(&nominal, &measured, FitMode::None, FitMethod::L2);
    assert_eq!((none.dn_mm, none.rotation_deg), (0.0, 0.0));
    assert_eq!(none.after_mm, none.before_mm);
}

#[test]
fn the_minimum_zone_of_a_one_sided_bump_is_its_height_where_least_squares_keeps_twice_that() {
    let nominal = Polygon::blade();
    let height = 0.010;
    // A 2 mm wide bump on the upper face at mid-chord, the section also lying 0.3 mm above the nominal.
    let bumped = nominal.section(|v| {
        if v.y > 0.0 && v.x.abs() < 1.0 {
            height
        } else {
            0.0
        }
    });
    let measured = displaced(&bumped, Vector2::new(0.0, 0.3), 0.0);
    let zone = fit(&nominal, &measured, FitMode::Full, FitMethod::MinZone);
    // Analytic: the band is halved by moving the section down by half the bump, no further.
    assert!(
        (zone.form.zone_mm - height).abs() < 1e-7,
        "zone {} mm",
        zone.form.zone_mm
    );
    assert!(
        (zone.dn_mm - (0.3 + height / 2.0)).abs() < 1e-6,
        "{}",
        zone.dn_mm
    );
    let l2 = fit(&nominal, &measured, FitMode::Full, FitMethod::L2);
    assert!(l2.form.zone_mm > 1.8 * height, "{:?}", l2.form);
    assert!((l2.dn_mm - 0.3).abs() < 1e-4, "{}", l2.dn_mm);
}

/// The full least-squares and minimum-zone fits of `measured`, the zone checked within the least-squares band.
fn both_fits_zone_within_l2(
    nominal: &Polygon,
    measured: &[Vector2<f64>],
    what: &str,
) -> (SectionFit, SectionFit) {
    let l2 = fit(nominal, measured, FitMode::Full, FitMethod::L2);
    let zone = fit(nominal, measured, FitMode::Full, FitMethod::MinZone);
    assert!(
        zone.form.zone_mm <= l2.form.zone_mm + 1e-9,
        "{what}: min zone {:?}, L2 {:?}",
        zone.form,
        l2.form
    );
    (l2, zone)
}

#[test]
fn the_minimum_zone_is_never_wider_than_the_least_squares_band() {
    let nominal = Polygon::blade();
    let mut rng = rand::rngs::StdRng::seed_from_u64(484);
    for _ in 0..3 {
        let noise: Vec<f64> = (0..1500).map(|_| rng.gen_range(-0.004..0.004)).collect();
        let mut k = 0;
        let noisy = nominal.section(|_| {
            k += 1;
            noise[k - 1]
        });
        let measured = displaced(&noisy, Vector2::new(0.2, -0.1), 0.05);
        let (l2, zone) = both_fits_zone_within_l2(&nominal, &measured, "");
        assert!(zone.form.zone_mm <= 0.008 + 1e-9);
        // Both see the same displacement, within what the noise allows.
        assert!((l2.dn_mm + 0.1).abs() < 5e-4 && (zone.dn_mm + 0.1).abs() < 2e-3);
    }
}

/// Two fits of one section placed alike and leaving the same zone, within what a settled step may still move (a
/// nanometre; the twist in degrees).
fn assert_same_fit(a: &SectionFit, b: &SectionFit, what: &str) {
    let pairs = [
        (a.dn_mm, b.dn_mm),
        (a.dchord_mm, b.dchord_mm),
        (a.rotation_deg, b.rotation_deg),
        (a.form.zone_mm, b.form.zone_mm),
    ];
    assert!(
        pairs.iter().all(|(x, y)| (x - y).abs() < 1e-6),
        "{what}: (dn, dchord, twist, zone) {pairs:?}"
    );
}

#[test]
fn a_fit_held_within_a_limit_stops_at_it_and_leaves_the_rest_in_the_form() {
    let nominal = Polygon::blade();
    let (shift, angle) = (Vector2::new(0.3, 0.4), 0.1);
    let measured = displaced(&nominal.section(|_| 0.0), shift, angle);
    let limits = FitLimits {
        dn_mm: Some(0.25),
        ..FitLimits::default()
    };
    for method in [FitMethod::L2, FitMethod::MinZone] {
        let held = fit_within(&nominal, &measured, FitMode::Full, method, &limits);
        // Held at the limit, within what a settled step may still move (a nanometre).
        assert!(
            (held.dn_mm - 0.25).abs() <= 1e-6,
            "{method:?}: {}",
            held.dn_mm
        );
        assert_eq!(held.at_limit, [false, true, false], "{method:?}");
        // The 0.15 mm the fit may not take stays as form: the faces 12 mm apart lie 0.15 mm up, so the band
        // about the nominal is some 0.3 mm wide.
        assert!(
            (held.form.zone_mm - 0.3).abs() < 0.01,
            "{method:?}: {:?}",
            held.form
        );
        // Held at 0.25 is the same as moved back by 0.25 first and held at 0: the same twist, shift and form.
        let back = Vector2::new(0.0, 0.25);
        let moved_back: Vec<Vector2<f64>> = measured.iter().map(|p| p - back).collect();
        let fixed = FitLimits {
            dn_mm: Some(0.0),
            ..FitLimits::default()
        };
        let pinned = fit_within(&nominal, &moved_back, FitMode::Full, method, &fixed);
        assert_eq!(pinned.dn_mm, 0.0);
        assert_same_fit(
            &SectionFit {
                dn_mm: 0.25,
                ..pinned
            },
            &held,
            &format!("{method:?}, held and pinned"),
        );
        // Limits the motion does not reach change nothing.
        let loose = FitLimits {
            dchord_mm: Some(1.0),
            dn_mm: Some(1.0),
            rotation_deg: Some(1.0),
        };
        let free = fit(&nominal, &measured, FitMode::Full, method);
        let within = fit_within(&nominal, &measured, FitMode::Full, method, &loose);
        assert_eq!(within.at_limit, [false; 3]);
        assert_same_fit(&within, &free, &format!("{method:?}, loose limits"));
        assert!((free.dn_mm - 0.4).abs() < 1e-6 && (free.rotation_deg - angle).abs() < 1e-6);
    }
}

#[test]
fn a_twist_limited_to_zero_is_the_translation_fit() {
    let nominal = Polygon::blade();
    let measured = displaced(&nominal.section(|_| 0.0), Vector2::new(-0.2, 0.1), 0.05);
    let no_turn = FitLimits {
        rotation_deg: Some(0.0),
        ..FitLimits::default()
    };
    for method in [FitMethod::L2, FitMethod::MinZone] {
        let limited = fit_within(&nominal, &measured, FitMode::Full, method, &no_turn);
        let translated = fit(&nominal, &measured, FitMode::Translation, method);
        assert_eq!(limited.rotation_deg, 0.0);
        // A limit of zero pins the twist by choice: it is not reported as reached.
        assert_eq!(limited.at_limit, [false; 3]);
        assert_same_fit(&limited, &translated, &format!("{method:?}, no turn"));
    }
}

#[test]
fn the_bounded_least_squares_step_meets_the_optimality_conditions() {
    // A convex quadratic within a box is at its minimum exactly where each unknown strictly inside its bounds has
    // a zero gradient, one at its lower bound a gradient >= 0 and one at its upper bound a gradient <= 0 (KKT).
    let mut rng = rand::rngs::StdRng::seed_from_u64(3);
    let mut active = 0;
    for _ in 0..500 {
        let rows: Vec<(f64, Vector3<f64>)> = (0..8)
            .map(|_| {
                let row = Vector3::from_fn(|_, _| rng.gen_range(-1.0..1.0));
                (rng.gen_range(-1.0..1.0), row)
            })
            .collect();
        let bound = |rng: &mut rand::rngs::StdRng| match rng.gen_range(0..4) {
            0 => f64::INFINITY,
            1 => 0.0,
            _ => rng.gen_range(0.01..0.5),
        };
        let lower = Vector3::from_fn(|_, _| -bound(&mut rng));
        let upper = Vector3::from_fn(|_, _| bound(&mut rng));
        let room = Step { lower, upper };
        let step = l2_step(&rows, &room);
        let gradient: Vector3<f64> = rows.iter().map(|(d, row)| row * (d + row.dot(&step))).sum();
        for k in 0..3 {
            assert!(
                lower[k] <= step[k] && step[k] <= upper[k],
                "{step} in {lower}..{upper}"
            );
            if !room.free(k) {
                continue;
            }
            let at_lower = step[k] <= lower[k] + 1e-12;
            let at_upper = step[k] >= upper[k] - 1e-12;
            active += usize::from(at_lower || at_upper);
            let g = gradient[k];
            let fine = (at_lower && g >= -1e-9) || (at_upper && g <= 1e-9) || g.abs() < 1e-9;
            assert!(
                fine,
                "unknown {k}: step {step}, gradient {gradient}, room {lower}..{upper}"
            );
        }
    }
    assert!(active > 100, "the bounds were reached {active} times");
}

#[test]
fn the_minimum_zone_settles_on_noisy_sections_dense_at_their_ends() {
    // The blade's ellipse (ends of radius 0.72 mm) sampled 1500 times, most densely at its ends, with Gaussian
    // noise of 2 um, moved and turned: 20 draws. Where the normals turn fast, the linear programme's step misleads;
    // the fit must still settle, within the least-squares band, at the displacement. (The section that did not
    // settle before the trust region, a simulated propeller's r500 scanned every 2.5 deg round its nose against
    // its faces, is not reproduced by this ellipse: the halving steps settled here too, in twice the time.)
    let nominal = Polygon::blade();
    let mut rng = rand::rngs::StdRng::seed_from_u64(2026);
    let gauss = rand_distr::Normal::new(0.0, 0.002).unwrap();
    for draw in 0..20 {
        let noisy = nominal.section(|_| rand_distr::Distribution::sample(&gauss, &mut rng));
        let shift = Vector2::new(rng.gen_range(-0.3..0.3), rng.gen_range(-0.3..0.3));
        let measured = displaced(&noisy, shift, rng.gen_range(-0.05..0.05));
        let (_, zone) = both_fits_zone_within_l2(&nominal, &measured, &format!("draw {draw}"));
        assert!(
            (zone.dn_mm - shift.y).abs() < 2e-3,
            "draw {draw}: dn {} for {}",
            zone.dn_mm,
            shift.y
        );
    }
}
