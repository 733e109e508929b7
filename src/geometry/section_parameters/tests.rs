//! Parameters of sections whose values are known in closed form: ellipses and NACA 4-digit sections, moved and
//! turned in the plane.

use nalgebra::{Rotation2, Vector2};

use zeroset_sim::naca::Naca4;

use super::*;

/// `count` points round an ellipse of semi-axes `a` (along x) and `b`, counter-clockwise.
fn ellipse(a: f64, b: f64, count: usize) -> Vec<Vector2<f64>> {
    (0..count)
        .map(|i| {
            let t = std::f64::consts::TAU * i as f64 / count as f64;
            Vector2::new(a * t.cos(), b * t.sin())
        })
        .collect()
}

/// The NACA 4-digit section `digits` (chord 100 mm along +x from the nose at the origin, its trailing edge closed),
/// `count` points round it from the tail, crowding at both edges (the simulator's sections).
fn naca(digits: &str, count: usize) -> Vec<Vector2<f64>> {
    Naca4::from_digits(digits, 100.0, true)
        .unwrap()
        .points(count)
        .into_iter()
        .map(|[x, y]| Vector2::new(x, y))
        .collect()
}

/// NACA's half-thickness at x (mm, chord 100 mm).
fn naca_half_thickness(t: f64, x: f64) -> f64 {
    let xi = x / 100.0;
    100.0
        * 5.0
        * t
        * (0.2969 * xi.sqrt() - 0.1260 * xi - 0.3516 * xi * xi + 0.2843 * xi.powi(3)
            - 0.1036 * xi.powi(4))
}

fn moved(points: &[Vector2<f64>], angle_deg: f64, shift: Vector2<f64>) -> Vec<Vector2<f64>> {
    let turn = Rotation2::new(angle_deg.to_radians());
    points.iter().map(|p| turn * p + shift).collect()
}

#[test]
fn an_ellipses_parameters_are_its_axes_wherever_it_lies_and_however_it_is_turned() {
    // 100 x 10 mm: chord 100, the largest inscribed circle the minor axis (its curvature radius at the minor
    // vertex, a^2 / b = 500 mm, is far wider), no camber; the thickness d in from an end is 2 b sqrt(1 - (1 -
    // d / a)^2). Both ends are alike: either may be called the leading edge, the chord then turned by 180 deg.
    let (a, b) = (50.0, 5.0);
    for (angle, shift) in [(0.0, Vector2::zeros()), (27.5, Vector2::new(310.0, -42.0))] {
        let outline = moved(&ellipse(a, b, 4000), angle, shift);
        let p = section_parameters(&outline, &[], 2.0).unwrap();
        // Each end is the peak of a quartic fitted across its nose (of radius b^2 / a = 0.5 mm), which the
        // ellipse's higher terms put 0.03 um inside it.
        assert!((p.chord_mm - 100.0).abs() < 1e-4, "{}", p.chord_mm);
        assert!(
            (p.max_thickness_mm - 10.0).abs() < 1e-4,
            "{}",
            p.max_thickness_mm
        );
        assert!(
            (p.max_thickness_at - 0.5).abs() < 1e-3,
            "{}",
            p.max_thickness_at
        );
        let edge = 2.0 * b * (1.0 - (1.0 - 2.0 / a).powi(2)).sqrt();
        // The polygon's chords cut inside the curve: with 4000 points, by under 0.1 um.
        assert!(
            (p.le_thickness_mm - edge).abs() < 1e-4,
            "{} vs {edge}",
            p.le_thickness_mm
        );
        assert!(
            (p.te_thickness_mm - edge).abs() < 1e-4,
            "{} vs {edge}",
            p.te_thickness_mm
        );
        let chord = p.trailing_edge - p.leading_edge;
        let turned = (chord.y.atan2(chord.x).to_degrees() - angle).rem_euclid(180.0);
        assert!(
            turned.min(180.0 - turned) < 1e-6,
            "chord along {chord} vs {angle} deg"
        );
    }
}

