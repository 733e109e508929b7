//! Signed distances from points to the zero set of an implicit model (positive outside the material).
//!
//! Three methods, so that a report can say which it used and a user can compare them:
//! - `Exact`: the orthogonal distance (Newton on the Lagrange system, seeded from the sampled zero set);
//! - `Paper`: the approximation of seed 003 (axis projections, then the perpendicular), which reports failure per
//!   point where its projections reach another branch;
//! - `Taubin`: the first-order estimate F / |grad F|.

mod certificate;
mod exact;
mod paper;
mod stack;

use nalgebra::SVector;
use serde::{Deserialize, Serialize};

pub(crate) use certificate::TOLERANCE_MM as CERTIFICATE_TOLERANCE_MM;
#[cfg(test)]
pub(crate) use certificate::{Certifier, Verdict};
#[cfg(test)]
pub(crate) use exact::lagrange_newton_to;
pub use exact::ExactDistance;
pub(crate) use exact::{crosses_zero_set, lagrange_newton};
pub use paper::paper_distance;
pub use stack::StackDistance;

use super::implicit::Implicit;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DistanceMethod {
    Exact,
    Paper,
    Taubin,
}

impl DistanceMethod {
    pub fn describe(self) -> &'static str {
        match self {
            Self::Exact => "exact orthogonal distance (Newton on the Lagrange system)",
            Self::Paper => "seed 003 approximation (axis projections, then the perpendicular)",
            Self::Taubin => "Taubin's first-order estimate F/|grad F|",
        }
    }
}

/// A foot point on the zero set and the signed distance to it (mm, positive outside the material).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Foot<const N: usize> {
    pub point: SVector<f64, N>,
    pub distance: f64,
}

impl DistanceError {
    /// A short machine-readable label for CSV files.
    pub fn label(self) -> &'static str {
        match self {
            Self::Paper(failure) => failure.label(),
            Self::ZeroGradient => "zero-gradient",
            Self::NoZeroSetNearby => "no-zero-set-nearby",
            Self::NoFootPoint => "no-foot-point",
            Self::OutsideModelRange => "outside-model-range",
        }
    }
}

/// Why the paper's approximation gave no distance for a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PaperFailure {
    #[error("the projection along axis {axis} crossed another branch of the model")]
    AxisHitOtherBranch { axis: usize },
    #[error("no axis projection reached the model")]
    NoAxisIntercept,
    #[error("the perpendicular line found no root on the model")]
    PerpendicularNoRoot,
    #[error("the perpendicular line crossed another branch of the model")]
    PerpendicularHitOtherBranch,
    #[error("the perpendicular foot lies farther than an axis intercept (projections on different branches)")]
    FartherThanAxisIntercept,
}

impl PaperFailure {
    /// A short machine-readable label for CSV files.
    pub fn label(self) -> &'static str {
        match self {
            Self::AxisHitOtherBranch { .. } => "paper-failed:axis-hit-other-branch",
            Self::NoAxisIntercept => "paper-failed:no-axis-intercept",
            Self::PerpendicularNoRoot => "paper-failed:perpendicular-no-root",
            Self::PerpendicularHitOtherBranch => "paper-failed:perpendicular-hit-other-branch",
            Self::FartherThanAxisIntercept => "paper-failed:farther-than-axis-intercept",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum DistanceError {
    #[error("the paper's approximation failed: {0}")]
    Paper(#[from] PaperFailure),
    #[error("the model's gradient vanishes at this point, so F/|grad F| is undefined")]
    ZeroGradient,
    #[error("the model has no zero set near this point (outside the region it was fitted on)")]
    NoZeroSetNearby,
    #[error("no foot point found on the model")]
    NoFootPoint,
    #[error("the point lies beyond the profiles the model interpolates")]
    OutsideModelRange,
}

/// Signed distances (mm) of points, in order (the points of a scan seed each other), by `method`. `reach` bounds
/// how far the paper's projections may travel (a few model sizes). `exact` computes the exact distances; it is
/// called only for that method, so its set-up (sampling the zero set) is not paid for the others.
pub fn signed_distances<F: Implicit<N>, const N: usize>(
    f: &F,
    points: &[SVector<f64, N>],
    method: DistanceMethod,
    reach: f64,
    exact: impl FnOnce(&[SVector<f64, N>]) -> Vec<Result<f64, DistanceError>>,
) -> Vec<Result<f64, DistanceError>> {
    match method {
        DistanceMethod::Exact => exact(points),
        DistanceMethod::Paper => points
            .iter()
            .map(|p| {
                paper_distance(f, p, reach)
                    .map(|foot| foot.distance)
                    .map_err(DistanceError::from)
            })
            .collect(),
        DistanceMethod::Taubin => points.iter().map(|p| taubin_distance(f, p)).collect(),
    }
}

/// Taubin's signed estimate F / |grad F|.
pub fn taubin_distance<const N: usize>(
    f: &impl Implicit<N>,
    p: &SVector<f64, N>,
) -> Result<f64, DistanceError> {
    let (v, g) = f.value_gradient(p);
    let norm = g.norm();
    if norm == 0.0 || !norm.is_finite() {
        return Err(DistanceError::ZeroGradient);
    }
    Ok(v / norm)
}

#[cfg(test)]
mod tests;
