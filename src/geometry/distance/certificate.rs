//! The exact distance's certificate: a proof that no point of the zero set lies nearer to p than the foot found, less
//! [`TOLERANCE_MM`]. Newton only ever finds a critical point of the distance; this is what makes it the global one.
//!
//! The proof has two parts, both from bounds over boxes that a polynomial's Taylor expansion gives
//! ([`crate::geometry::taylor`]):
//! - Near the foot x* (normal n, |grad F| = G), a zero x = x* + u has n.u = -(F(x*) + u'H u / 2) / G for some H
//!   the Hessian takes between them, so |p - x|^2 - d^2 = |u|^2 - 2 (p - x*).u >= |u|^2 (1 - d h / G) less rounding,
//!   where h bounds |u'H u| / |u|^2: the tangential curvature A, plus the cross and normal terms B and C weighted by
//!   how far u can lean off the tangent. Where d h <= G, no zero within that ball is nearer than the foot. The
//!   disk of radius d about p lies within 2d of x*, so one ball settles the whole question wherever the model
//!   bends gently enough; the bounds found for one foot serve the next feet along a scan while they stay inside.
//! - Elsewhere (a thin section's far face within reach, a sharp end), the rest of the disk is covered by boxes,
//!   each dropped when it lies outside the disk or the ball, or when its centred form shows F cannot vanish in
//!   it, and halved otherwise. A box that stays small and undecided holds a zero nearer than the foot: its centre
//!   is where Newton should start again.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use nalgebra::{SMatrix, SVector};

use super::{lagrange_newton, Foot};
use crate::geometry::implicit::Implicit;
use crate::geometry::taylor::Taylor;

/// What a certified foot's distance may exceed the true distance by (mm).
pub(crate) const TOLERANCE_MM: f64 = 1e-7;
/// The balls tried first about a foot, in multiples of the disk's reach: the larger, the more of the next feet
/// along a scan fall in it and need no expansion of their own.
const FIRST_BALLS: [f64; 3] = [4.0, 2.0, 1.0];
/// The smallest local ball tried before boxes, as a fraction of the disk's reach.
const SMALLEST_BALL: f64 = 1.0 / 1024.0;
/// Boxes examined before a foot is left uncertified (each costs one Taylor expansion, one to a few microseconds):
/// 512 for a curve, where the station measures every point live and a sharp edge's sliver would otherwise cost
/// milliseconds a point, and 65 536 for a surface, whose boxes split in eight and cover an area, not a line.
const fn box_budget(n: usize) -> usize {
    if n == 2 {
        512
    } else {
        65_536
    }
}

/// A box this small, as a fraction of the distance, starts Newton from its centre: it finds the zero in it or next
/// to it, which either refutes the foot or is proved as a second foot. A curve's boxes start it sooner (the
/// station measures every point live); a surface's go finer, where a second foot's ball must hold the box.
const fn smallest_box(n: usize) -> f64 {
    if n == 2 {
        1e-2
    } else {
        1e-4
    }
}
/// Two critical points this close, as a fraction of their distance from p, are one foot found twice.
const SAME_FOOT: f64 = 1e-9;
/// When the boxes run out, Newton starts from the centres of this many of the nearest boxes left.
const NEWTON_FROM_LEFT_BOXES: usize = 16;
/// Other critical points of the distance, about as near as the foot, whose balls the boxes may leave out.
const MAX_OTHER_FEET: usize = 8;

/// The part of space where a model stands for the part: between two planes of constant x (a profile stack's
/// segment). Zeros beyond them are not the part's and neither refute a foot nor need a proof.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Slab {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
}

impl Slab {
    /// Whether `x` (a coordinate along the slab's axis) lies in it, rounding allowed for.
    fn holds(&self, x: f64) -> bool {
        let rounding = 1e-12 * (1.0 + self.lo.abs().max(self.hi.abs()));
        x >= self.lo - rounding && x <= self.hi + rounding
    }

    /// Whether the slab meets the x-range of a cube.
    fn meets<const N: usize>(&self, centre: &SVector<f64, N>, half: f64) -> bool {
        centre[0] + half >= self.lo && centre[0] - half <= self.hi
    }
}

/// A ball about a point within which no zero (in the slab, if any) lies nearer to the point examined than its
/// distance, less the tolerance: the search need not look there.
type ClearBall<const N: usize> = (SVector<f64, N>, f64);

/// What the certificate says of a foot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Verdict<const N: usize> {
    /// No zero lies nearer to the point than the foot, less [`TOLERANCE_MM`].
    Certified,
    /// A zero lies nearer than the foot: this foot, Newton's from beside it, strictly nearer.
    Nearer(Foot<N>),
    /// Neither could be shown within the budget (or the model has no Taylor expansion).
    Unknown,
}