#[test]
fn a_naca_0012_section_has_its_published_thickness_at_30_percent_and_its_nose_is_the_leading_edge()
{
    let outline = moved(&naca("0012", 3000), -12.0, Vector2::new(0.0, 250.0));
    let p = section_parameters(&outline, &[], 5.0).unwrap();
    // The nose is the peak of a quartic fitted across it, which NACA's nose (x ~ y^2 + |y|^3 near its tip) puts
    // 0.35 um beyond it: the same on a scan as on its nominal, so their difference keeps it out.
    assert!((p.chord_mm - 100.0).abs() < 5e-4, "{}", p.chord_mm);
    // The nose is the blunt end: the leading edge, at the moved origin.
    assert!(
        (p.leading_edge - Vector2::new(0.0, 250.0)).norm() < 5e-4,
        "{}",
        p.leading_edge
    );
    let chord = p.trailing_edge - p.leading_edge;
    assert!(
        (chord.y.atan2(chord.x).to_degrees() + 12.0).abs() < 1e-6,
        "{chord}"
    );
    // The thickest point of the NACA 00xx thickness lies at x/c = 0.2998 with t = 12.00 % (its flat top there
    // makes the inscribed circle's diameter the thickness).
    assert!(
        (p.max_thickness_mm - 12.0).abs() < 2e-3,
        "{}",
        p.max_thickness_mm
    );
    assert!(
        (p.max_thickness_at - 0.2998).abs() < 2e-3,
        "{}",
        p.max_thickness_at
    );
    let le = 2.0 * naca_half_thickness(0.12, 5.0);
    let te = 2.0 * naca_half_thickness(0.12, 95.0);
    assert!(
        (p.le_thickness_mm - le).abs() < 2e-3,
        "{} vs {le}",
        p.le_thickness_mm
    );
    assert!(
        (p.te_thickness_mm - te).abs() < 2e-3,
        "{} vs {te}",
        p.te_thickness_mm
    );
}

#[test]
fn a_thinned_section_reads_back_thinner_by_as_much() {
    // Scaling a NACA 0012 across its chord by 0.99 scales its thickness, and so its largest inscribed circle, by
    // as much: what a thickness error must show.
    let section = naca("0012", 3000);
    let nominal = section_parameters(&section, &[], 5.0).unwrap();
    let thinned: Vec<Vector2<f64>> = section
        .iter()
        .map(|p| Vector2::new(p.x, 0.99 * p.y))
        .collect();
    let thinner = section_parameters(&thinned, &[], 5.0).unwrap();
    let ratio = thinner.max_thickness_mm / nominal.max_thickness_mm;
    assert!((ratio - 0.99).abs() < 2e-4, "{ratio}");
    assert!((thinner.chord_mm - nominal.chord_mm).abs() < 1e-3);
}

#[test]
fn an_outline_that_is_not_a_section_is_refused_saying_why() {
    assert_eq!(
        section_parameters(&ellipse(5.0, 1.0, 3), &[], 1.0),
        Err(ParameterError::TooFewPoints(3))
    );
    // Edge thickness asked farther in than the chord is long.
    let error = section_parameters(&ellipse(5.0, 1.0, 100), &[], 20.0).unwrap_err();
    assert!(
        error.to_string().contains("from its leading edge"),
        "{error}"
    );
}

/// `outline` with each point moved along its outline normal by Gaussian noise of `sigma` mm.
fn noisy(outline: &[Vector2<f64>], sigma: f64, seed: u64) -> Vec<Vector2<f64>> {
    use rand::SeedableRng;
    use rand_distr::Distribution;
    let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
    let normal = rand_distr::Normal::new(0.0, sigma).unwrap();
    let n = outline.len();
    (0..n)
        .map(|i| {
            let tangent = outline[(i + 1) % n] - outline[(i + n - 1) % n];
            let across = Vector2::new(tangent.y, -tangent.x).normalize();
            outline[i] + across * normal.sample(&mut rng)
        })
        .collect()
}

