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
        let p = section_parameters(&outline, 2.0).unwrap();
        assert!((p.chord_mm - 100.0).abs() < 1e-9, "{}", p.chord_mm);
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
    let p = section_parameters(&outline, 5.0).unwrap();
    assert!((p.chord_mm - 100.0).abs() < 1e-6, "{}", p.chord_mm);
    // The nose is the blunt end: the leading edge, at the moved origin.
    assert!(
        (p.leading_edge - Vector2::new(0.0, 250.0)).norm() < 1e-6,
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
    let nominal = section_parameters(&section, 5.0).unwrap();
    let thinned: Vec<Vector2<f64>> = section
        .iter()
        .map(|p| Vector2::new(p.x, 0.99 * p.y))
        .collect();
    let thinner = section_parameters(&thinned, 5.0).unwrap();
    let ratio = thinner.max_thickness_mm / nominal.max_thickness_mm;
    assert!((ratio - 0.99).abs() < 2e-4, "{ratio}");
    assert!((thinner.chord_mm - nominal.chord_mm).abs() < 1e-3);
}

#[test]
fn an_outline_that_is_not_a_section_is_refused_saying_why() {
    assert_eq!(
        section_parameters(&ellipse(5.0, 1.0, 3), 1.0),
        Err(ParameterError::TooFewPoints(3))
    );
    // Edge thickness asked farther in than the chord is long.
    let error = section_parameters(&ellipse(5.0, 1.0, 100), 20.0).unwrap_err();
    assert!(
        error.to_string().contains("from its leading edge"),
        "{error}"
    );
}
