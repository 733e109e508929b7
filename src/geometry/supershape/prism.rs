//! A superformula prism fitted to parallel section scans: the model of an extruded part (a nut, a gear)
//! whose profiles are planar sections across its axis.
//!
//! Why not the general recovery: section scans touch only the side walls, so a full supershape's
//! second superformula (the shape along the axis) is not determined by them. A prism is: its cross
//! section is one superformula r1 (seed 000 eq. 4) of the in-plane coordinates, the same at every
//! section, and along the axis it is straight. As a supershape it is r1 with a square r2 of very high
//! exponents (seed 000 eq. 5: for |phi| < pi/4, r2 cos phi = 1, so the side wall is exactly
//! rho = r1(theta)), so the station's exact distance and meshes treat it like any other supershape.
//!
//! The fit: Levenberg-Marquardt (the levenberg-marquardt crate) on the radial residual in mm,
//! |q - c| - s r1(theta - psi), over the centre c, the turn psi, the size s and the exponents n1, n2,
//! n3 (logarithms, so they stay positive); a = b = 1 (s carries the size). The symmetry number m is
//! given or found as the dominant harmonic of the radius about the centroid. Several starts (turns over
//! one period, a few exponent sets) and the smallest cost wins, since the radial cost has local minima
//! at turns of half a lobe.

use std::f64::consts::TAU;

use nalgebra::{Isometry3, Matrix3, Point2, Rotation3, Translation3, UnitQuaternion};

use super::deform::{Deformation, Deformations};
use super::differences;
use super::formula::{Superformula, SuperformulaError};
use super::lobes;
use super::shape::Supershape;

/// The exponents of the square r2 that makes a supershape a prism: the side wall is rho = r1 to within
/// r1 tan(phi)^n / n, below 1e-20 of the size over the middle 80% of the height.
const SQUARE_EXPONENT: f64 = 200.0;
/// The square r2 of a prism.
pub(super) const SQUARE: Superformula = Superformula {
    m: 4.0,
    n1: SQUARE_EXPONENT,
    n2: SQUARE_EXPONENT,
    n3: SQUARE_EXPONENT,
    a: 1.0,
    b: 1.0,
};
/// Symmetry numbers tried when none is given.
const SYMMETRIES: std::ops::RangeInclusive<usize> = 2..=12;
/// Fewer points than this cannot fix seven parameters against a machine's noise.
const MIN_POINTS: usize = 30;

/// Why a prism could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PrismFitError {
    #[error("{got} points cannot fit a superformula prism; scan at least {MIN_POINTS} points over the profiles")]
    TooFewPoints { got: usize },
    #[error("the points show no repeating lobes (no symmetry number from 2 to 12 stands out); give the part's symmetry in its config")]
    NoSymmetry,
    #[error("the fit did not converge from any start (best RMS {rms_mm:.4} mm over {points} points); check that the scans are of this part")]
    NoConvergence { rms_mm: f64, points: usize },
    #[error(transparent)]
    Parameter(#[from] SuperformulaError),
}

/// A fitted cross section: the superformula, its centre, turn and size in the section plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PrismSection {
    pub formula: Superformula,
    pub centre: Point2<f64>,
    /// Turn of the outline about its centre, radians.
    pub turn: f64,
    /// The outline's scale, mm (a = b = 1).
    pub size_mm: f64,
    /// RMS of the radial residuals at the solution, mm.
    pub rms_mm: f64,
}

impl PrismSection {
    /// The outline's radius (mm) at polar angle `theta` about its centre, in the section plane.
    pub fn radius(&self, theta: f64) -> f64 {
        self.size_mm * self.formula.radius(theta - self.turn)
    }

    /// The prism as a supershape placed in the part frame: its axis along the part's x between `x_range`
    /// (mm), the section plane's coordinates (u, v) being the part's (y, z).
    pub fn supershape(&self, x_range: (f64, f64)) -> (Supershape, Deformations) {
        let half_height = (x_range.1 - x_range.0) / 2.0;
        let shape = Supershape {
            r1: self.formula,
            r2: SQUARE,
            scale: [self.size_mm, self.size_mm, half_height],
        };
        // Canonical x, y (turned by `turn`) -> part y, z; canonical z -> part x.
        let (sin, cos) = self.turn.sin_cos();
        let axes = Matrix3::new(0.0, 0.0, 1.0, cos, -sin, 0.0, sin, cos, 0.0);
        let rotation =
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(axes));
        let place = Isometry3::from_parts(
            Translation3::new(x_range.0 + half_height, self.centre.x, self.centre.y),
            rotation,
        );
        (shape, Deformations(vec![Deformation::Rigid(place)]))
    }
}