/// The Hessian at a centre and how far it can move (Frobenius norm of the entrywise bounds) within a ball.
#[derive(Debug, Clone, Copy)]
struct HessianBound<const N: usize> {
    centre: SVector<f64, N>,
    radius: f64,
    hessian: SMatrix<f64, N, N>,
    variation: f64,
}

impl<const N: usize> HessianBound<N> {
    fn of(taylor: &Taylor<N>, centre: SVector<f64, N>, radius: f64) -> Self {
        Self {
            centre,
            radius,
            hessian: taylor.hessian(),
            variation: taylor.hessian_variation(radius).norm(),
        }
    }

    /// Whether the ball holds every point within `reach` of `x`.
    fn covers(&self, x: &SVector<f64, N>, reach: f64) -> bool {
        (x - self.centre).norm() + reach <= self.radius
    }
}

/// Certifies feet one after another; the Hessian bounds of the last ball are kept for the next foot.
pub(crate) struct Certifier<'a, F, const N: usize> {
    f: &'a F,
    slab: Option<Slab>,
    last: Option<HessianBound<N>>,
}

impl<'a, F: Implicit<N>, const N: usize> Certifier<'a, F, N> {
    pub(crate) fn new(f: &'a F) -> Self {
        Self {
            f,
            slab: None,
            last: None,
        }
    }

    /// A certifier for a model that stands for the part only within `slab`.
    pub(crate) fn within(f: &'a F, slab: Slab) -> Self {
        Self {
            f,
            slab: Some(slab),
            last: None,
        }
    }

    /// The verdict on `foot` (a point of the zero set, at signed distance `distance` from `p`).
    pub(crate) fn check(
        &mut self,
        p: &SVector<f64, N>,
        foot: &SVector<f64, N>,
        distance: f64,
    ) -> Verdict<N> {
        let (value, gradient) = self.f.value_gradient(foot);
        self.check_at(p, foot, distance, value, &gradient, Vec::new())
    }

    /// The same, given the model's value and gradient at the foot, and `clear` balls already proved (a stack's
    /// creases).
    pub(crate) fn check_at(
        &mut self,
        p: &SVector<f64, N>,
        foot: &SVector<f64, N>,
        distance: f64,
        value: f64,
        gradient: &SVector<f64, N>,
        mut clear: Vec<ClearBall<N>>,
    ) -> Verdict<N> {
        let d = distance.abs();
        if d <= TOLERANCE_MM {
            return Verdict::Certified;
        }
        let local = Local::new(p, foot, value, gradient, d);
        let reach = 2.0 * d;
        if let Some(last) = &self.last {
            if last.covers(foot, reach) && local.proves(last, reach) {
                return Verdict::Certified;
            }
        }
        let Some(taylor) = self.f.taylor(foot) else {
            return Verdict::Unknown;
        };
        for radius in FIRST_BALLS.map(|multiple| multiple * reach) {
            let bound = HessianBound::of(&taylor, *foot, radius);
            if local.proves(&bound, reach) {
                self.last = Some(bound);
                return Verdict::Certified;
            }
        }
        let ball = self.largest_proven_ball(&local, &taylor, foot, reach / 2.0);
        clear.push((*foot, ball));
        self.boxes(p, d, clear)
    }

    /// Whether no zero (in the slab) lies nearer to `p` than `d`, less the tolerance, when the foot at that distance
    /// is not on this model: a stack's segment beside the one that holds the foot. `clear` as for
    /// [`Self::check_at`].
    pub(crate) fn check_clear(
        &self,
        p: &SVector<f64, N>,
        d: f64,
        clear: Vec<ClearBall<N>>,
    ) -> Verdict<N> {
        if d <= TOLERANCE_MM {
            return Verdict::Certified;
        }
        self.boxes(p, d, clear)
    }

