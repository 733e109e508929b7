//! The approximate perpendicular distance of seed 003 (section 3 in 2-D, section 4 in 3-D).
//!
//! From the measured point, Newton finds the zero set along each coordinate axis (the "horizontal and vertical
//! projections"). The plane (3-D) or line (2-D) through those axis intercepts has the normal
//! (1/dx, 1/dy[, 1/dz]) with d the point-to-intercept offsets, which is the paper's determinant written out
//! ((y_m - y_0)(z_m - z_0), ... divided by their product). Newton then finds the zero set along that normal through
//! the point, and the distance to that foot is the answer.
//!
//! Extension, stated: where an axis line never meets the zero set (a blade surface parallel to that axis), its
//! intercept is taken at infinity, the limit of the paper's formula, so its normal component is zero.
//!
//! The method fails where its projections reach another branch of the zero set (near leading and trailing edges)
//! or find nothing; those points are reported as failures with the reason, never as a number.

use nalgebra::SVector;

use super::{Foot, PaperFailure};
use crate::geometry::implicit::Implicit;

const MAX_NEWTON_STEPS: usize = 60;
const STEP_TOLERANCE_MM: f64 = 1e-10;
/// Sign checks along each projection segment: enough to catch a branch that the segment crosses and leaves.
const CROSSING_CHECKS: usize = 8;
/// How much longer than the nearest axis intercept the perpendicular may be before it counts as another branch.
const FARTHER_THAN_INTERCEPT: f64 = 1.05;

/// The paper's approximate foot and signed distance, or why the method cannot give one for this point.
/// `reach` bounds how far a projection may travel (a few model sizes): beyond it the root is not on this part.
pub fn paper_distance<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    reach: f64,
) -> Result<Foot<N>, PaperFailure> {
    let side = f.value(p);
    if side == 0.0 {
        return Ok(Foot {
            point: *p,
            distance: 0.0,
        });
    }
    let mut normal = SVector::<f64, N>::zeros();
    let mut nearest_intercept = f64::INFINITY;
    for axis in 0..N {
        let mut direction = SVector::<f64, N>::zeros();
        direction[axis] = 1.0;
        match root_along_line(f, p, &direction, reach) {
            LineRoot::Found(t) => {
                if crosses_before(f, p, &direction, t, side) {
                    return Err(PaperFailure::AxisHitOtherBranch { axis });
                }
                // d_axis = p_axis - root_axis = -t; the paper's normal component is 1 / d_axis.
                normal[axis] = -1.0 / t;
                nearest_intercept = nearest_intercept.min(t.abs());
            }
            LineRoot::None => {}
        }
    }
    if normal.norm() == 0.0 {
        return Err(PaperFailure::NoAxisIntercept);
    }
    let direction = normal.normalize();
    let t = match root_along_line(f, p, &direction, reach) {
        LineRoot::Found(t) => t,
        LineRoot::None => return Err(PaperFailure::PerpendicularNoRoot),
    };
    if crosses_before(f, p, &direction, t, side) {
        return Err(PaperFailure::PerpendicularHitOtherBranch);
    }
    // Any axis intercept is itself a point of the zero set. On the concave side of a curve the tilted perpendicular
    // can be a little longer than an axis projection; one markedly longer has reached another branch.
    if t.abs() > nearest_intercept * FARTHER_THAN_INTERCEPT {
        return Err(PaperFailure::FartherThanAxisIntercept);
    }
    let distance = if side > 0.0 { t.abs() } else { -t.abs() };
    Ok(Foot {
        point: p + direction * t,
        distance,
    })
}

enum LineRoot {
    Found(f64),
    None,
}

/// Newton's method for F(p + t d) = 0 in t, from t = 0.
fn root_along_line<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    d: &SVector<f64, N>,
    reach: f64,
) -> LineRoot {
    let mut t = 0.0;
    for _ in 0..MAX_NEWTON_STEPS {
        let (v, g) = f.value_gradient(&(p + d * t));
        let slope = g.dot(d);
        if slope == 0.0 || !slope.is_finite() {
            return LineRoot::None;
        }
        let step = v / slope;
        t -= step;
        if t.abs() > reach || !t.is_finite() {
            return LineRoot::None;
        }
        if step.abs() < STEP_TOLERANCE_MM {
            return LineRoot::Found(t);
        }
    }
    LineRoot::None
}

/// Whether F changes sign strictly between p and p + t d: then the root found is not the first one on that line,
/// and the projection has jumped over a branch.
fn crosses_before<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
    d: &SVector<f64, N>,
    t: f64,
    side: f64,
) -> bool {
    (1..CROSSING_CHECKS).any(|k| {
        let s = t * k as f64 / CROSSING_CHECKS as f64;
        f.value(&(p + d * s)) * side < 0.0
    })
}
