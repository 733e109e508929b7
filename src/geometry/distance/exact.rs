//! The exact orthogonal distance: the foot point x minimising |x - p| subject to F(x) = 0, found by Newton's method
//! on the Lagrange system  x - p + lambda grad F(x) = 0,  F(x) = 0.
//!
//! Newton only finds a nearby critical point, so where it starts decides which side of a thin blade it lands on.
//! Starts come from the previous foot point along a scan, else from the sampled zero set (nearest samples first),
//! and every answer is checked: the segment from p to the foot must not cross the zero set, and the foot must be no
//! farther than the on-curve point it started from (the true distance can never be larger than that).

use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::{SMatrix, SVector};

use super::certificate::{Certifier, Verdict};
use super::{DistanceError, Foot};
use crate::geometry::implicit::Implicit;
use crate::geometry::sampling::{project_to_zero_set, ZeroSetSamples};
use crate::geometry::small;

/// How many sampled seeds are tried before the slow, robust fallback, and how many samples are looked at to
/// find them.
const SEEDS_TRIED: usize = 8;
const SEEDS_SCANNED: usize = 400;
/// Seeds closer together than this fraction of their distance from the point lead to the same foot.
const SEED_SEPARATION: f64 = 0.1;
/// Along a scan, a foot is trusted without a search when Taubin's estimate agrees with it to this fraction.
/// Taubin's estimate is first-order exact: its relative error is about d / 2R, 0.4% at 0.8 mm from a 100 mm
/// radius, and large only near sharp edges, where the search must run anyway.
const TAUBIN_AGREEMENT: f64 = 0.02;
/// Newton stops when a step is below this many millimetres: convergence is quadratic there, so the error left is
/// of the order of the step's square times the curvature, far below the 1e-6 mm the station promises (a test
/// holds every foot to a fully converged one, edges included).
const STEP_TOLERANCE_MM: f64 = 1e-6;
const MAX_NEWTON_STEPS: usize = 40;

/// How many times a foot refuted by its certificate is searched for again from the nearer zero it showed.
const REFUTATIONS_FOLLOWED: usize = 4;

/// Exact distances to the zero set of `f`, seeded from `samples`. Every foot is put to its certificate
/// ([`super::certificate`]); those it could neither prove nor refute are counted.
pub struct ExactDistance<'a, F, const N: usize> {
    f: &'a F,
    samples: &'a ZeroSetSamples<N>,
    uncertified: AtomicUsize,
}

impl<'a, F: Implicit<N>, const N: usize> ExactDistance<'a, F, N> {
    pub fn new(f: &'a F, samples: &'a ZeroSetSamples<N>) -> Self {
        Self {
            f,
            samples,
            uncertified: AtomicUsize::new(0),
        }
    }

    /// How many feet found so far the certificate could not prove global (a model without a Taylor expansion has
    /// none proved).
    pub fn uncertified(&self) -> usize {
        self.uncertified.load(Ordering::Relaxed)
    }

    /// The foot point of `p`. `previous`, when given, is the foot of a neighbouring point along the same scan
    /// together with that point: Newton then starts from the previous foot moved by the step between the points.
    pub fn foot(
        &self,
        p: &SVector<f64, N>,
        previous: Option<(&SVector<f64, N>, &Foot<N>)>,
    ) -> Result<Foot<N>, DistanceError> {
        self.certified_foot(p, previous, &mut Certifier::new(self.f))
    }

    /// The foot found, then put to the certificate: a refuted foot gives way to the one Newton finds from the
    /// nearer zero the certificate showed.
    fn certified_foot(
        &self,
        p: &SVector<f64, N>,
        previous: Option<(&SVector<f64, N>, &Foot<N>)>,
        certifier: &mut Certifier<F, N>,
    ) -> Result<Foot<N>, DistanceError> {
        // Along a scan, Newton from the previous foot moved by the step, and nothing else if the certificate
        // proves it: the checks the search makes on such a foot are all implied by the proof. A verdict on it is
        // kept, so that the search's finding the same foot does not pay for the same proof twice.
        let mut judged: Option<(SVector<f64, N>, Verdict<N>)> = None;
        let mut refuted_by = None;
        if let Some((prev_point, prev_foot)) = previous {
            let start = prev_foot.point + (p - prev_point);
            if let Some(c) = lagrange_newton_with_gradient(self.f, p, &start, STEP_TOLERANCE_MM) {
                match certifier.check_at(
                    p,
                    &c.foot.point,
                    c.foot.distance,
                    c.value,
                    &c.gradient,
                    Vec::new(),
                ) {
                    Verdict::Certified => return Ok(c.foot),
                    Verdict::Nearer(nearer) => refuted_by = Some(nearer),
                    Verdict::Unknown => judged = Some((c.foot.point, Verdict::Unknown)),
                }
            }
        }
        let mut foot = match refuted_by {
            Some(nearer) => nearer,
            None => self.uncertified_foot(p, previous)?,
        };
        for _ in 0..REFUTATIONS_FOLLOWED {
            let verdict = match judged.take() {
                Some((point, verdict)) if (point - foot.point).norm() <= 1e-9 => verdict,
                _ => certifier.check(p, &foot.point, foot.distance),
            };
            match verdict {
                Verdict::Certified => return Ok(foot),
                // Strictly nearer, by the certificate's own Newton run: following it always makes progress.
                Verdict::Nearer(nearer) => foot = nearer,
                Verdict::Unknown => break,
            }
        }
        self.uncertified.fetch_add(1, Ordering::Relaxed);
        Ok(foot)
    }