    /// The ball about a crease foot `c` within which no zero on the slab's side of the crease lies nearer to `p`
    /// than `d` (= |p - c|) less the tolerance; `None` where the proof does not hold. The crease is the curve where
    /// the zero set meets the slab's face x = c.x, and c is a critical point of the distance from p along it (a
    /// Newton foot in that plane; the proof needs no more), so p - c = lambda grad F + mu e_x with the in-plane part
    /// along the curve's normal. A zero c + u on the slab's
    /// side (side * u_x >= 0) then has |p - c - u|^2 - d^2 = |u|^2 + 2 lambda F(c) + lambda u'H u - 2 mu u_x: where
    /// mu points out of the slab the last term only helps, and the rest is the proof of an ordinary foot with
    /// |lambda| |grad F| in place of the distance; where that alone fails, the last term pays for the bending
    /// along x (`Local::proves_beside_crease`).
    pub(crate) fn crease_ball(
        &self,
        p: &SVector<f64, N>,
        c: &SVector<f64, N>,
        d: f64,
        side: f64,
    ) -> Option<ClearBall<N>> {
        let (value, gradient) = self.f.value_gradient(c);
        let mut in_plane = gradient;
        in_plane[0] = 0.0;
        let squared = in_plane.norm_squared();
        if !(squared > 0.0 && squared.is_finite()) || d <= TOLERANCE_MM {
            return None;
        }
        let r = p - c;
        let mut r_plane = r;
        r_plane[0] = 0.0;
        let lambda = r_plane.dot(&in_plane) / squared;
        let mu = r[0] - lambda * gradient[0];
        let gradient_norm = gradient.norm();
        let normal = gradient / gradient_norm;
        let local = Local {
            d,
            lever: lambda.abs() * gradient_norm,
            gradient_norm,
            normal,
            off_zero_set: value.abs() / gradient_norm,
            // 2 |lambda F(c)| and 2 (off-normal + outward mu) |u| are what the tolerance must absorb.
            admissible: (lambda * value).abs() <= d * TOLERANCE_MM / 8.0
                && (r_plane - in_plane * lambda).norm() + (side * mu).max(0.0)
                    <= TOLERANCE_MM / 8.0,
            side: if lambda < 0.0 { -1.0 } else { 1.0 },
            outward: (-side * mu).max(0.0),
        };
        let taylor = self.f.taylor(c)?;
        let reach = 2.0 * d;
        let radius = self.largest_proven_ball(&local, &taylor, c, reach);
        (radius > 0.0).then_some((*c, radius))
    }

    /// The largest ball about `x`, from `radius` down by halves, within which `local`'s proof holds (0 if none).
    fn largest_proven_ball(
        &self,
        local: &Local<N>,
        taylor: &Taylor<N>,
        x: &SVector<f64, N>,
        mut radius: f64,
    ) -> f64 {
        let smallest = SMALLEST_BALL * radius;
        while radius >= smallest {
            if local.proves(&HessianBound::of(taylor, *x, radius), radius) {
                return radius;
            }
            radius /= 2.0;
        }
        0.0
    }

    /// Covers the disk of radius `d` about `p`, less the proven ball of radius `ball` about the foot, with boxes,
    /// nearest to p first. A box that stays undecided down to the smallest size holds a zero about as near as the
    /// foot: Newton from it finds that zero's own critical point, which is either nearer (the foot is refuted) or
    /// not, and then its own ball is proved and left out like the foot's (two feet equally near, across a
    /// medial axis). Boxes the balls do not cover are split on until they are dropped or the budget runs out.
    fn boxes(&self, p: &SVector<f64, N>, d: f64, mut balls: Vec<ClearBall<N>>) -> Verdict<N> {
        if balls
            .iter()
            .any(|(x, radius)| (x - p).norm() + d <= *radius)
            || self.slab.is_some_and(|slab| !slab.meets(p, d))
        {
            return Verdict::Certified;
        }
        let smallest = smallest_box(N) * d;
        let mut queue = BinaryHeap::from([Cube::new(p, *p, d)]);
        let mut examined = 0;
        while let Some(Cube { centre, half, .. }) = queue.pop() {
            let inside = |(x, radius): &(SVector<f64, N>, f64)| {
                (centre - x).map(|c| c.abs() + half).norm() <= *radius
            };
            if balls.iter().any(inside) {
                continue;
            }
            examined += 1;
            if examined > box_budget(N) {
                queue.push(Cube::new(p, centre, half));
                return self.nearer_beside(p, d, queue);
            }
            let Some(taylor) = self.f.taylor(&centre) else {
                return Verdict::Unknown;
            };
            if taylor.value().abs() > taylor.variation(half) + taylor.rounding()
                || zeros_lie_beyond(&taylor, p, &centre, half, self.slab, d - TOLERANCE_MM)
            {
                continue;
            }
            // Newton once per box as it first falls below the smallest size; where that settles nothing (Newton
            // fails, leaves the slab, or finds a foot already known whose ball falls short of the box), the box is
            // split further within the budget, like any other.
            if half < smallest && 2.0 * half >= smallest {
                if let Some(other) = lagrange_newton(self.f, p, &centre)
                    .filter(|other| self.slab.is_none_or(|slab| slab.holds(other.point[0])))
                {
                    // Nearer by less than the tolerance is the foot itself, found again with its rounding.
                    let other_d = other.distance.abs();
                    if other_d < d - TOLERANCE_MM {
                        return Verdict::Nearer(other);
                    }
                    let known = balls
                        .iter()
                        .any(|(x, _)| (x - other.point).norm() <= SAME_FOOT * other_d);
                    if !known {
                        let (value, gradient) = self.f.value_gradient(&other.point);
                        let local = Local::new(p, &other.point, value, &gradient, other_d);
                        let Some(expansion) = self.f.taylor(&other.point) else {
                            return Verdict::Unknown;
                        };
                        let radius =
                            self.largest_proven_ball(&local, &expansion, &other.point, other_d);
                        balls.push((other.point, radius));
                        if balls.len() > MAX_OTHER_FEET {
                            return Verdict::Unknown;
                        }
                        if inside(balls.last().unwrap()) {
                            continue;
                        }
                    }
                }
            }
            let quarter = half / 2.0;
            for corner in 0..(1usize << N) {
                let offset = SVector::<f64, N>::from_fn(|k, _| {
                    if corner >> k & 1 == 1 {
                        quarter
                    } else {
                        -quarter
                    }
                });
                let child = Cube::new(p, centre + offset, quarter);
                let in_slab = self
                    .slab
                    .is_none_or(|slab| slab.meets(&child.centre, quarter));
                if in_slab && child.nearest < d - TOLERANCE_MM {
                    queue.push(child);
                }
            }
        }
        Verdict::Certified
    }

