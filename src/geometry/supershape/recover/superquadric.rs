//! The superquadric special case of the recovery: m1 = m2 = 4 and each superformula's three exponents equal, so
//! that r1 and r2 are superellipses (n = 2 / epsilon2 across the axis, 2 / epsilon1 along it) and the supershape
//! is the superquadric ((|x|^(2/e2) + |y|^(2/e2))^(e2/e1) + |z|^(2/e1) = 1 (EMS's family, the issue's
//! yardstick). Eleven parameters instead of fifteen, and a radial function in closed form: the surface point on
//! the ray through q is q / N(q), N the superquadric's norm (homogeneous of degree one), so seed 001's
//! F2 = 1 - |q| / |I| is 1 - N(q), without eq. 8's angles or the superformula's powers of sines and cosines.
//!
//! The cost has a local minimum for each way of laying the superquadric's axes on the points' (which inertia
//! axis is z, and a turn of pi / 4 about it, where a square section and a round one have the same inertia), so
//! every inertia axis with both its turns is a start: six short minimisations on a subsample, the best refined on
//! every point.

use nalgebra::{Point3, Rotation3};
use num_dual::DualNum;
use rayon::prelude::*;

use super::model::{self, Candidate, Frame, PARAMS, SMALLEST_EXPONENT};
use super::problem::{minimise_model, Residual};
use super::{
    evenly, extent_in, rms_radial, symmetry, Fitted, RecoveryError, SymmetrySource, EARLY_POINTS,
    STANDARD_PATIENCE,
};

/// Centre (3), turn from the start frame as a Gibbs vector (3), logarithms of the sizes (3), and the exponents
/// across and along the axis as l with n = `SMALLEST_EXPONENT` + exp(l): the supershape's parameters with r1's
/// three exponents tied to one value and r2's three to another.
const SUPERQUADRIC_PARAMS: usize = 11;
/// The starts' exponents: n = 2 (an ellipsoid, epsilon = 1, as Solina and Bajcsy start).
const START_EXPONENT: f64 = 2.0;
/// The evaluation budget of a start on the subsample, in the crate's units (x 12 evaluations).
const START_PATIENCE: usize = 10;
/// The symmetry numbers of a superquadric.
pub(super) const SYMMETRY: [u32; 2] = [4, 4];

/// The radial residual of a superquadric laid on `start`.
struct Superquadric {
    start: Rotation3<f64>,
}

impl Residual<SUPERQUADRIC_PARAMS> for Superquadric {
    /// sqrt(a1 a2 a3) (1 - N(q)): seed 001 eq. 4's residual, as the supershape's.
    fn residual<T>(&self, p: &[T; SUPERQUADRIC_PARAMS], point: &Point3<f64>) -> T
    where
        T: DualNum<Primitive = f64> + Copy,
    {
        let q = model::canonical(&self.start, p, point);
        let [across, along] = [p[9], p[10]].map(|l| l.exp() + SMALLEST_EXPONENT);
        let section = power_norm(q[0].abs(), q[1].abs(), across);
        let norm = power_norm(section, q[2].abs(), along);
        ((p[6] + p[7] + p[8]) * 0.5).exp() * (-norm + 1.0)
    }
}

/// (u^n + v^n)^(1/n) for u, v >= 0, the larger factored out so that no power overflows whatever n.
fn power_norm<T>(u: T, v: T, n: T) -> T
where
    T: DualNum<Primitive = f64> + Copy,
{
    let (large, small) = if u.re() >= v.re() { (u, v) } else { (v, u) };
    if small.re() == 0.0 {
        // Also the centre (both 0): ln 0 would make the derivatives NaN where the value is plain.
        return large;
    }
    let ratio = small / large;
    large * ((ratio.ln() * n).exp().ln_1p() / n).exp()
}

/// A superquadric's parameters as the supershape candidate they are.
fn candidate(start: Rotation3<f64>, p: &[f64; SUPERQUADRIC_PARAMS]) -> Candidate {
    let mut params = [0.0; PARAMS];
    params[..9].copy_from_slice(&p[..9]);
    params[9..12].fill(p[9]);
    params[12..].fill(p[10]);
    Candidate {
        frame: Frame {
            symmetry: SYMMETRY,
            start,
        },
        params,
    }
}

/// The superquadric parameters of a candidate that is one (`candidate`'s inverse).
fn parameters(candidate: &Candidate) -> [f64; SUPERQUADRIC_PARAMS] {
    let p = &candidate.params;
    std::array::from_fn(|k| match k {
        0..=8 => p[k],
        9 => p[9],
        _ => p[12],
    })
}

/// A start on the frame `start`: centre and half sizes from the points' extent along its axes, an ellipsoid.
fn start_on(points: &[Point3<f64>], start: Rotation3<f64>) -> [f64; SUPERQUADRIC_PARAMS] {
    let (low, high) = extent_in(points, &start);
    let centre = start * ((low + high) / 2.0);
    let half = (high - low) / 2.0;
    let l = model::exponent_parameter(START_EXPONENT);
    [
        centre.x,
        centre.y,
        centre.z,
        0.0,
        0.0,
        0.0,
        half.x.ln(),
        half.y.ln(),
        half.z.ln(),
        l,
        l,
    ]
}