/// Fits the cross section to points of parallel sections given in their plane's coordinates.
/// `symmetry`: the number of lobes when known (a hex nut: 6), else found from the points. Starts from six turns
/// over one period, each with four exponent sets.
pub fn fit_prism_section(
    points: &[Point2<f64>],
    symmetry: Option<usize>,
) -> Result<PrismSection, PrismFitError> {
    if points.len() < MIN_POINTS {
        return Err(PrismFitError::TooFewPoints { got: points.len() });
    }
    let centroid = lobes::circle_centre(points);
    let m = match symmetry {
        Some(m) => m,
        None => dominant_harmonic(points, &centroid).ok_or(PrismFitError::NoSymmetry)?,
    };
    let period = TAU / m as f64;
    let turns: Vec<f64> = (0..6).map(|k| period * k as f64 / 6.0).collect();
    fit_from(
        points,
        m,
        &centroid,
        &turns,
        &[(2.0, 2.0), (4.0, 4.0), (8.0, 4.0), (1.0, 1.0)],
    )
}

/// The same fit from the given turns only (radians, where a lobe's maximum is expected), each with a pinched and
/// a boxy exponent set: for a caller that has read the outline's phase already (the 3-D recovery's starts).
pub fn fit_prism_section_from_turns(
    points: &[Point2<f64>],
    m: usize,
    turns: &[f64],
) -> Result<PrismSection, PrismFitError> {
    if points.len() < MIN_POINTS {
        return Err(PrismFitError::TooFewPoints { got: points.len() });
    }
    let centroid = lobes::circle_centre(points);
    fit_from(points, m, &centroid, turns, &[(1.2, 1.2), (4.0, 4.0)])
}

/// Levenberg-Marquardt from every turn with every (n1, n2 = n3) start, the smallest cost kept.
fn fit_from(
    points: &[Point2<f64>],
    m: usize,
    centroid: &Point2<f64>,
    turns: &[f64],
    exponents: &[(f64, f64)],
) -> Result<PrismSection, PrismFitError> {
    let mean_radius =
        points.iter().map(|p| (p - centroid).norm()).sum::<f64>() / points.len() as f64;
    let period = TAU / m as f64;
    let mut best: Option<(f64, [f64; 7])> = None;
    for &turn in turns {
        for &(n1, n23) in exponents {
            let start = [
                centroid.x,
                centroid.y,
                turn,
                f64::ln(mean_radius),
                f64::ln(n1),
                f64::ln(n23),
                f64::ln(n23),
            ];
            let (solved, cost) =
                differences::minimise(start, |p| radial_residuals(points, m as f64, p));
            if cost.is_finite() && best.is_none_or(|(b, _)| cost < b) {
                best = Some((cost, solved));
            }
        }
    }
    let (cost, p) = best.expect("at least one start ran");
    let rms_mm = (2.0 * cost / points.len() as f64).sqrt();
    let formula = Superformula::new(m as f64, p[4].exp(), p[5].exp(), p[6].exp(), 1.0, 1.0)?;
    let section = PrismSection {
        formula,
        centre: Point2::new(p[0], p[1]),
        // A turn by 2 pi / m swaps the cosine and sine terms of eq. 4, so with n2 != n3 the outline repeats only
        // every 4 pi / m.
        turn: p[2].rem_euclid(2.0 * period),
        size_mm: p[3].exp(),
        rms_mm,
    };
    // A fit that misses by a tenth of the part's size has not found the outline.
    if !(rms_mm.is_finite() && rms_mm < 0.1 * section.size_mm) {
        return Err(PrismFitError::NoConvergence {
            rms_mm,
            points: points.len(),
        });
    }
    Ok(section)
}

/// The number of lobes of the outline: the strongest harmonic, if it stands out of a round outline's noise.
fn dominant_harmonic(points: &[Point2<f64>], centroid: &Point2<f64>) -> Option<usize> {
    let lobes = lobes::strongest(points, centroid, SYMMETRIES)?;
    // A lobed outline's first harmonic stands well above the noise of a round one.
    (lobes.strength > 2e-4).then_some(lobes.count)
}