    /// The verdict when the boxes ran out before the disk was covered: Newton from the centres of the nearest
    /// boxes left ([`NEWTON_FROM_LEFT_BOXES`]), where a nearer zero would be if there is one. Where p lies near a
    /// centre of curvature the zero set runs at about the foot's distance over a wide cap, and the boxes that
    /// cover it stop short of the size that starts Newton: a nearer foot there was once missed by 76 um.
    fn nearer_beside(
        &self,
        p: &SVector<f64, N>,
        d: f64,
        mut queue: BinaryHeap<Cube<N>>,
    ) -> Verdict<N> {
        for _ in 0..NEWTON_FROM_LEFT_BOXES {
            let Some(cube) = queue.pop() else { break };
            let Some(other) = lagrange_newton(self.f, p, &cube.centre) else {
                continue;
            };
            let in_slab = self.slab.is_none_or(|slab| slab.holds(other.point[0]));
            if in_slab && other.distance.abs() < d - TOLERANCE_MM {
                return Verdict::Nearer(other);
            }
        }
        Verdict::Unknown
    }
}

/// Whether every zero in the cube about `centre` (half-side `half`), within the slab if any, lies at least `reach`
/// from p. The zeros lie within a thick plane: F(c + w) = F(c) + g.w + R with |R| bounded by the expansion's terms
/// of order two and up, so n.w lies within the thickness of -F(c)/|g|. Their distance from p is then at least that
/// of p's component along n from the thick plane, and of its tangential component from the box's shadow, taken
/// along the tangential direction from the box to p (the box's support there). The box is the cube cut to the
/// slab: at a crease, p lies off the slab's face, and what is left of a cube across the face lies away from p.
/// Near a foot, where the zero set runs at about the distance of p, this drops a cube an order of magnitude larger
/// than the one that needs F not to vanish in it.
fn zeros_lie_beyond<const N: usize>(
    taylor: &Taylor<N>,
    p: &SVector<f64, N>,
    centre: &SVector<f64, N>,
    half: f64,
    slab: Option<Slab>,
    reach: f64,
) -> bool {
    let gradient = taylor.gradient();
    let gradient_norm = gradient.norm();
    if !(gradient_norm > 0.0 && gradient_norm.is_finite()) {
        return false;
    }
    let normal = gradient / gradient_norm;
    let offset = -taylor.value() / gradient_norm;
    let thickness = (taylor.curved_variation(half) + taylor.rounding()) / gradient_norm;
    let along = (p - centre).dot(&normal);
    let off_plane = ((along - offset).abs() - thickness).max(0.0);
    // The box: the cube, cut along x to the slab.
    let (mut lo, mut hi) = (centre.add_scalar(-half), centre.add_scalar(half));
    if let Some(slab) = slab {
        lo[0] = lo[0].max(slab.lo);
        hi[0] = hi[0].min(slab.hi);
        if lo[0] > hi[0] {
            return true;
        }
    }
    let (middle, halves) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
    let q = p - middle;
    let tangential = q - normal * q.dot(&normal);
    let across = tangential.norm();
    let support = if across > 0.0 {
        (tangential / across).abs().dot(&halves)
    } else {
        0.0
    };
    let off_shadow = (across - support).max(0.0);
    // A margin for the rounding of these sums.
    (off_plane.powi(2) + off_shadow.powi(2)).sqrt() * (1.0 - 1e-12) >= reach
}

/// A cube of the search, ordered so that the one nearest to p comes first.
struct Cube<const N: usize> {
    centre: SVector<f64, N>,
    half: f64,
    /// The least distance from p to any point of the cube.
    nearest: f64,
}

