//! The exact orthogonal distance: the foot point x minimising |x - p| subject to F(x) = 0, found by Newton's method
//! on the Lagrange system  x - p + lambda grad F(x) = 0,  F(x) = 0.
//!
//! Newton only finds a nearby critical point, so where it starts decides which side of a thin blade it lands on.
//! Starts come from the previous foot point along a scan, else from the sampled zero set (nearest samples first),
//! and every answer is checked: the segment from p to the foot must not cross the zero set, and the foot must be no
//! farther than the on-curve point it started from (the true distance can never be larger than that).

use nalgebra::{SMatrix, SVector};

use super::{DistanceError, Foot};
use crate::geometry::implicit::Implicit;
use crate::geometry::small;
use crate::geometry::sampling::{project_to_zero_set, ZeroSetSamples};

/// How many sampled seeds are tried before the slow, robust fallback.
const SEEDS_TRIED: usize = 8;
/// Newton stops when a step is below this many millimetres: convergence is quadratic there, so the error left is
/// of the order of its square, far below the 1e-6 mm the station promises.
const STEP_TOLERANCE_MM: f64 = 1e-8;
const MAX_NEWTON_STEPS: usize = 40;

/// Exact distances to the zero set of `f`, seeded from `samples`.
pub struct ExactDistance<'a, F, const N: usize> {
    f: &'a F,
    samples: &'a ZeroSetSamples<N>,
}

impl<'a, F: Implicit<N>, const N: usize> ExactDistance<'a, F, N> {
    pub fn new(f: &'a F, samples: &'a ZeroSetSamples<N>) -> Self {
        Self { f, samples }
    }

    /// The foot point of `p`. `previous`, when given, is the foot of a neighbouring point along the same scan
    /// together with that point: Newton then starts from the previous foot moved by the step between the points.
    pub fn foot(
        &self,
        p: &SVector<f64, N>,
        previous: Option<(&SVector<f64, N>, &Foot<N>)>,
    ) -> Result<Foot<N>, DistanceError> {
        if let Some((prev_point, prev_foot)) = previous {
            let start = prev_foot.point + (p - prev_point);
            if let Some(foot) = self.checked_newton(p, &start, &prev_foot.point) {
                return Ok(foot);
            }
        }
        for seed in self.samples.nearest_iter(p).take(SEEDS_TRIED) {
            if let Some(foot) = self.checked_newton(p, &seed, &seed) {
                return Ok(foot);
            }
        }
        self.robust_fallback(p)
    }

    /// Feet of a sequence of points, each seeded from the previous one (the points of one scan, in order).
    pub fn feet_along_scan(&self, points: &[SVector<f64, N>]) -> Vec<Result<Foot<N>, DistanceError>> {
        let mut out: Vec<Result<Foot<N>, DistanceError>> = Vec::with_capacity(points.len());
        for (i, p) in points.iter().enumerate() {
            let previous = match (i.checked_sub(1), out.last()) {
                (Some(j), Some(Ok(foot))) => Some((&points[j], foot)),
                _ => None,
            };
            out.push(self.foot(p, previous));
        }
        out
    }

    /// Newton from `start`; `None` unless it converged to a foot that passes the checks against `on_curve`.
    fn checked_newton(
        &self,
        p: &SVector<f64, N>,
        start: &SVector<f64, N>,
        on_curve: &SVector<f64, N>,
    ) -> Option<Foot<N>> {
        let foot = lagrange_newton(self.f, p, start)?;
        let bound = (p - on_curve).norm();
        if foot.distance.abs() > bound + 1e-9 * (1.0 + bound) {
            return None;
        }
        (!crosses_zero_set(self.f, p, &foot.point)).then_some(foot)
    }

    /// Slow but sure: from the nearest sample, alternate a step along the tangent towards p with a projection back
    /// onto the zero set until the foot stops moving, then polish with Newton.
    fn robust_fallback(&self, p: &SVector<f64, N>) -> Result<Foot<N>, DistanceError> {
        let seed = self
            .samples
            .nearest_iter(p)
            .next()
            .ok_or(DistanceError::NoZeroSetNearby)?;
        let travel = 4.0 * (p - seed).norm() + self.samples.cell_size();
        let mut x = seed;
        for _ in 0..500 {
            let (_, g) = self.f.value_gradient(&x);
            let n = g.normalize();
            let offset = p - x;
            let tangential = offset - n * offset.dot(&n);
            let next =
                project_to_zero_set(self.f, &(x + tangential), travel).ok_or(DistanceError::NoFootPoint)?;
            let moved = (next - x).norm();
            x = next;
            if moved < STEP_TOLERANCE_MM {
                break;
            }
        }
        self.checked_newton(p, &x, &seed)
            .or_else(|| signed_foot(self.f, p, x))
            .ok_or(DistanceError::NoFootPoint)
    }
}

/// Newton's method on the Lagrange system from `start`. Returns the converged foot with its signed distance.
pub(crate) fn lagrange_newton<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    start: &SVector<f64, N>,
) -> Option<Foot<N>> {
    let mut x = *start;
    let (_, g0) = f.value_gradient(&x);
    let g0n = g0.norm_squared();
    if g0n == 0.0 {
        return None;
    }
    let mut lambda = (p - x).dot(&g0) / g0n;
    for _ in 0..MAX_NEWTON_STEPS {
        let (v, g, h) = f.value_gradient_hessian(&x);
        // Solve [[I + lambda H, g], [g^T, 0]] (dx, dl) = -(x - p + lambda g, F) by the Schur complement, so that the
        // code stays generic in N (an (N+1)-square matrix is not expressible with const generics).
        let a: SMatrix<f64, N, N> = SMatrix::identity() + h * lambda;
        let r = x - p + g * lambda;
        let both = small::solve(&a, &SMatrix::<f64, N, 2>::from_columns(&[r, g]))?;
        let (a_inv_r, a_inv_g) = (both.column(0).into_owned(), both.column(1).into_owned());
        let denom = g.dot(&a_inv_g);
        if denom == 0.0 || !denom.is_finite() {
            return None;
        }
        let dl = (v - g.dot(&a_inv_r)) / denom;
        let dx = -(a_inv_r + a_inv_g * dl);
        x += dx;
        lambda += dl;
        if !x.iter().all(|c| c.is_finite()) {
            return None;
        }
        if dx.norm() < STEP_TOLERANCE_MM {
            return signed_foot(f, p, x);
        }
    }
    None
}

/// The foot `x` with the distance from `p` signed by the side of p (positive where F > 0, outside).
fn signed_foot<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    x: SVector<f64, N>,
) -> Option<Foot<N>> {
    let (_, g) = f.value_gradient(&x);
    let offset = p - x;
    let unsigned = offset.norm();
    let side = offset.dot(&g);
    let distance = if side < 0.0 { -unsigned } else { unsigned };
    distance.is_finite().then_some(Foot { point: x, distance })
}

/// Whether the open segment from `p` to its foot passes through the zero set, i.e. the foot is on the far side of
/// some part of the curve (the far face of a thin trailing edge, say). Checked at three interior points.
pub(crate) fn crosses_zero_set<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    foot: &SVector<f64, N>,
) -> bool {
    let side = f.value(p);
    if side == 0.0 {
        return false;
    }
    [0.25, 0.5, 0.75]
        .iter()
        .any(|t| f.value(&(p + (foot - p) * *t)) * side < 0.0)
}