    /// The foot the seeded searches find, without its certificate: for a model that stands for the part only in
    /// part of its zero set (a stack's segment between its two profile planes), where a nearer zero elsewhere
    /// does not refute it.
    pub(crate) fn uncertified_foot(
        &self,
        p: &SVector<f64, N>,
        previous: Option<(&SVector<f64, N>, &Foot<N>)>,
    ) -> Result<Foot<N>, DistanceError> {
        // The fast path's foot is trusted at once only after a step within one sampling cell: across a longer
        // step its checks say little (a point 1.9 mm inside a degree-8 section got a foot 3.7 mm away that way,
        // in a batch of unordered points), so the seeded search decides, and the foot is kept only for when the
        // search finds none.
        let mut unconfirmed = None;
        if let Some((prev_point, prev_foot)) = previous {
            if let Some(foot) = self.along_the_scan(p, prev_point, prev_foot) {
                if (p - prev_point).norm() <= self.samples.cell_size() {
                    return Ok(foot);
                }
                unconfirmed = Some(foot);
            }
        }
        let Some((nearest_sample, _)) = self.samples.nearest(p) else {
            return unconfirmed.ok_or(DistanceError::NoZeroSetNearby);
        };
        // The point's own projection along the gradient: a point of the zero set that finds detail finer than the
        // sampling grid (a spurious sliver hugging a sharp edge), which no grid sample can.
        let own = project_to_zero_set(self.f, p, f64::INFINITY);
        let mut best: Option<Foot<N>> = None;
        // Near a sharp edge Newton from the nearest sample can stop at a local minimum of the distance; the global
        // one has a sample within about a cell of it, so every seed up to that far beyond the best foot is tried.
        let reach = 2.0 * self.samples.cell_size();
        if let Some(foot) = own.and_then(|x| self.checked_newton(p, &x, &x)) {
            if best.is_none_or(|b| foot.distance.abs() < b.distance.abs()) {
                best = Some(foot);
            }
        }
        // Refined samples crowd around a sharp edge: seeds next to one already tried would only find the same
        // local minimum again, so only seeds a fair fraction of the distance apart are tried.
        let mut tried: Vec<SVector<f64, N>> = Vec::with_capacity(SEEDS_TRIED);
        for seed in self.samples.nearest_iter(p).take(SEEDS_SCANNED) {
            if tried.len() == SEEDS_TRIED
                || best.is_some_and(|b| (p - seed).norm() > b.distance.abs() + reach)
            {
                break;
            }
            let apart = SEED_SEPARATION * (p - seed).norm();
            if tried.iter().any(|t| (t - seed).norm() < apart) {
                continue;
            }
            tried.push(seed);
            if let Some(foot) = self.checked_newton(p, &seed, &seed) {
                if best.is_none_or(|b| foot.distance.abs() < b.distance.abs()) {
                    best = Some(foot);
                }
            }
        }
        match best.or(unconfirmed) {
            Some(foot) => Ok(foot),
            None => self.robust_fallback(p, &nearest_sample),
        }
    }

    /// Feet of a sequence of points, each seeded from the previous one (the points of one scan, in order).
    pub fn feet_along_scan(
        &self,
        points: &[SVector<f64, N>],
    ) -> Vec<Result<Foot<N>, DistanceError>> {
        let mut out: Vec<Result<Foot<N>, DistanceError>> = Vec::with_capacity(points.len());
        let mut certifier = Certifier::new(self.f);
        for (i, p) in points.iter().enumerate() {
            let previous = match (i.checked_sub(1), out.last()) {
                (Some(j), Some(Ok(foot))) => Some((&points[j], foot)),
                _ => None,
            };
            out.push(self.certified_foot(p, previous, &mut certifier));
        }
        out
    }

