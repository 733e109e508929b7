//! The least-squares problem of one supershape's recovery for the levenberg-marquardt crate: the residuals of
//! seed 001 eq. 4 at every point, and their Jacobian from dual numbers (exact, one pass per point).

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{Const, Point3, U1};
use nalgebra_lm::{storage::Owned, DMatrix, DVector, Dyn};
use num_dual::DualSVec64;

use super::model::{residual, Candidate, Radius, PARAMS};
use crate::geometry::supershape::differences::UNDEFINED;

/// Minimises a1 a2 a3 sum F2^2 over the candidate's parameters from where it stands, with the given radius and
/// at most `patience` x 16 evaluations. Returns the candidate reached and its cost (the sum of squares there), or
/// `None` when the cost is not finite there.
pub fn minimise(
    points: &[Point3<f64>],
    start: Candidate,
    radius: Radius,
    patience: usize,
) -> Option<(Candidate, f64)> {
    let problem = RadialCost {
        points,
        radius,
        at: start,
    };
    let (solved, _) = LevenbergMarquardt::new()
        .with_patience(patience)
        .minimize(problem);
    let cost: f64 = points
        .iter()
        .map(|p| residual(&solved.at.frame, radius, &solved.at.params, p).powi(2))
        .sum();
    cost.is_finite().then_some((solved.at, cost))
}

struct RadialCost<'a> {
    points: &'a [Point3<f64>],
    radius: Radius,
    at: Candidate,
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for RadialCost<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.at.params.copy_from_slice(x.as_slice());
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_column_slice(&self.at.params)
    }

    /// A residual that is not finite (a trial step into exponents where the radius overflows) counts as
    /// `UNDEFINED`, so that the crate rejects the step and stays where it was; given no residuals at all it
    /// would stop at the failed trial.
    fn residuals(&self) -> Option<DVector<f64>> {
        Some(DVector::from_iterator(
            self.points.len(),
            self.points.iter().map(|p| {
                let value = residual(&self.at.frame, self.radius, &self.at.params, p);
                if value.is_finite() {
                    value
                } else {
                    UNDEFINED
                }
            }),
        ))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let duals: [DualSVec64<PARAMS>; PARAMS] =
            std::array::from_fn(|j| DualSVec64::from_re(self.at.params[j]).derivative(j));
        let mut jacobian = DMatrix::zeros(self.points.len(), PARAMS);
        for (i, p) in self.points.iter().enumerate() {
            let value = residual(&self.at.frame, self.radius, &duals, p);
            let row = value.eps.unwrap_generic(Const::<PARAMS>, U1);
            for j in 0..PARAMS {
                if !row[j].is_finite() {
                    return None;
                }
                jacobian[(i, j)] = row[j];
            }
        }
        Some(jacobian)
    }
}
