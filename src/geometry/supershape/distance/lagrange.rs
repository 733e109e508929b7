//! The orthogonality conditions of the nearest point, solved by Newton's method. For a point `p` and
//! K surfaces g_1 .. g_K (K = 1: a smooth patch, K = 2: an intersection curve), the nearest point x
//! on their common zero set is a stationary point of |x - p|^2 / 2 + sum_i lambda_i g_i(x):
//!
//!   x - p + sum_i lambda_i grad g_i(x) = 0,   g_i(x) = 0,
//!
//! i.e. p - x lies in the span of the surfaces' normals at x. Newton on these 3 + K equations uses
//! the full Jacobian [[I + sum_i lambda_i H_i, G], [G^T, 0]] (H_i the Hessians, G = [grad g_i]),
//! so it converges quadratically even far from the surface, where the first-order (Gauss-Newton)
//! iteration contracts only by a factor distance x curvature and diverges past the focal distance.
//! For K = 3 (a vertex) the point is fixed by the constraints alone.

use nalgebra::{Const, DimMin, Matrix3, Point3, SMatrix, SVector, Vector3};

/// Smooth constraint surfaces by index: a value (zero on the surface), its gradient and Hessian.
pub(super) trait Surfaces {
    fn value_and_gradient(&self, s: usize, x: &Point3<f64>) -> (f64, Vector3<f64>);
    fn hessian(&self, s: usize, x: &Point3<f64>, gradient: &Vector3<f64>) -> Matrix3<f64>;
}

const MAX_ITERATIONS: usize = 40;
/// Converged when Newton's step is below this (mm). Newton's next step would be of its square.
const STEP_TOLERANCE: f64 = 1e-10;
/// And the constraints' values, divided by their gradients' norms (a length in mm), below this.
const ON_SURFACE_TOLERANCE: f64 = 1e-10;
/// Below this step (mm) the Hessians are not recomputed: over a micrometre they change by a relative
/// 1e-3 / (radius of curvature in mm), which leaves the convergence all but quadratic.
const HESSIAN_REUSE: f64 = 1e-3;

/// The nearest point to `p` on the common zero set of `surfaces`, by Newton from `seed` (a point on
/// or near that set). `max_step` bounds each move (mm), so that a step from a poor seed cannot jump
/// to a far branch. `None` if Newton does not converge.
pub(super) fn nearest_on<const K: usize, const D: usize>(
    model: &impl Surfaces,
    surfaces: [usize; K],
    p: &Point3<f64>,
    seed: &Point3<f64>,
    max_step: f64,
) -> Option<Point3<f64>>
where
    Const<K>: DimMin<Const<K>, Output = Const<K>>,
    Const<D>: DimMin<Const<D>, Output = Const<D>>,
{
    debug_assert_eq!(D, 3 + K);
    let mut x = *seed;
    let mut lambda: SVector<f64, K> = SVector::zeros();
    let mut hessians = [Matrix3::zeros(); K];
    let mut last_step = f64::INFINITY;
    for iteration in 0..MAX_ITERATIONS {
        let mut values = [0.0; K];
        let mut gradients = [Vector3::zeros(); K];
        for k in 0..K {
            (values[k], gradients[k]) = model.value_and_gradient(surfaces[k], &x);
        }
        if iteration == 0 {
            lambda = least_squares_multipliers(&gradients, &(x - p))?;
        }
        // Once Newton's steps are below HESSIAN_REUSE the Hessians of the previous point serve:
        // they only set the rate of convergence, the fixed point is the exact gradients'.
        if last_step > HESSIAN_REUSE {
            for k in 0..K {
                hessians[k] = model.hessian(surfaces[k], &x, &gradients[k]);
            }
        }
        let mut hessian = Matrix3::identity();
        let mut residual: SVector<f64, D> = SVector::zeros();
        let mut jacobian: SMatrix<f64, D, D> = SMatrix::zeros();
        let mut stationarity = x - p;
        for k in 0..K {
            hessian += hessians[k] * lambda[k];
            stationarity += gradients[k] * lambda[k];
            residual[3 + k] = values[k];
            for i in 0..3 {
                jacobian[(i, 3 + k)] = gradients[k][i];
                jacobian[(3 + k, i)] = gradients[k][i];
            }
        }
        for i in 0..3 {
            residual[i] = stationarity[i];
            for j in 0..3 {
                jacobian[(i, j)] = hessian[(i, j)];
            }
        }
        let step = jacobian.lu().solve(&-residual)?;
        let mut dx = Vector3::new(step[0], step[1], step[2]);
        let mut dlambda = SVector::<f64, K>::from_fn(|k, _| step[3 + k]);
        let length = dx.norm();
        if !length.is_finite() {
            return None;
        }
        if length > max_step {
            dx *= max_step / length;
            dlambda *= max_step / length;
        }
        x += dx;
        lambda += dlambda;
        last_step = length;
        let on_surfaces =
            (0..K).all(|k| values[k].abs() <= ON_SURFACE_TOLERANCE * gradients[k].norm());
        if length < STEP_TOLERANCE && on_surfaces {
            return Some(x);
        }
    }
    None
}

/// The multipliers that best satisfy x - p + G lambda = 0 at the seed.
fn least_squares_multipliers<const K: usize>(
    gradients: &[Vector3<f64>; K],
    offset: &Vector3<f64>,
) -> Option<SVector<f64, K>>
where
    Const<K>: DimMin<Const<K>, Output = Const<K>>,
{
    let normal = SMatrix::<f64, K, K>::from_fn(|i, j| gradients[i].dot(&gradients[j]));
    let rhs = SVector::<f64, K>::from_fn(|i, _| -gradients[i].dot(offset));
    normal.lu().solve(&rhs)
}

/// A point on the common zero set of `surfaces` near `seed`, by Gauss-Newton's minimal-norm steps
/// x <- x - G (G^T G)^-1 g (K <= 3 transversal surfaces). `None` if it does not converge.
pub(super) fn project<const K: usize>(
    model: &impl Surfaces,
    surfaces: [usize; K],
    seed: &Point3<f64>,
    max_step: f64,
) -> Option<Point3<f64>>
where
    Const<K>: DimMin<Const<K>, Output = Const<K>>,
{
    let mut x = *seed;
    for _ in 0..MAX_ITERATIONS {
        let mut values = SVector::<f64, K>::zeros();
        let mut gradients = [Vector3::zeros(); K];
        for k in 0..K {
            (values[k], gradients[k]) = model.value_and_gradient(surfaces[k], &x);
        }
        if (0..K).all(|k| values[k].abs() <= ON_SURFACE_TOLERANCE * gradients[k].norm()) {
            return Some(x);
        }
        let normal = SMatrix::<f64, K, K>::from_fn(|i, j| gradients[i].dot(&gradients[j]));
        let weights = normal.lu().solve(&values)?;
        let mut dx = -(0..K).fold(Vector3::zeros(), |sum, k| sum + gradients[k] * weights[k]);
        let length = dx.norm();
        if !length.is_finite() {
            return None;
        }
        if length > max_step {
            dx *= max_step / length;
        }
        x += dx;
    }
    None
}