#[test]
fn the_mean_line_of_a_naca_section_is_its_camber_line_wherever_it_lies() {
    // NACA "mpxx": maximum camber m % of the chord at p tenths, on a mean line from the nose (0, 0) to the tail
    // (100, 0) mm. The inscribed circles' centres lie on it to within microns (the thickness is laid off normal
    // to it), the chord angle is the section's turn.
    for (digits, camber_mm, at) in [
        ("4412", 4.0, 0.4),
        ("2412", 2.0, 0.4),
        ("6409", 6.0, 0.4),
        ("0012", 0.0, f64::NAN),
    ] {
        for (angle, shift) in [(0.0, Vector2::zeros()), (-33.0, Vector2::new(-250.0, 71.0))] {
            let outline = moved(&naca(digits, 600), angle, shift);
            let line = section_parameters(&outline, &[], 2.0).unwrap().mean_line;
            let back = |p: Vector2<f64>| Rotation2::new(-f64::to_radians(angle)) * (p - shift);
            let case = format!("NACA {digits} turned {angle} deg");
            assert!(
                (line.chord_angle_deg - angle).abs() < 0.004,
                "{case}: {}",
                line.chord_angle_deg
            );
            assert!(
                (line.max_camber_mm - camber_mm).abs() < 0.005,
                "{case}: {}",
                line.max_camber_mm
            );
            if camber_mm > 0.0 {
                assert!(
                    (line.max_camber_at - at).abs() < 0.005,
                    "{case}: {}",
                    line.max_camber_at
                );
            }
            assert!(
                back(line.leading_end).norm() < 0.01,
                "{case}: {}",
                back(line.leading_end)
            );
            assert!(
                (back(line.trailing_end) - Vector2::new(100.0, 0.0)).norm() < 0.001,
                "{case}"
            );
            assert!(
                line.points.len() > MEAN_LINE_STATIONS * 9 / 10,
                "{}",
                line.points.len()
            );
        }
    }
}

#[test]
fn noise_of_2_um_moves_the_chord_angle_by_under_3_millidegrees_where_the_two_farthest_points_move_ten_times_more(
) {
    // Seed 003's root section (NACA 4412, chord 180 mm) scanned with 400 points against its dense nominal.
    let scaled = |count| {
        naca("4412", count)
            .iter()
            .map(|p| p * 1.8)
            .collect::<Vec<_>>()
    };
    let dense = scaled(8000);
    let nominal = section_parameters(&dense, &[], 2.0).unwrap().mean_line;
    let angle_of = |(a, b): (Vector2<f64>, Vector2<f64>)| (b - a).y.atan2((b - a).x).to_degrees();
    let farthest_nominal = angle_of(farthest_pair(&dense));
    let (mut worst, mut worst_farthest) = (0.0f64, 0.0f64);
    for seed in 0..20 {
        let outline = noisy(&scaled(400), 0.002, seed);
        let line = section_parameters(&outline, &[], 2.0).unwrap().mean_line;
        worst = worst.max((line.chord_angle_deg - nominal.chord_angle_deg).abs());
        worst_farthest =
            worst_farthest.max((angle_of(farthest_pair(&outline)) - farthest_nominal).abs());
        let camber = line.max_camber_mm - nominal.max_camber_mm;
        assert!(
            camber.abs() < 0.004,
            "seed {seed}: camber off by {camber} mm"
        );
    }
    assert!(worst < 0.003, "the chord angle moved by {worst} deg");
    assert!(
        worst_farthest > 10.0 * worst,
        "{worst_farthest} against {worst}"
    );
}