/// One superquadric fitted to normalised points: each inertia axis as z with both its turns (`symmetry`'s
/// guesses), minimised briefly on a subsample, the one nearest its points (by RMS radial distance, not the cost:
/// eq. 4's volume term has a degenerate minimum) refined on every point.
pub(super) fn fit(points: &[Point3<f64>]) -> Result<Fitted, RecoveryError> {
    let early = evenly(points, EARLY_POINTS);
    let frames: Vec<Rotation3<f64>> = symmetry::guesses(points, Some(SYMMETRY))
        .into_iter()
        .flat_map(|guess| guess.starts)
        .collect();
    let count = frames.len();
    let (_, start, reached) = frames
        .into_par_iter()
        .filter_map(|start| {
            let (reached, _) = minimise_model(
                &early,
                &Superquadric { start },
                start_on(points, start),
                START_PATIENCE,
            )?;
            let distance = rms_radial(&candidate(start, &reached), &early);
            distance.is_finite().then_some((distance, start, reached))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or(RecoveryError::NoConvergence { starts: count })?;
    let candidate = refine(points, &candidate(start, &reached))
        .ok_or(RecoveryError::NoConvergence { starts: count })?;
    Ok(Fitted {
        candidate,
        starts: count,
        source: [SymmetrySource::Given; 2],
    })
}

/// A superquadric candidate minimised on `points` from where it stands, still a superquadric.
pub(super) fn refine(points: &[Point3<f64>], from: &Candidate) -> Option<Candidate> {
    let model = Superquadric {
        start: from.frame.start,
    };
    let (reached, _) = minimise_model(points, &model, parameters(from), STANDARD_PATIENCE)?;
    Some(candidate(from.frame.start, &reached))
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Const;
    use num_dual::DualSVec64;

    fn start() -> Rotation3<f64> {
        Rotation3::from_euler_angles(0.3, -0.2, 0.9)
    }

    fn params() -> [f64; SUPERQUADRIC_PARAMS] {
        [
            0.1,
            -0.2,
            0.05,
            0.1,
            -0.3,
            0.2,
            0.9f64.ln(),
            0.6f64.ln(),
            0.4f64.ln(),
            model::exponent_parameter(5.0),
            model::exponent_parameter(1.3),
        ]
    }

    fn points() -> Vec<Point3<f64>> {
        (0..300)
            .map(|k| {
                let t = k as f64 * 0.37;
                Point3::new(1.1 * t.sin(), 0.8 * (1.3 * t).cos(), 0.6 * (0.7 * t).sin())
            })
            .collect()
    }

    /// The centre and points on the canonical axes, where coordinates of q are exactly 0 (the norm's kinks).
    fn special_points() -> Vec<Point3<f64>> {
        let p = params();
        let rotation = candidate(start(), &p).rotation();
        let centre = Point3::new(p[0], p[1], p[2]);
        let a = [p[6].exp(), p[7].exp(), p[8].exp()];
        [[0.0; 3], [0.0, 0.0, 0.3], [0.5, 0.0, 0.0], [0.0, -1.4, 0.0]]
            .iter()
            .map(|t| {
                centre + rotation * nalgebra::Vector3::new(t[0] * a[0], t[1] * a[1], t[2] * a[2])
            })
            .collect()
    }

    /// The closed form is the supershape's own residual (seed 001 eqs. 3 and 8 through the superformula) at
    /// the tied parameters, inside, outside and on the axis.
    #[test]
    fn the_closed_form_is_the_supershapes_radial_residual() {
        let p = params();
        let model = Superquadric { start: start() };
        let tied = candidate(start(), &p);
        for point in points().into_iter().chain(special_points()) {
            let mine = model.residual(&p, &point);
            let theirs =
                model::residual(&tied.frame, model::Radius::Standard, &tied.params, &point);
            assert!(
                (mine - theirs).abs() < 1e-9,
                "{mine} vs {theirs} at {point}"
            );
        }
        assert_eq!(parameters(&tied), p);
    }

    /// The dual numbers' Jacobian of the closed form matches central differences in every parameter, and is
    /// finite at the centre and on the axes, where the norm has kinks (a NaN there would stop the solver).
    #[test]
    fn dual_jacobians_match_central_differences() {
        let p = params();
        let model = Superquadric { start: start() };
        let duals: [DualSVec64<SUPERQUADRIC_PARAMS>; SUPERQUADRIC_PARAMS] =
            std::array::from_fn(|j| DualSVec64::from_re(p[j]).derivative(j));
        for point in &special_points() {
            let gradient = model.residual(&duals, point).eps;
            assert!(
                gradient
                    .unwrap_generic(Const::<SUPERQUADRIC_PARAMS>, Const::<1>)
                    .iter()
                    .all(|g| g.is_finite()),
                "{point}"
            );
        }
        for point in &points() {
            let gradient = model
                .residual(&duals, point)
                .eps
                .unwrap_generic(Const::<SUPERQUADRIC_PARAMS>, Const::<1>);
            for j in 0..SUPERQUADRIC_PARAMS {
                let h = 1e-6;
                let (mut up, mut down) = (p, p);
                up[j] += h;
                down[j] -= h;
                let numeric =
                    (model.residual(&up, point) - model.residual(&down, point)) / (2.0 * h);
                assert!(
                    (gradient[j] - numeric).abs() < 1e-5 * (1.0 + numeric.abs()),
                    "parameter {j} at {point}: {} vs {numeric}",
                    gradient[j]
                );
            }
        }
    }
}