impl<const N: usize> Cube<N> {
    fn new(p: &SVector<f64, N>, centre: SVector<f64, N>, half: f64) -> Self {
        let nearest = (centre - p).map(|c| (c.abs() - half).max(0.0)).norm();
        Self {
            centre,
            half,
            nearest,
        }
    }
}

impl<const N: usize> PartialEq for Cube<N> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl<const N: usize> Eq for Cube<N> {}

impl<const N: usize> PartialOrd for Cube<N> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl<const N: usize> Ord for Cube<N> {
    /// Reversed, for the max-heap to give the nearest first.
    fn cmp(&self, other: &Self) -> Ordering {
        other.nearest.total_cmp(&self.nearest)
    }
}

/// The foot's own quantities for the local proof.
struct Local<const N: usize> {
    d: f64,
    /// What the bending is weighed by: the distance along the normal (for a crease, |lambda| G).
    lever: f64,
    gradient_norm: f64,
    normal: SVector<f64, N>,
    /// |F(x*)| / G: how far the foot may be off the zero set.
    off_zero_set: f64,
    /// Whether the foot's own rounding (off the zero set, p off its normal line) is small enough for the proof.
    admissible: bool,
    /// +1 where p lies along the gradient from the foot (outside), -1 inside.
    side: f64,
    /// At a crease: how far p - c leans out of the slab along x (mu's outward part, mm; 0 for an ordinary foot).
    outward: f64,
}

impl<const N: usize> Local<N> {
    fn new(
        p: &SVector<f64, N>,
        foot: &SVector<f64, N>,
        value: f64,
        gradient: &SVector<f64, N>,
        d: f64,
    ) -> Self {
        let gradient_norm = gradient.norm();
        let normal = gradient / gradient_norm;
        let offset = p - foot;
        let off_zero_set = value.abs() / gradient_norm;
        let off_normal = (offset - normal * offset.dot(&normal)).norm();
        Self {
            d,
            lever: d,
            gradient_norm,
            normal,
            off_zero_set,
            admissible: off_zero_set <= TOLERANCE_MM / 8.0 && off_normal <= TOLERANCE_MM / 8.0,
            side: if offset.dot(&normal) < 0.0 { -1.0 } else { 1.0 },
            outward: 0.0,
        }
    }

    /// Whether no zero x within `extent` (at most 2d) of the foot, and within `bound`'s ball, lies nearer to p
    /// than d less the tolerance. With u = x - x*, p - x* = d' n + (rounding) and s the part of u along the tangent:
    /// |p - x|^2 - d^2 >= |u|^2 + (|d'| / G) sign(d') u'H u - 2 d |F(x*)| / G - 2 |u| off_normal. The last two are
    /// held to 3/4 d tolerance, within the 2 d tolerance - tolerance^2 that (d - tolerance)^2 leaves; the proof is
    /// that sign(d') u'H u >= -K |u|^2 with d K <= G. Only the bending towards p counts: a point outside a convex
    /// nose is certified however far it lies, one inside only short of the centre of curvature.
    fn proves(&self, bound: &HessianBound<N>, extent: f64) -> bool {
        debug_assert!(
            extent <= 2.0 * self.d * (1.0 + 1e-12),
            "the proof holds within 2d"
        );
        if !(self.gradient_norm > 0.0 && self.gradient_norm.is_finite() && self.admissible) {
            return false;
        }
        let n = &self.normal;
        let h = bound.hessian * self.side;
        let e = bound.variation;
        let basis = tangents_of(n);
        let tangents = &basis[..N - 1];
        let least_bending = least_eigenvalue(tangents, &h);
        let cross = tangents
            .iter()
            .map(|t| t.dot(&(h * n)).powi(2))
            .sum::<f64>()
            .sqrt();
        let normal = n.dot(&(h * n)).abs();
        // How far u can lean off the tangent: |n.u| <= |F(x*)| / G + |H| |u|^2 / 2G, for |u| from the tolerance on.
        let lean = (self.off_zero_set / TOLERANCE_MM
            + (h.norm() + e) * extent / (2.0 * self.gradient_norm))
            .min(1.0);
        let along = if least_bending < 0.0 {
            least_bending
        } else {
            least_bending * (1.0 - lean * lean)
        };
        let towards_p = -(along - 2.0 * lean * cross - lean * lean * normal - e);
        // A margin for the rounding of the expansion and of these sums.
        self.lever * towards_p <= self.gradient_norm * (1.0 - ROUNDING_MARGIN)
            || self.proves_beside_crease(bound, extent)
    }