/// A stadium: a 100 mm long bar with round ends of radius `r`, counter-clockwise, about 0.05 mm between points.
fn stadium(r: f64) -> Vec<Vector2<f64>> {
    let mut points = Vec::new();
    let straight = 100.0 - 2.0 * r;
    for k in 0..2 {
        let (centre, from) = if k == 0 {
            (Vector2::new(straight / 2.0, 0.0), -90f64)
        } else {
            (Vector2::new(-straight / 2.0, 0.0), 90f64)
        };
        for i in 0..=180 {
            let a = (from + i as f64).to_radians();
            points.push(centre + Vector2::new(a.cos(), a.sin()) * r);
        }
        let sign = if k == 0 { -1.0 } else { 1.0 };
        for i in 1..(straight / 0.5) as usize {
            points.push(Vector2::new(
                -sign * (straight / 2.0 - 0.5 * i as f64),
                -sign * r,
            ));
        }
    }
    points
}

#[test]
fn round_edges_have_their_radius_and_a_sharp_one_none() {
    // A stadium's ends are circles: both radii exact, wherever it lies.
    let outline = moved(&stadium(3.0), 33.0, Vector2::new(-250.0, 80.0));
    let p = section_parameters(&noisy(&outline, 0.002, 5), &[], 2.0).unwrap();
    for radius in [p.le_radius_mm, p.te_radius_mm] {
        let radius = radius.expect("a round end");
        assert!((radius - 3.0).abs() < 0.005, "{radius}");
    }
    // NACA 0012 of chord 100 mm: nose radius 1.1019 t^2 c = 1.5867 mm (its published value); the closed trailing
    // edge is a corner and has none. NACA's half-thickness 0.2969 sqrt(x) - 0.1260 x ... bends away from its
    // osculating circle at first order, so the circle fitted over a quarter of the radius is 6 % wider (1.686
    // mm); on a round nose whose curvature is stationary at the tip (the stadium's) the two agree.
    let p = section_parameters(&noisy(&naca("0012", 2000), 0.002, 6), &[], 2.0).unwrap();
    let le = p.le_radius_mm.expect("a round nose");
    assert!(le > 1.5867 && le < 1.5867 * 1.07, "{le}");
    assert_eq!(p.te_radius_mm, None);
    // Twice as thick, four times the osculating nose radius (r ~ t^2); the fitted circle's zone follows the
    // radius, on a stretched outline that is not the same shape, so it grows 3.7 times.
    let thick = section_parameters(&naca("0024", 2000), &[], 2.0).unwrap();
    let ratio = thick.le_radius_mm.unwrap()
        / section_parameters(&naca("0012", 2000), &[], 2.0)
            .unwrap()
            .le_radius_mm
            .unwrap();
    assert!(ratio > 3.5 && ratio < 4.0, "{ratio}");
}

#[test]
fn a_nose_scanned_in_10_degree_steps_keeps_its_tip_whatever_the_steps_phase() {
    // NACA 0012 (nose radius 1.58 mm), dense along its faces, its nose (the first 3 mm) kept only where its normal
    // has turned another 10 degrees from a phase or 1 mm on, as a scan steps round it. The farthest point then falls short of
    // the tip by up to r (1 - cos 5 deg), 6 um; the chord from the nose's circle stays within 1 um of 100 mm, and the
    // thickness 2 mm in within 10 um of the dense outline's (8.8 um at worst; 31 um along the points' chords).
    let dense = naca("0012", 6000);
    let normal_angle = |i: usize| {
        let n = dense.len();
        let t = dense[(i + 1) % n] - dense[(i + n - 1) % n];
        t.y.atan2(t.x).to_degrees()
    };
    let mut worst_shortfall = 0.0f64;
    let dense_le_thickness = section_parameters(&dense, &[], 2.0)
        .unwrap()
        .le_thickness_mm;
    for phase in (0..10).step_by(2) {
        // As a scan steps: another point where the normal has turned into the next 10 deg, or 1 mm on.
        let (mut next_angle, mut last) = (None, dense[0]);
        let outline: Vec<Vector2<f64>> = (0..dense.len())
            .filter(|&i| {
                let angle = normal_angle(i).rem_euclid(360.0);
                let step = ((angle - phase as f64) / 10.0).floor();
                let keep =
                    dense[i].x > 3.0 || next_angle != Some(step) || (dense[i] - last).norm() >= 1.0;
                next_angle = Some(step);
                if keep {
                    last = dense[i];
                }
                keep
            })
            .map(|i| dense[i])
            .collect();
        let (a, b) = farthest_pair(&outline);
        worst_shortfall = worst_shortfall.max(100.0 - (b - a).norm());
        let p = section_parameters(&outline, &[], 2.0).unwrap();
        assert!(
            (p.chord_mm - 100.0).abs() < 1e-3,
            "phase {phase} deg: chord {}",
            p.chord_mm
        );
        // 2 mm in, the faces are crossed where the points stand up to 1 mm apart round the nose: between them
        // the smooth outline, not their chord, which cut inside the faces and put the thickness up to 31 um thin.
        assert!(
            (p.le_thickness_mm - dense_le_thickness).abs() < 0.010,
            "phase {phase} deg: leading-edge thickness {} mm, the dense outline's {dense_le_thickness} mm",
            p.le_thickness_mm
        );
    }
    assert!(
        worst_shortfall > 2e-3,
        "the steps cost the farthest points only {worst_shortfall} mm"
    );
}

