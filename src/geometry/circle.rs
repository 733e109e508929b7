//! The circle nearest a set of points: Kasa's algebraic fit, and the geometric (orthogonal-distance) fit refined
//! from it by Gauss-Newton. The algebraic fit alone shrinks the radius on a short noisy arc (it weights each
//! point by its distance from the centre); an edge radius is judged in microns, so it is refined.

use nalgebra::{DMatrix, DVector, Matrix3, Vector2, Vector3};

/// Gauss-Newton steps at most; each converges quadratically from the algebraic start.
const MAX_STEPS: usize = 50;
/// A step shorter than this (mm) ends the refinement.
const STEP_TOLERANCE_MM: f64 = 1e-10;

/// A fitted circle, with the RMS of the points' distances from it (mm).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Circle {
    pub centre: Vector2<f64>,
    pub radius: f64,
    pub rms_mm: f64,
}

/// Kasa's fit: x^2 + y^2 + D x + E y + F = 0 in least squares; its centre (-D/2, -E/2).
pub(crate) fn algebraic_centre(points: &[Vector2<f64>]) -> Vector2<f64> {
    let rows = DMatrix::from_fn(points.len(), 3, |i, j| match j {
        0 => points[i].x,
        1 => points[i].y,
        _ => 1.0,
    });
    let rhs = DVector::from_fn(points.len(), |i, _| -points[i].norm_squared());
    let solution = rows
        .svd(true, true)
        .solve(&rhs, 1e-12)
        .expect("an SVD with both factors solves");
    Vector2::new(-solution[0] / 2.0, -solution[1] / 2.0)
}

/// The circle minimising the sum of squared distances |p - c| - r; `None` for fewer than three points or points
/// on a line (no finite circle).
pub(crate) fn fit_circle(points: &[Vector2<f64>]) -> Option<Circle> {
    if points.len() < 3 {
        return None;
    }
    // Centred on the points' mean, so that the fit is as well conditioned far from the origin as near it.
    let mean = points.iter().sum::<Vector2<f64>>() / points.len() as f64;
    let local: Vec<Vector2<f64>> = points.iter().map(|p| p - mean).collect();
    let mut centre = algebraic_centre(&local);
    let mean_radius =
        |c: &Vector2<f64>| local.iter().map(|p| (p - c).norm()).sum::<f64>() / local.len() as f64;
    let mut radius = mean_radius(&centre);
    if !radius.is_finite() {
        return None;
    }
    for _ in 0..MAX_STEPS {
        // Residual r_i = |p_i - c| - R; its gradient in (cx, cy, R) is (-(p_i - c)/|p_i - c|, -1).
        let mut normal = Matrix3::zeros();
        let mut rhs = Vector3::zeros();
        for p in &local {
            let d = p - centre;
            let length = d.norm();
            if length == 0.0 {
                continue;
            }
            let gradient = Vector3::new(-d.x / length, -d.y / length, -1.0);
            normal += gradient * gradient.transpose();
            rhs -= gradient * (length - radius);
        }
        let step = normal.lu().solve(&rhs)?;
        centre += Vector2::new(step.x, step.y);
        radius += step.z;
        if !(radius.is_finite() && centre.x.is_finite() && centre.y.is_finite()) {
            return None;
        }
        if step.norm() < STEP_TOLERANCE_MM {
            break;
        }
    }
    let rms_mm = (local
        .iter()
        .map(|p| ((p - centre).norm() - radius).powi(2))
        .sum::<f64>()
        / local.len() as f64)
        .sqrt();
    Some(Circle {
        centre: centre + mean,
        radius: radius.abs(),
        rms_mm,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An arc of radius 2.5 mm about (100, -40) from -50 to +50 deg, with a +-2 um alternating ripple.
    fn arc(count: usize, ripple_mm: f64) -> Vec<Vector2<f64>> {
        (0..count)
            .map(|k| {
                let angle = (-50.0 + 100.0 * k as f64 / (count - 1) as f64).to_radians();
                let r = 2.5 + if k % 2 == 0 { ripple_mm } else { -ripple_mm };
                Vector2::new(100.0, -40.0) + Vector2::new(angle.cos(), angle.sin()) * r
            })
            .collect()
    }

    #[test]
    fn an_exact_arc_fits_back_to_its_circle() {
        let circle = fit_circle(&arc(11, 0.0)).unwrap();
        assert!((circle.radius - 2.5).abs() < 1e-9, "{circle:?}");
        assert!(
            (circle.centre - Vector2::new(100.0, -40.0)).norm() < 1e-9,
            "{circle:?}"
        );
        assert!(circle.rms_mm < 1e-9);
    }

    /// A +-2 um ripple on a 100 deg arc moves the radius by less than the ripple and shows as the RMS.
    #[test]
    fn a_rippled_short_arc_keeps_its_radius_and_reports_the_ripple() {
        let circle = fit_circle(&arc(21, 0.002)).unwrap();
        assert!((circle.radius - 2.5).abs() < 0.002, "{circle:?}");
        assert!((circle.rms_mm - 0.002).abs() < 2e-4, "{circle:?}");
    }

    #[test]
    fn points_on_a_line_or_too_few_have_no_circle() {
        let line: Vec<_> = (0..5)
            .map(|k| Vector2::new(k as f64, 2.0 * k as f64))
            .collect();
        // No circle, or one so wide (over 1 000 times the points' extent) that no edge would be taken for it.
        let fitted = fit_circle(&line);
        assert!(fitted.is_none_or(|c| c.radius > 1e4), "{fitted:?}");
        assert_eq!(fit_circle(&line[..2]), None);
    }
}
