//! Levenberg-Marquardt (the levenberg-marquardt crate) over a fixed number of parameters with the Jacobian by
//! central differences, for the fits whose residuals are not generic over dual numbers (a section's superformula,
//! a pose against a CSG tree) and have few parameters.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra_lm::{storage::Owned, DMatrix, DVector, Dyn};

/// Minimises the sum of squares of `residuals` from `start`; returns the parameters reached and half the sum of
/// squares there (the crate's objective), infinite when the residuals are not defined there.
pub fn minimise<const P: usize>(
    start: [f64; P],
    residuals: impl Fn(&[f64; P]) -> Option<Vec<f64>>,
) -> ([f64; P], f64) {
    let Some(rows) = residuals(&start).map(|r| r.len()) else {
        return (start, f64::INFINITY);
    };
    let (solved, _) = LevenbergMarquardt::new().minimize(Problem {
        params: start,
        rows,
        residuals,
    });
    let objective = (solved.residuals)(&solved.params)
        .map(|r| r.iter().map(|v| v * v).sum::<f64>() / 2.0)
        .filter(|o| o.is_finite())
        .unwrap_or(f64::INFINITY);
    (solved.params, objective)
}

/// The stand-in for a residual that is not defined at a trial step: the crate then rejects the step and stays
/// where it was (given no residuals it would stop at the failed trial). Far above any residual of these fits near
/// their solution.
pub const UNDEFINED: f64 = 1e6;

struct Problem<const P: usize, F> {
    params: [f64; P],
    rows: usize,
    residuals: F,
}

impl<const P: usize, F: Fn(&[f64; P]) -> Option<Vec<f64>>> LeastSquaresProblem<f64, Dyn, Dyn>
    for Problem<P, F>
{
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.params.copy_from_slice(x.as_slice());
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_column_slice(&self.params)
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let values = (self.residuals)(&self.params)
            .filter(|r| r.len() == self.rows)
            .unwrap_or_else(|| vec![UNDEFINED; self.rows]);
        Some(DVector::from_iterator(
            self.rows,
            values
                .into_iter()
                .map(|v| if v.is_finite() { v } else { UNDEFINED }),
        ))
    }

    /// Each column by a central difference of step 1e-7 (1 + |parameter|).
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let mut columns = Vec::with_capacity(P);
        for j in 0..P {
            let h = 1e-7 * (1.0 + self.params[j].abs());
            let (mut plus, mut minus) = (self.params, self.params);
            plus[j] += h;
            minus[j] -= h;
            let (up, down) = ((self.residuals)(&plus)?, (self.residuals)(&minus)?);
            columns.push(
                up.iter()
                    .zip(&down)
                    .map(|(u, d)| (u - d) / (2.0 * h))
                    .collect::<Vec<f64>>(),
            );
        }
        let rows = columns.first().map_or(0, Vec::len);
        Some(DMatrix::from_fn(rows, P, |i, j| columns[j][i]))
    }
}