    /// The same beside a crease (a surface's, N = 3), for zeros on the slab's side only, where the bending
    /// towards p along x is paid for by how far p leans out of the slab. With t1 the crease's tangent (normal to
    /// n and to x), t2 the tangent plane's direction nearest to x (its x-part sigma = |n x e_x|), u = a t1 +
    /// b t2 + v n and mu' the outward lean, the ordinary proof's terms give |p - x|^2 - d^2 >= c0 |u|^2 +
    /// L q(a, b) + 2 mu' |u_x|, less the tolerance's share, with L = lever / G and q the tangential Hessian
    /// (towards p). On the slab's side |u_x| >= sigma |b| - |n_x| |v|, and |v| <= |F| / G + (|H| + e) |u|^2 / 2G.
    /// What is left, A a^2 + 2 B a b + C b^2 + 2 mu' sigma |b| with A = c0 + L q11, B = L q12 and C = c0 +
    /// L q22, is at least 2 mu' sigma |b| - K b^2 with K = B^2 / A - C once A > 0. That holds for |b| <= |u| <=
    /// extent when K extent <= 2 mu' sigma: a crease seen from well out of the slab clears a ball its bending
    /// alone could not.
    fn proves_beside_crease(&self, bound: &HessianBound<N>, extent: f64) -> bool {
        let n = &self.normal;
        if N != 3 || self.outward <= 0.0 {
            return false;
        }
        let mut t1 = SVector::<f64, N>::zeros();
        t1[1] = -n[2];
        t1[2] = n[1];
        let sigma = t1.norm();
        if sigma <= 1e-12 {
            return false;
        }
        t1 /= sigma;
        let mut t2 = -n * n[0];
        t2[0] += 1.0;
        t2 /= sigma;
        let h = bound.hessian * self.side;
        let e = bound.variation;
        let g = self.gradient_norm;
        let spread = (h.norm() + e) / (2.0 * g);
        // The lean's constant part, 2 mu' |n_x| |F| / G, is the tolerance's to absorb.
        if 2.0 * self.outward * n[0].abs() * self.off_zero_set > self.d * TOLERANCE_MM / 8.0 {
            return false;
        }
        let lean = (self.off_zero_set / TOLERANCE_MM + spread * extent).min(1.0);
        let hn = h * n;
        let cross = (t1.dot(&hn).powi(2) + t2.dot(&hn).powi(2)).sqrt();
        let normal = n.dot(&hn).abs();
        let l = self.lever / g;
        let c0 = 1.0
            - l * (2.0 * lean * cross + lean * lean * normal + e)
            - 2.0 * self.outward * n[0].abs() * spread;
        let a = c0 + l * t1.dot(&(h * t1));
        let b = l * t1.dot(&(h * t2));
        let c = c0 + l * t2.dot(&(h * t2));
        if c0 <= ROUNDING_MARGIN || a <= ROUNDING_MARGIN {
            return false;
        }
        let k = b * b / a - c;
        k <= 0.0 || k * extent <= 2.0 * self.outward * sigma * (1.0 - ROUNDING_MARGIN)
    }
}

/// The proofs' relative margin for the rounding of the expansion and of their sums.
const ROUNDING_MARGIN: f64 = 1e-9;

/// An orthonormal basis of the tangent space at a normal `n` (N - 1 vectors), by Gram-Schmidt on the axes least
/// aligned with it.
/// The basis is returned in an array of two; a curve's uses the first only.
fn tangents_of<const N: usize>(n: &SVector<f64, N>) -> [SVector<f64, N>; 2] {
    let mut axes: [usize; N] = std::array::from_fn(|k| k);
    axes.sort_unstable_by(|&a, &b| n[a].abs().total_cmp(&n[b].abs()));
    let mut tangents = [SVector::<f64, N>::zeros(); 2];
    for (i, &k) in axes[..N - 1].iter().enumerate() {
        let mut t = SVector::<f64, N>::zeros();
        t[k] = 1.0;
        t -= n * n[k];
        for previous in &tangents[..i] {
            t -= previous * previous.dot(&t);
        }
        tangents[i] = t.normalize();
    }
    tangents
}