    /// The fast path along a scan: Newton from the previous foot moved by the step between the points, trusted
    /// only when cheap checks all agree. The distance function is 1-Lipschitz, so it cannot jump by more than
    /// the points moved; the segment to the foot must not cross the zero set; and Taubin's first-order estimate
    /// F/|grad F| at the point must agree with the distance. The last catches what the first two cannot: a chain
    /// of feet creeping onto a branch beside the surface, and the nearest face changing across the medial axis
    /// of a sharp edge, where Taubin's estimate is poor anyway. Whatever fails goes to the seeded search.
    fn along_the_scan(
        &self,
        p: &SVector<f64, N>,
        prev_point: &SVector<f64, N>,
        prev_foot: &Foot<N>,
    ) -> Option<Foot<N>> {
        let step = (p - prev_point).norm();
        let (side, gradient) = self.f.value_gradient(p);
        let taubin = side / gradient.norm();
        let start = prev_foot.point + (p - prev_point);
        let foot = lagrange_newton(self.f, p, &start)?;
        let lipschitz =
            (foot.distance.abs() - prev_foot.distance.abs()).abs() <= step * (1.0 + 1e-9) + 1e-12;
        let agrees =
            (taubin - foot.distance).abs() <= TAUBIN_AGREEMENT * foot.distance.abs() + 1e-7;
        let midpoint = self.f.value(&((p + foot.point) / 2.0));
        let same_side = side == 0.0 || midpoint * side > 0.0;
        (lipschitz && agrees && same_side).then_some(foot)
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
    fn robust_fallback(
        &self,
        p: &SVector<f64, N>,
        nearest_sample: &SVector<f64, N>,
    ) -> Result<Foot<N>, DistanceError> {
        let seed = *nearest_sample;
        let travel = 4.0 * (p - seed).norm() + self.samples.cell_size();
        let mut x = seed;
        for _ in 0..500 {
            let (_, g) = self.f.value_gradient(&x);
            let n = g.normalize();
            let offset = p - x;
            let tangential = offset - n * offset.dot(&n);
            let next = project_to_zero_set(self.f, &(x + tangential), travel)
                .ok_or(DistanceError::NoFootPoint)?;
            let moved = (next - x).norm();
            x = next;
            if moved < STEP_TOLERANCE_MM {
                break;
            }
        }
        self.checked_newton(p, &x, &seed)
            .ok_or(DistanceError::NoFootPoint)
    }
}

/// Newton's method on the Lagrange system from `start`. Returns the converged foot with its signed distance.
pub(crate) fn lagrange_newton<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    start: &SVector<f64, N>,
) -> Option<Foot<N>> {
    lagrange_newton_to(f, p, start, STEP_TOLERANCE_MM)
}

/// Newton's method on the Lagrange system, stopping at a step below `tolerance` mm.
pub(crate) fn lagrange_newton_to<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    start: &SVector<f64, N>,
    tolerance: f64,
) -> Option<Foot<N>> {
    lagrange_newton_with_gradient(f, p, start, tolerance).map(|converged| converged.foot)
}

/// A foot with the model's value and gradient there, for its certificate.
pub(crate) struct Converged<const N: usize> {
    pub(crate) foot: Foot<N>,
    /// A bound on |F| at the foot.
    pub(crate) value: f64,
    pub(crate) gradient: SVector<f64, N>,
}

/// Newton's method on the Lagrange system, with the value and gradient at the foot: the last evaluation's carried
/// through the final step (g + H dx, whose error is of the order of the step's square, below 1e-12 at a final step
/// under 1e-6 mm). The value there is F + g.dx + dx'H dx / 2 to second order, and F + g.dx is zero by the step's
/// own constraint row, so what is handed on is a bound: twice the second-order term's size, |H| |dx|^2, against
/// the 1e-8 mm the certificate allows.
pub(crate) fn lagrange_newton_with_gradient<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    start: &SVector<f64, N>,
    tolerance: f64,
) -> Option<Converged<N>> {
    let mut x = *start;
    let mut lambda = f64::NAN;
    for _ in 0..MAX_NEWTON_STEPS {
        let (v, g, h) = f.value_gradient_hessian(&x);
        if lambda.is_nan() {
            // The multiplier that best balances x - p + lambda grad F = 0 at the start.
            let g2 = g.norm_squared();
            if g2 == 0.0 {
                return None;
            }
            lambda = (p - x).dot(&g) / g2;
        }
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
        if dx.norm() < tolerance {
            // The last step's gradient is the foot's to within the step: it tells the side.
            return signed_foot(p, x, &g).map(|foot| Converged {
                foot,
                value: (v + g.dot(&dx)).abs() + h.norm() * dx.norm_squared(),
                gradient: g + h * dx,
            });
        }
    }
    None
}

/// The foot `x` with the distance from `p` signed by the side of p (positive along the outward gradient).
fn signed_foot<const N: usize>(
    p: &SVector<f64, N>,
    x: SVector<f64, N>,
    gradient: &SVector<f64, N>,
) -> Option<Foot<N>> {
    let offset = p - x;
    let unsigned = offset.norm();
    let distance = if offset.dot(gradient) < 0.0 {
        -unsigned
    } else {
        unsigned
    };
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