/// `dense` (from its sharp tail round, closed) as a scan steps round it: the tail, then a point every `step` mm
/// along the outline (from `phase` of a step on) or where its direction has turned another 10 deg, whichever
/// comes first.
fn stepped(dense: &[Vector2<f64>], step: f64, phase: f64) -> Vec<Vector2<f64>> {
    stepped_by(dense, step, phase, 10.0)
}

/// As [`stepped`], with a point wherever the direction has turned another `angle_deg`.
fn stepped_by(dense: &[Vector2<f64>], step: f64, phase: f64, angle_deg: f64) -> Vec<Vector2<f64>> {
    let direction = |i: usize| {
        let t = dense[(i + 1) % dense.len()] - dense[i];
        t.y.atan2(t.x)
    };
    let mut out = vec![dense[0]];
    let (mut travelled, mut last_angle) = ((1.0 - phase) * step, direction(1));
    for i in 1..dense.len() {
        travelled += (dense[i] - dense[i - 1]).norm();
        let turned = (direction(i) - last_angle + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        if travelled >= step || turned.abs() >= angle_deg.to_radians() {
            out.push(dense[i]);
            travelled = 0.0;
            last_angle = direction(i);
        }
    }
    out
}

#[test]
fn a_noisy_scans_maximum_thickness_is_not_read_at_its_luckiest_station() {
    // NACA 4412 and 6409 at 150 mm chord scanned as the simulated CMM steps (0.75-1.25 mm along the faces, 10 deg
    // round the nose), 2 um noise, 20 draws each: the maximum thickness within 4 um of the dense outline's (3.1 um
    // at worst here), never biased by more than a micron. Before, the largest of the stations' noisy inscribed
    // circles (against the points' chords) was taken: up to 7.9 um thick over 40 draws.
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(41);
    for digits in ["4412", "6409"] {
        let dense = naca_of_150_mm(digits);
        let truth = section_parameters(&dense, &[], 2.0)
            .unwrap()
            .max_thickness_mm;
        let errors: Vec<f64> = (0..20)
            .map(|draw| {
                let scan = stepped(&dense, 0.75 + 0.5 * rng.gen::<f64>(), rng.gen());
                let outline = noisy(&scan, 0.002, draw);
                section_parameters(&outline, &[], 2.0)
                    .unwrap()
                    .max_thickness_mm
                    - truth
            })
            .collect();
        let mean = errors.iter().sum::<f64>() / errors.len() as f64;
        let worst = errors.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        assert!(worst < 0.004, "NACA {digits}: {errors:?}");
        assert!(mean.abs() < 0.001, "NACA {digits}: mean {mean}");
    }
}

/// The NACA 4-digit section `digits` of 150 mm chord with its trailing edge closed: 30 000 points from the tail.
fn naca_of_150_mm(digits: &str) -> Vec<Vector2<f64>> {
    Naca4::from_digits(digits, 150.0, true)
        .unwrap()
        .points(30000)
        .into_iter()
        .map(|[x, y]| Vector2::new(x, y))
        .collect()
}

/// A scan that starts at a sharp trailing edge, its first point replaced by the 16 contacts of a ball rolling round
/// the edge, each `apex` within 2 um of noise on each axis; and the contacts' indices.
fn with_roll_contacts(
    scan: &[Vector2<f64>],
    apex: Vector2<f64>,
    rng: &mut rand::rngs::StdRng,
) -> (Vec<Vector2<f64>>, Vec<usize>) {
    use rand_distr::Distribution;
    let noise = rand_distr::Normal::new(0.0, 0.002).unwrap();
    let mut outline: Vec<Vector2<f64>> = (0..16)
        .map(|_| apex + Vector2::new(noise.sample(rng), noise.sample(rng)))
        .collect();
    outline.extend_from_slice(&scan[1..]);
    (outline, (0..16).collect())
}

#[test]
fn a_sharp_edges_tip_is_the_mean_of_the_contacts_rolling_round_it() {
    // A scan rolls the ball round a sharp trailing edge: some 16 contacts, each the apex within the noise (2 um
    // on each axis here). The farthest of them stands proud of the apex, 0.8-5.8 um along the chord over 20 draws,
    // 3.4 um on average; the mean of the contacts the compensation names, within 1.2 um of it (-0.1 um on
    // average).
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(43);
    let dense = naca_of_150_mm("4412");
    let truth = section_parameters(&dense, &[], 2.0).unwrap();
    let along = (truth.trailing_edge - truth.leading_edge).normalize();
    let (mut named, mut farthest) = (Vec::new(), Vec::new());
    for _ in 0..20 {
        let scan = stepped(&dense, 0.75 + 0.5 * rng.gen::<f64>(), rng.gen());
        // The tail (the scan's first point) becomes the roll's contacts.
        let (outline, contacts) = with_roll_contacts(&scan, scan[0], &mut rng);
        let tip_error = |contacts: &[usize]| {
            let p = section_parameters(&outline, contacts, 2.0).unwrap();
            (p.trailing_edge - truth.trailing_edge).dot(&along)
        };
        named.push(tip_error(&contacts));
        farthest.push(tip_error(&[]));
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let worst = |v: &[f64]| v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(mean(&farthest) > 0.002, "farthest: {farthest:?}");
    assert!(mean(&named).abs() < 0.0005, "named: {named:?}");
    assert!(worst(&named) < 0.002, "named: {named:?}");
}

#[test]
fn a_noisy_nose_scanned_every_2_5_degrees_has_its_tip_within_two_microns() {
    // NACA 4412 and 0012 at 100 mm (nose radii 1.6 mm) stepped 1 mm along the faces and 2.5 deg round the nose,
    // 2 um noise, 20 draws each. The tip along the chord, against the dense outline's: the nose fitted across its
    // points averages the noise (0.6 um RMS, 1.6 um at worst in a longer campaign); the farthest point moved out
    // to the smooth outline's reach carried one point's noise (1.5 um RMS, 6 um at worst).
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let mut errors = Vec::new();
    for digits in ["4412", "0012"] {
        let dense = naca(digits, 20_000);
        let truth = section_parameters(&dense, &[], 2.0).unwrap();
        let out = (truth.leading_edge - truth.trailing_edge).normalize();
        for draw in 0..20 {
            let scan = noisy(&stepped_by(&dense, 1.0, rng.gen(), 2.5), 0.002, draw);
            let measured = section_parameters(&scan, &[], 2.0).unwrap();
            errors.push((measured.leading_edge - truth.leading_edge).dot(&out));
        }
    }
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    let worst = errors.iter().fold(0.0f64, |w, e| w.max(e.abs()));
    assert!(rms < 0.001, "RMS {rms} mm");
    assert!(worst < 0.002, "worst {worst} mm");
}

#[test]
fn a_sharp_trailing_edge_s_apex_is_the_mean_line_s_end_and_steadies_the_chord_angle() {
    // NACA 4412 of 150 mm with its trailing edge closed, scanned every 0.75-1.25 mm from a random phase with 2 um
    // of noise, the ball's 16 contacts rolling round the trailing edge named: the mean line ends at the apex the
    // contacts give. Followed out from the inscribed circles' centres instead, the end moved across the chord with
    // the faces' noise.
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(4412);
    let dense = naca_of_150_mm("4412");
    let truth = section_parameters(&dense, &[], 2.0).unwrap();
    assert_eq!(truth.mean_line.trailing_end, truth.trailing_edge);
    let mut errors = Vec::new();
    for _ in 0..40 {
        let scan = noisy(
            &stepped(&dense, 0.75 + 0.5 * rng.gen::<f64>(), rng.gen()),
            0.002,
            rng.gen(),
        );
        let (outline, contacts) = with_roll_contacts(&scan, dense[0], &mut rng);
        let measured = section_parameters(&outline, &contacts, 2.0).unwrap();
        assert_eq!(measured.mean_line.trailing_end, measured.trailing_edge);
        errors.push(measured.mean_line.chord_angle_deg - truth.mean_line.chord_angle_deg);
    }
    // Over these 40 draws: RMS 0.81 mdeg, worst 1.48 (0.83 and 1.84 with the end followed out); on the simulated
    // propeller's 120 sections of eight seeds the worst chord angle error fell from 5.65 to 3.61 mdeg
    // (BENCHMARKS.md).
    let rms = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
    let worst = errors.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(
        rms < 0.001 && worst < 0.0016,
        "RMS {rms} deg, worst {worst} deg: {errors:?}"
    );
}

#[test]
fn a_round_nose_too_sparse_for_its_circle_is_not_taken_for_a_sharp_end() {
    // NACA 4412 of 150 mm (nose radius 2.4 mm) with a point only every 1.5 mm or 40 deg of turn: too few round the
    // nose for its circle, so no radius is read there. Its farthest point is not a corner: the mean line is still
    // followed out to the nose (its end 0.47 mm across the chord from the farthest point, which as the end would
    // turn the chord angle by 0.18 deg).
    let dense = naca_of_150_mm("4412");
    let truth = section_parameters(&dense, &[], 2.0).unwrap();
    for phase in [0.0, 0.25, 0.5, 0.75] {
        let scan = stepped_by(&dense, 1.5, phase, 40.0);
        let p = section_parameters(&scan, &[], 2.0).unwrap();
        assert_eq!(
            p.le_radius_mm, None,
            "phase {phase}: too sparse for a circle"
        );
        assert_ne!(p.mean_line.leading_end, p.leading_edge, "phase {phase}");
        let error = p.mean_line.chord_angle_deg - truth.mean_line.chord_angle_deg;
        assert!(
            error.abs() < 0.01,
            "phase {phase}: chord angle off by {error} deg"
        );
    }
    // The trailing edge is a corner however far apart the points beside it lie (a nominal outline thinned where it
    // is straight): the line ends there.
    let thinned: Vec<Vector2<f64>> = std::iter::once(dense[0])
        .chain(
            stepped_by(&dense, 0.5, 0.0, 5.0)
                .into_iter()
                .filter(|p| (p - dense[0]).norm() > 3.0),
        )
        .collect();
    let n = thinned.len();
    assert!((thinned[1] - thinned[0]).norm() > 3.0 && (thinned[n - 1] - thinned[0]).norm() > 3.0);
    let p = section_parameters(&thinned, &[], 2.0).unwrap();
    assert_eq!(p.trailing_edge, dense[0]);
    assert_eq!(p.mean_line.trailing_end, p.trailing_edge);
}

#[test]
fn a_noisy_scan_s_trailing_edge_thickness_is_read_from_its_faces_fitted_not_from_two_points() {
    // NACA 4412, 0012 and 6409 of 150 mm, scanned every 1 mm and 2.5 deg round the nose from a random phase with
    // 2 um of noise, the ball's 16 contacts rolling round the trailing edge named; 30 draws each. The thickness 2 mm
    // in from the trailing edge, against the dense outline's: each face crossed through the two points beside the
    // line carried their noise (2.6-2.7 um RMS, up to 7.6 um over 100 draws); each face's quadratic over the points
    // within 5 mm of the line averages it (1.4-1.5 um RMS, 4.1 um at worst over 100 draws). The leading-edge
    // thickness, where the face turns too fast for the quadratic, is read as before, as unbiased.
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(77);
    let (mut trailing, mut leading) = (Vec::new(), Vec::new());
    for digits in ["4412", "0012", "6409"] {
        let dense = naca_of_150_mm(digits);
        let truth = section_parameters(&dense, &[], 2.0).unwrap();
        for _ in 0..30 {
            let scan = noisy(&stepped_by(&dense, 1.0, rng.gen(), 2.5), 0.002, rng.gen());
            let (outline, contacts) = with_roll_contacts(&scan, dense[0], &mut rng);
            let measured = section_parameters(&outline, &contacts, 2.0).unwrap();
            trailing.push(measured.te_thickness_mm - truth.te_thickness_mm);
            leading.push(measured.le_thickness_mm - truth.le_thickness_mm);
        }
    }
    let rms = |v: &[f64]| (v.iter().map(|e| e * e).sum::<f64>() / v.len() as f64).sqrt();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let worst = |v: &[f64]| v.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert!(
        rms(&trailing) < 0.0018 && worst(&trailing) < 0.005,
        "trailing edge: RMS {} mm, worst {} mm",
        rms(&trailing),
        worst(&trailing)
    );
    assert!(
        mean(&leading).abs() < 0.001,
        "leading edge: mean {} mm",
        mean(&leading)
    );
}

#[test]
fn a_nose_s_radius_does_not_depend_on_where_the_scan_s_points_fall_round_it() {
    // NACA 4412 and 6409 of 150 mm stepped 1 mm and 2.5 deg round the nose from random phases, 20 draws each. The
    // leading edge's circle fitted to the scan's points read the noise-free noses 15-21 um narrower than their
    // dense outlines on average, with a spread of 17 um from the phase alone: a NACA nose is not a circle, and
    // which points fall in the zone, and how they crowd, moved it. Fitted to the smooth outline through the
    // points, sampled evenly: within 1 um without noise, and with 2 um of noise at the circle fit's own limit
    // over that arc (5 um RMS over 60 draws, within 1 um on average).
    use rand::{Rng, SeedableRng};
    let mut rng = rand::rngs::StdRng::seed_from_u64(5);
    for digits in ["4412", "6409"] {
        let dense = naca_of_150_mm(digits);
        let truth = section_parameters(&dense, &[], 2.0)
            .unwrap()
            .le_radius_mm
            .unwrap();
        let (mut clean, mut noisy_errors) = (Vec::new(), Vec::new());
        for draw in 0..20 {
            let scan = stepped_by(&dense, 1.0, rng.gen(), 2.5);
            let radius = |outline: &[Vector2<f64>]| {
                section_parameters(outline, &[], 2.0)
                    .unwrap()
                    .le_radius_mm
                    .unwrap()
                    - truth
            };
            clean.push(radius(&scan));
            noisy_errors.push(radius(&noisy(&scan, 0.002, draw)));
        }
        let worst = clean.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        assert!(worst < 0.001, "NACA {digits} without noise: {clean:?}");
        let mean = noisy_errors.iter().sum::<f64>() / noisy_errors.len() as f64;
        let rms =
            (noisy_errors.iter().map(|e| e * e).sum::<f64>() / noisy_errors.len() as f64).sqrt();
        assert!(
            mean.abs() < 0.003 && rms < 0.008,
            "NACA {digits} with noise: mean {mean}, RMS {rms}"
        );
    }
}