/// The least eigenvalue of `h` restricted to the span of `tangents` (one or two of them).
fn least_eigenvalue<const N: usize>(tangents: &[SVector<f64, N>], h: &SMatrix<f64, N, N>) -> f64 {
    let entry = |i: usize, j: usize| tangents[i].dot(&(h * tangents[j]));
    match tangents.len() {
        1 => entry(0, 0),
        2 => {
            let (a, b, c) = (entry(0, 0), entry(0, 1), entry(1, 1));
            (a + c) / 2.0 - ((a - c) / 2.0).hypot(b)
        }
        _ => unreachable!("models are curves or surfaces"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::implicit::{Frame, IpModel};
    use crate::geometry::poly::Poly;
    use nalgebra::Vector2;

    /// The ellipse x^2/a^2 + y^2/b^2 = 1 as a degree-2 model in millimetres.
    fn ellipse(a: f64, b: f64) -> IpModel<2> {
        IpModel {
            frame: Frame::identity(),
            poly: Poly::new(2, vec![-1.0, 0.0, 0.0, 1.0 / (a * a), 0.0, 1.0 / (b * b)]),
        }
    }

    #[test]
    fn the_nearest_foot_on_a_thin_ellipse_is_certified_and_the_far_one_is_not() {
        // A slender section 100 mm long and 4 mm thick: from a point 0.5 mm inside, the near face's foot is
        // certified; the far face's (a critical point of the distance, 3.5 mm away) is shown to have a zero
        // nearer, close to the near face.
        let model = ellipse(50.0, 2.0);
        let mut certifier = Certifier::new(&model);
        let p = Vector2::new(10.0, 1.5 - 0.5);
        let near = Vector2::new(10.0, 2.0 * (1.0f64 - 0.04).sqrt());
        let (near_distance, far) = (-(near.y - p.y), Vector2::new(10.0, -near.y));
        // The near foot is not exactly on the normal at x = 10 for an ellipse; polish it.
        let near = crate::geometry::distance::lagrange_newton(&model, &p, &near).unwrap();
        assert!((near.distance - near_distance).abs() < 0.01);
        assert_eq!(
            certifier.check(&p, &near.point, near.distance),
            Verdict::Certified
        );
        let far = crate::geometry::distance::lagrange_newton(&model, &p, &far).unwrap();
        assert!(far.distance.abs() > 2.5);
        match certifier.check(&p, &far.point, far.distance) {
            Verdict::Nearer(x) => assert!((x.point - near.point).norm() < 1e-6, "{}", x.point),
            other => panic!("the far face's foot: {other:?}"),
        }
    }

    #[test]
    fn a_foot_beyond_the_centre_of_curvature_is_refuted() {
        // Inside a circle of radius 2 mm, 3 mm from the far side: the antipodal critical point lies 3 mm away,
        // while the near side is 1 mm away.
        let model = ellipse(2.0, 2.0);
        let mut certifier = Certifier::new(&model);
        let p = Vector2::new(1.0, 0.0);
        match certifier.check(&p, &Vector2::new(-2.0, 0.0), -3.0) {
            Verdict::Nearer(x) => {
                assert!(
                    (x.point - Vector2::new(2.0, 0.0)).norm() < 1e-6,
                    "{}",
                    x.point
                )
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(
            certifier.check(&p, &Vector2::new(2.0, 0.0), -1.0),
            Verdict::Certified
        );
    }

    #[test]
    fn a_cube_whose_zeros_all_lie_beyond_the_reach_is_dropped_though_the_model_vanishes_in_it() {
        // The ellipse's zero set crosses each cube tried; the thick tangent plane says whether all of the zeros in
        // it lie at least the reach from p. Each verdict is checked against the zeros themselves, traced densely.
        let model = ellipse(50.0, 20.0);
        let p = Vector2::new(0.0, 21.0);
        let zeros: Vec<Vector2<f64>> = (0..200_000)
            .map(|i| {
                let t = i as f64 * std::f64::consts::TAU / 200_000.0;
                Vector2::new(50.0 * t.cos(), 20.0 * t.sin())
            })
            .collect();
        let mut dropped = 0;
        for (along, half) in [
            (2.0f64, 0.5),
            (5.0, 1.0),
            (10.0, 2.0),
            (0.5, 0.25),
            (20.0, 4.0),
        ] {
            let centre = Vector2::new(along, 20.0 * (1.0f64 - (along / 50.0).powi(2)).sqrt());
            let taylor = model.taylor(&centre).unwrap();
            assert!(
                taylor.value().abs() <= taylor.variation(half),
                "F vanishes in the cube"
            );
            let nearest_zero = zeros
                .iter()
                .filter(|z| (*z - centre).amax() <= half)
                .map(|z| (p - z).norm())
                .fold(f64::INFINITY, f64::min);
            let reach = 1.0 + 1e-3;
            let beyond = zeros_lie_beyond(&taylor, &p, &centre, half, None, reach);
            if beyond {
                dropped += 1;
                assert!(
                    nearest_zero >= reach,
                    "a zero {nearest_zero} mm from p in the cube at {along}"
                );
            }
        }
        // The cubes to the side of the foot (0, 20) are dropped; one that holds it is not.
        let holding = Vector2::new(0.1, 20.0);
        assert!(!zeros_lie_beyond(
            &model.taylor(&holding).unwrap(),
            &p,
            &holding,
            0.25,
            None,
            1.0 + 1e-3
        ));
        assert!(dropped >= 4, "{dropped} of 5 cubes dropped");
    }

    /// The plane y = 0 in 3-D, as a degree-1 model.
    fn plane_y() -> IpModel<3> {
        IpModel {
            frame: Frame::identity(),
            poly: Poly::new(1, vec![0.0, 0.0, 1.0, 0.0]),
        }
    }

    #[test]
    fn a_crease_seen_from_out_of_its_slab_clears_a_ball_its_bending_towards_p_alone_could_not() {
        // The parabolic sheet y = x^2 (F = y - x^2), cut at x = 0, seen from p = (-1/2, 1, 0): the crease is the
        // z axis and its nearest point the origin, d^2 = 5/4. Along x the sheet bends towards p with curvature 2,
        // twice what a lever of 1 allows, so the ordinary proof fails at every radius. On the slab's side x >= 0,
        // |p - x|^2 - d^2 = x - x^2 + x^4 >= 0 up to x = 1: p's lean out of the slab (mu' = 1/2) clears a ball of
        // radius 1 there. On the side x <= 0 the same sheet comes nearer (x - x^2 + x^4 < 0), and no ball is
        // cleared.
        let mut poly = Poly::<3>::zero(2);
        let y = poly.basis().index_of(&[0, 1, 0]).unwrap();
        let xx = poly.basis().index_of(&[2, 0, 0]).unwrap();
        poly.coeffs_mut()[y] = 1.0;
        poly.coeffs_mut()[xx] = -1.0;
        let model = IpModel {
            frame: Frame::identity(),
            poly,
        };
        let p = nalgebra::Vector3::new(-0.5, 1.0, 0.0);
        let c = nalgebra::Vector3::zeros();
        let d = 1.25f64.sqrt();
        let within = Certifier::within(&model, Slab { lo: 0.0, hi: 10.0 });
        let (_, radius) = within.crease_ball(&p, &c, d, 1.0).unwrap();
        assert!(radius >= d / 2.0 && radius <= 1.0, "{radius}");
        let beyond = Certifier::within(&model, Slab { lo: -10.0, hi: 0.0 });
        assert_eq!(beyond.crease_ball(&p, &c, d, -1.0), None);
        // The sheet's nearer zeros beyond x = 0: x = -0.3 is 0.0519 nearer in d^2.
        let nearer = nalgebra::Vector3::new(-0.3, 0.09, 0.0);
        assert!((p - nearer).norm() < d - 0.02);
    }

    #[test]
    fn a_crease_foot_is_cleared_on_the_side_of_the_slab_it_bounds_and_not_on_the_other() {
        // The half-plane y = 0, x >= 0, seen from p = (-1, 1, 0): its nearest point is the crease at the origin,
        // at sqrt 2. On the slab's side the whole disk is cleared; on the other side (x <= 0) the plane comes
        // nearer than the crease, at (-1, 0, 0), and the crease proof must refuse.
        let model = plane_y();
        let p = nalgebra::Vector3::new(-1.0, 1.0, 0.0);
        let c = nalgebra::Vector3::zeros();
        let d = 2f64.sqrt();
        let within = Certifier::within(&model, Slab { lo: 0.0, hi: 10.0 });
        let (_, radius) = within.crease_ball(&p, &c, d, 1.0).unwrap();
        assert!(radius >= 2.0 * d - 1e-12, "{radius}");
        assert_eq!(
            within.check_clear(&p, d, vec![(c, radius)]),
            Verdict::Certified
        );
        let beyond = Certifier::within(&model, Slab { lo: -10.0, hi: 0.0 });
        assert_eq!(beyond.crease_ball(&p, &c, d, -1.0), None);
        // Without the crease's ball, the boxes cut to the slab prove it too (the cut boxes lie away from p); but
        // claimed at a distance the origin beats, no proof: the boxes close in on it, and Newton's foot from
        // there, (-1, 0, 0), lies beyond the slab.
        assert_eq!(within.check_clear(&p, d, Vec::new()), Verdict::Certified);
        assert_eq!(
            within.check_clear(&p, d + 0.1, Vec::new()),
            Verdict::Unknown
        );
    }

    #[test]
    fn feet_along_a_scan_reuse_one_ball_and_stay_certified() {
        let model = ellipse(50.0, 20.0);
        let mut certifier = Certifier::new(&model);
        for i in 0..200 {
            let t = 0.3 + 0.001 * i as f64;
            let on = Vector2::new(50.0 * t.cos(), 20.0 * t.sin());
            let normal = Vector2::new(on.x / 2500.0, on.y / 400.0).normalize();
            let p = on + normal * 0.8;
            assert_eq!(certifier.check(&p, &on, 0.8), Verdict::Certified, "at {i}");
        }
    }
}