/// The radial residuals of the section fit, |q - c| - s r1(theta - psi) in mm, at the parameters
/// [cx, cy, turn, ln size, ln n1, ln n2, ln n3] (a = b = 1). Its Jacobian is taken by central differences:
/// seven parameters, and the exponents' partials of eq. 4 in closed form would add a page of code for no
/// measurable gain in a fit made once per teach.
fn radial_residuals(points: &[Point2<f64>], m: f64, p: &[f64; 7]) -> Option<Vec<f64>> {
    let formula = Superformula {
        m,
        n1: p[4].exp(),
        n2: p[5].exp(),
        n3: p[6].exp(),
        a: 1.0,
        b: 1.0,
    };
    let size = p[3].exp();
    let residuals: Vec<f64> = points
        .iter()
        .map(|q| {
            let (dx, dy) = (q.x - p[0], q.y - p[1]);
            dx.hypot(dy) - size * formula.radius(dy.atan2(dx) - p[2])
        })
        .collect();
    residuals.iter().all(|r| r.is_finite()).then_some(residuals)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;
    use rand::{Rng, SeedableRng};
    use rand_distr::{Distribution, Normal};

    /// The simulator's nut outline (config/sims/nut.toml): m = 6, n1 = 8, n2 = n3 = 4, 40 mm, made
    /// 0.2% oversize and turned 0.5 degrees, here also off centre.
    fn nut() -> PrismSection {
        PrismSection {
            formula: Superformula::new(6.0, 8.0, 4.0, 4.0, 1.0, 1.0).unwrap(),
            centre: Point2::new(1.5, -2.0),
            turn: 0.5f64.to_radians(),
            size_mm: 40.0 * 1.002,
            rms_mm: 0.0,
        }
    }

    fn outline(truth: &PrismSection, count: usize, noise_mm: f64, seed: u64) -> Vec<Point2<f64>> {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let noise = Normal::new(0.0, noise_mm.max(1e-300)).unwrap();
        (0..count)
            .map(|_| {
                let theta: f64 = rng.gen_range(-std::f64::consts::PI..std::f64::consts::PI);
                let r = truth.radius(theta)
                    + if noise_mm > 0.0 {
                        noise.sample(&mut rng)
                    } else {
                        0.0
                    };
                truth.centre + nalgebra::Vector2::new(theta.cos(), theta.sin()) * r
            })
            .collect()
    }

    #[test]
    fn a_noise_free_outline_is_recovered_exactly() {
        let truth = nut();
        let fitted = fit_prism_section(&outline(&truth, 400, 0.0, 1), None).unwrap();
        assert_eq!(fitted.formula.m, 6.0);
        assert!(fitted.rms_mm < 1e-9, "{fitted:?}");
        for k in 0..360 {
            let theta = (k as f64).to_radians();
            assert!(
                (fitted.radius(theta) - truth.radius(theta)).abs() < 1e-8,
                "at {k} degrees: {fitted:?}"
            );
        }
    }

    #[test]
    fn with_two_microns_of_noise_the_outline_stays_within_half_a_micron() {
        let truth = nut();
        let fitted = fit_prism_section(&outline(&truth, 900, 0.002, 2), Some(6)).unwrap();
        assert!((fitted.rms_mm - 0.002).abs() < 3e-4, "{fitted:?}");
        let worst = (0..360)
            .map(|k| {
                (fitted.radius((k as f64).to_radians()) - truth.radius((k as f64).to_radians()))
                    .abs()
            })
            .fold(0.0, f64::max);
        assert!(worst < 5e-4, "worst radius error {worst} mm");
    }

    #[test]
    fn the_symmetry_number_is_found() {
        for m in [3.0, 5.0, 8.0] {
            let truth = PrismSection {
                formula: Superformula::new(m, 3.0, 6.0, 6.0, 1.0, 1.0).unwrap(),
                ..nut()
            };
            let fitted = fit_prism_section(&outline(&truth, 500, 0.002, 3), None).unwrap();
            assert_eq!(fitted.formula.m, m, "{fitted:?}");
        }
        let round = PrismSection {
            formula: Superformula::circle(),
            ..nut()
        };
        assert_eq!(
            fit_prism_section(&outline(&round, 500, 0.0, 4), None),
            Err(PrismFitError::NoSymmetry)
        );
    }

    #[test]
    fn the_placed_supershape_has_the_outline_as_its_side_wall() {
        let truth = nut();
        let (shape, place) = truth.supershape((2.0, 27.0));
        for k in 0..72 {
            let theta = (k as f64 * 5.0).to_radians();
            let r = truth.radius(theta);
            for x in [4.5, 14.5, 24.5] {
                let on_wall = Point3::new(
                    x,
                    truth.centre.x + r * theta.cos(),
                    truth.centre.y + r * theta.sin(),
                );
                let radial = shape.radial(&place.inverse(&on_wall));
                assert!(radial.abs() < 1e-12, "x {x}, {k}: {radial}");
            }
        }
        // Beyond the ends along the axis, outside.
        let beyond = Point3::new(28.0, truth.centre.x, truth.centre.y);
        assert!(shape.radial(&place.inverse(&beyond)) < 0.0);
    }

    #[test]
    fn too_few_points_are_refused() {
        assert_eq!(
            fit_prism_section(&outline(&nut(), 10, 0.0, 5), Some(6)),
            Err(PrismFitError::TooFewPoints { got: 10 })
        );
    }
}
