//! The least-squares problem of a recovery for the levenberg-marquardt crate: the residuals of seed 001 eq. 4
//! at every point, and their Jacobian from dual numbers (exact, one pass per point). It serves any model whose
//! residual is written once, generically over the number type: the supershape and its superquadric special case.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{Const, Point3, U1};
use nalgebra_lm::{storage::Owned, DMatrix, DVector, Dyn};
use num_dual::{DualNum, DualSVec64};

use super::model::{residual, Candidate, Radius, PARAMS};
use crate::geometry::supershape::differences::UNDEFINED;

/// A model's residual at one point as a function of its `N` parameters, for f64 and for dual numbers alike.
pub trait Residual<const N: usize> {
    fn residual<T>(&self, params: &[T; N], point: &Point3<f64>) -> T
    where
        T: DualNum<Primitive = f64> + Copy;
}

/// The supershape with one radius and frame (`model::residual`).
struct Supershape {
    candidate: Candidate,
    radius: Radius,
}

impl Residual<PARAMS> for Supershape {
    fn residual<T>(&self, params: &[T; PARAMS], point: &Point3<f64>) -> T
    where
        T: DualNum<Primitive = f64> + Copy,
    {
        residual(&self.candidate.frame, self.radius, params, point)
    }
}

/// Minimises a1 a2 a3 sum F2^2 over the candidate's parameters from where it stands, with the given radius and
/// at most `patience` x 16 evaluations. Returns the candidate reached and its cost (the sum of squares there), or
/// `None` when the cost is not finite there.
pub fn minimise(
    points: &[Point3<f64>],
    start: Candidate,
    radius: Radius,
    patience: usize,
) -> Option<(Candidate, f64)> {
    let model = Supershape {
        candidate: start,
        radius,
    };
    let (params, cost) = minimise_model(points, &model, start.params, patience)?;
    Some((
        Candidate {
            frame: start.frame,
            params,
        },
        cost,
    ))
}

/// Minimises the sum of a model's squared residuals from `start`, with at most `patience` x (N + 1)
/// evaluations; the parameters reached and the sum there, `None` when it is not finite.
pub fn minimise_model<M: Residual<N>, const N: usize>(
    points: &[Point3<f64>],
    model: &M,
    start: [f64; N],
    patience: usize,
) -> Option<([f64; N], f64)> {
    let problem = SquaredResiduals {
        points,
        model,
        at: start,
    };
    let (solved, _) = LevenbergMarquardt::new()
        .with_patience(patience)
        .minimize(problem);
    let cost: f64 = points
        .iter()
        .map(|p| model.residual(&solved.at, p).powi(2))
        .sum();
    cost.is_finite().then_some((solved.at, cost))
}

struct SquaredResiduals<'a, M, const N: usize> {
    points: &'a [Point3<f64>],
    model: &'a M,
    at: [f64; N],
}

impl<M: Residual<N>, const N: usize> LeastSquaresProblem<f64, Dyn, Dyn>
    for SquaredResiduals<'_, M, N>
{
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.at.copy_from_slice(x.as_slice());
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_column_slice(&self.at)
    }

    /// A residual that is not finite (a trial step into exponents where the radius overflows) counts as
    /// `UNDEFINED`, so that the crate rejects the step and stays where it was; given no residuals at all it
    /// would stop at the failed trial.
    fn residuals(&self) -> Option<DVector<f64>> {
        Some(DVector::from_iterator(
            self.points.len(),
            self.points.iter().map(|p| {
                let value = self.model.residual(&self.at, p);
                if value.is_finite() {
                    value
                } else {
                    UNDEFINED
                }
            }),
        ))
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let duals: [DualSVec64<N>; N] =
            std::array::from_fn(|j| DualSVec64::from_re(self.at[j]).derivative(j));
        let mut jacobian = DMatrix::zeros(self.points.len(), N);
        for (i, p) in self.points.iter().enumerate() {
            let value = self.model.residual(&duals, p);
            let row = value.eps.unwrap_generic(Const::<N>, U1);
            for j in 0..N {
                if !row[j].is_finite() {
                    return None;
                }
                jacobian[(i, j)] = row[j];
            }
        }
        Some(jacobian)
    }
}
