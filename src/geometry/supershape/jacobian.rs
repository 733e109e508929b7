//! Jacobians by central differences for the levenberg-marquardt crate, for the fits whose residuals are not generic
//! over dual numbers (a section's superformula, a pose against a CSG tree) and have few parameters.

use nalgebra_lm::DMatrix;

/// The Jacobian of `residuals` (one row per residual, one column per parameter) at `params`, each column by a
/// central difference of step 1e-7 (1 + |parameter|). `None` when the residuals are not defined at a step.
pub fn central_differences<const P: usize>(
    params: &[f64; P],
    residuals: impl Fn(&[f64; P]) -> Option<Vec<f64>>,
) -> Option<DMatrix<f64>> {
    let mut columns = Vec::with_capacity(P);
    for j in 0..P {
        let h = 1e-7 * (1.0 + params[j].abs());
        let (mut plus, mut minus) = (*params, *params);
        plus[j] += h;
        minus[j] -= h;
        let (up, down) = (residuals(&plus)?, residuals(&minus)?);
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
