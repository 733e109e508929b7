//! Fitting implicit polynomials to measured points.
//!
//! - 3L (seed 003 section 2; Lei, Blane, Cooper, PAMI 2000): besides the data (target 0), two offset copies along
//!   the outward normals, at +c outside (target +c) and -c inside (target -c), so that F approximates the signed
//!   distance near the data. Here c is chosen per point: it starts at a fraction of the data's RMS radius and is
//!   halved until the offset point's nearest data point is its own point, so that an offset never reaches past the
//!   medial axis of a thin section (the opposite face of a trailing edge a few tenths of a millimetre away).
//! - ridge-regularised 3L (Tasdizen, Tarel, Cooper, IEEE TIP 2000): the same system with a penalty on the
//!   coefficients, weighted so that it is invariant to rotations of the data (the weights of the Bombieri norm,
//!   scaled by the data's moments), which keeps spurious branches away from the data.
//! - orthogonal-distance refinement: Levenberg-Marquardt (Gauss-Newton with damping) on the exact distances of the
//!   points to the zero set, started from the ridge answer, with the same regulariser.
//!
//! Every system is solved by Householder QR of the stacked rows (chunk by chunk, see `lsq`), never by normal
//! equations. The data are normalised first (centroid, unit RMS radius) and the normalisation is stored with the
//! model. The candidates of one fit share what does not depend on the offset: the point index, the reduced data
//! rows, the ridge weights and the side probes.

mod ball_index;
mod design;
mod lsq;
mod offsets;

use nalgebra::{DVector, SVector};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use self::ball_index::BallIndex;
use self::design::Monomials;
use self::lsq::Reduced;
use self::offsets::{choose_offsets, Offsets};
use super::distance::{crosses_zero_set, lagrange_newton, ExactDistance, Foot};
use super::implicit::{Frame, IpModel};
use super::poly::{factorial, Basis, Poly, MAX_DEGREE};
use super::sampling::{project_to_zero_set, Aabb, ZeroSetSamples};
use super::small;

/// Default zero-set sampling for the statistics: cells along the longest side of twice the data's box.
const PROFILE_SAMPLING_CELLS: usize = 512;
const SURFACE_SAMPLING_CELLS: usize = 64;
/// The largest offsets tried when none is given (fractions of the RMS radius), for 3L and ridge fits.
const OFFSET_CANDIDATES: [f64; 4] = [0.003, 0.01, 0.03, 0.1];
/// The largest offsets of the ridge fits that start the orthogonal refinement: the refinement finds a local
/// minimum, and on airfoil sections one of these two starts was the better in every case measured.
const ORTHOGONAL_START_OFFSETS: [f64; 2] = [0.1, 0.03];
/// Side probes reach at most this far (a fraction of the RMS radius) and are only used from this depth on: the
/// probe noise of a CMM (microns) stays well below it on parts of tens of millimetres.
const PROBE_REACH: f64 = 0.1;
const PROBE_MIN_DEPTH: f64 = 2e-3;
/// The exact distances of the statistics follow the scan in runs of this many points, the runs in parallel (each
/// run's first point is found by the seeded search, the others from their predecessor's foot).
const MEASURE_RUN: usize = 4096;
const ODR_MAX_ITERATIONS: usize = 60;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum FitMethod {
    /// Plain 3L, as in seed 003 (to reproduce the paper).
    #[serde(rename = "3l")]
    ThreeL,
    /// Ridge-regularised 3L.
    #[serde(rename = "ridge")]
    Ridge,
    /// Ridge-regularised 3L refined by orthogonal distances: the most accurate (see BENCHMARKS.md).
    #[serde(rename = "odr")]
    #[default]
    Orthogonal,
}

impl FitMethod {
    pub fn describe(self) -> &'static str {
        match self {
            Self::ThreeL => "3L (Lei-Blane-Cooper), as in seed 003",
            Self::Ridge => "ridge-regularised 3L (Tasdizen-Tarel-Cooper)",
            Self::Orthogonal => {
                "ridge-regularised 3L refined by orthogonal distances (Levenberg-Marquardt)"
            }
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    pub degree: usize,
    pub method: FitMethod,
    /// Ridge weight relative to one data row; the default is measured in BENCHMARKS.md.
    pub ridge: f64,
    /// Largest 3L offset c, as a fraction of the data's RMS radius (it only shrinks from there, point by point).
    /// `None`: for 3L and ridge, the paper's procedure of varying the level sets and keeping the most accurate fit;
    /// for the orthogonal method, the start measured best in BENCHMARKS.md.
    pub offset: Option<f64>,
    /// Grid cells along the longest side of the box in which the zero set is sampled for the statistics;
    /// `None` for the default of the dimension (a fine grid for profiles, a coarser one for surfaces).
    pub sampling_cells: Option<usize>,
}

impl FitOptions {
    pub fn new(degree: usize, method: FitMethod) -> Self {
        Self {
            degree,
            method,
            ridge: 1e-5,
            offset: None,
            sampling_cells: None,
        }
    }
}

/// How near a spurious branch must come to the data to be reported, as a fraction of the data box's diagonal:
/// 2 mm for a 100 mm section, farther than a measured point of a part in tolerance strays from its model.
pub const BESIDE_DATA: f64 = 0.02;

/// How good a fit is, in millimetres; returned with every model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitStats {
    pub points: usize,
    /// RMS of the exact distances of the fitted points to the zero set.
    pub rms_distance_mm: f64,
    pub max_distance_mm: f64,
    /// Where the largest distance is: the fitted point's coordinates.
    pub max_distance_at: Vec<f64>,
    /// Condition number (largest over smallest singular value) of the least-squares system that was solved.
    pub condition_number: f64,
    /// Connected components of the zero set inside twice the data's bounding box: 1 for a clean closed profile;
    /// more means a spurious branch near the data.
    pub zero_set_components: usize,
    /// Of those, the spurious branches beside the data: components no fitted point lies nearest to that come
    /// within [`BESIDE_DATA`] of the data's box diagonal of a fitted point. Only these can change a deviation.
    #[serde(default)]
    pub branches_beside_data: usize,
    /// The range of 3L offsets used, mm.
    pub offset_min_mm: f64,
    pub offset_max_mm: f64,
    /// Levenberg-Marquardt iterations of the orthogonal refinement (0 for the other methods).
    pub refinement_iterations: usize,
    /// Points whose exact distance could not be computed (a defect of the model near them).
    pub points_without_foot: usize,
    /// Segments across the data along the normals, and how many of them the model's zero set crosses more than
    /// once: a sliver of spurious surface beside the data, where deviations may have the wrong sign.
    #[serde(default)]
    pub side_segments: usize,
    #[serde(default)]
    pub side_segments_crossed_again: usize,
}

impl FitStats {
    /// Whether these statistics describe a closer fit than `other`: every point placed, then the smaller RMS.
    fn closer_than(&self, other: &FitStats) -> bool {
        (self.points_without_foot, self.rms_distance_mm)
            < (other.points_without_foot, other.rms_distance_mm)
    }
}

/// A fitted model with its statistics.
#[derive(Debug, Clone)]
pub struct Fitted<const N: usize> {
    pub model: IpModel<N>,
    pub method: FitMethod,
    pub stats: FitStats,
    /// The box in which the model was fitted and sampled (the data's bounding box), mm.
    pub domain: Aabb<N>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    #[error("degree {degree} is not supported (1 to {MAX_DEGREE})")]
    BadDegree { degree: usize },
    #[error("{got} points are too few for a degree-{degree} fit (it has {unknowns} coefficients; give at least {needed} points)")]
    TooFewPoints {
        got: usize,
        degree: usize,
        unknowns: usize,
        needed: usize,
    },
    #[error("the points do not span {dims} dimensions (they lie on a {what}); a fit needs a {dims}-D spread")]
    Degenerate { dims: usize, what: &'static str },
    #[error("{normals} normals were given for {points} points")]
    NormalCount { points: usize, normals: usize },
    #[error("the least-squares system is singular (too few distinct points for this degree)")]
    Singular,
}

/// Fits an implicit polynomial to `points` (mm) with outward unit `normals`.
pub fn fit_ip<const N: usize>(
    points: &[SVector<f64, N>],
    normals: &[SVector<f64, N>],
    options: &FitOptions,
) -> Result<Fitted<N>, FitError> {
    let degree = options.degree;
    if degree == 0 || degree > MAX_DEGREE {
        return Err(FitError::BadDegree { degree });
    }
    if normals.len() != points.len() {
        return Err(FitError::NormalCount {
            points: points.len(),
            normals: normals.len(),
        });
    }
    let basis = Basis::<N>::new(degree);
    // Three rows per point; with fewer points than unknowns the data rows alone leave the shape undetermined.
    if points.len() < basis.len() {
        return Err(FitError::TooFewPoints {
            got: points.len(),
            degree,
            unknowns: basis.len(),
            needed: basis.len(),
        });
    }
    check_spread(points)?;
    let frame = Frame::of_points(points).ok_or(FitError::Degenerate {
        dims: N,
        what: "single point",
    })?;
    let unit: Vec<SVector<f64, N>> = points.iter().map(|p| frame.to_unit(p)).collect();
    let domain = Aabb::of_points(points).expect("points are not empty");
    let candidates: Vec<f64> = match (options.offset, options.method) {
        (Some(fixed), _) => vec![fixed],
        (None, FitMethod::Orthogonal) => ORTHOGONAL_START_OFFSETS.to_vec(),
        (None, FitMethod::ThreeL | FitMethod::Ridge) => OFFSET_CANDIDATES.to_vec(),
    };
    // Every ladder of offsets at once, the side probes' with the candidates': they share one index and what each
    // point's rungs found.
    let mut largests = candidates.clone();
    let probe_set = largests
        .iter()
        .position(|&l| l == PROBE_REACH)
        .unwrap_or_else(|| {
            largests.push(PROBE_REACH);
            largests.len() - 1
        });
    let offset_sets = choose_offsets(&BallIndex::new(&unit), &unit, normals, &largests);
    let probes = SideProbes::new(&unit, normals, &offset_sets[probe_set]);
    let monomials = Monomials::new(&basis);
    let data_rows = Reduced::of_rows(unit.len(), 1, basis.len(), |i, rows| {
        monomials.fill(&unit[i], rows.push(0.0))
    });
    let ridge = match options.method {
        FitMethod::ThreeL => None,
        FitMethod::Ridge | FitMethod::Orthogonal => Some(
            ridge_weights(&basis, &unit, options.ridge)
                .iter()
                .map(|w| w.sqrt())
                .collect::<Vec<f64>>(),
        ),
    };
    // The candidates on both cores as well as within each: their sequential parts (the zero set's samples, the
    // solve's last steps) then overlap. The best is chosen in the candidates' order, as one after another would.
    let fit_candidate = |offsets: &Vec<Offsets>| -> Result<Fitted<N>, FitError> {
        let (coeffs, condition_number) = solve_three_level(
            &monomials,
            &data_rows,
            &unit,
            normals,
            offsets,
            ridge.as_deref(),
        )?;
        let mut poly = Poly::new(degree, coeffs);
        let mut refinement_iterations = 0;
        if options.method == FitMethod::Orthogonal {
            // Unconstrained first: the most accurate, unless its zero set crosses more side segments again than
            // its start's does; then the refinement that may not.
            let allowed = probes.crossed_again(&poly);
            let refined = refine_orthogonal(&poly, &monomials, &unit, None)
                .filter(|(r, _)| probes.crossed_again(r) <= allowed)
                .or_else(|| refine_orthogonal(&poly, &monomials, &unit, Some(&probes)));
            if let Some((refined, iterations)) = refined {
                poly = refined;
                refinement_iterations = iterations;
            }
        }
        let model = IpModel { frame, poly };
        let (min_offset, max_offset) = offsets
            .iter()
            .flat_map(|o| [o.inside, o.outside])
            .flatten()
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), c| {
                (lo.min(c), hi.max(c))
            });
        // With no safe offset at all the range is empty: record zero rather than an infinity, which JSON cannot
        // hold (the model file would not load again).
        let min_offset = if min_offset.is_finite() {
            min_offset
        } else {
            0.0
        };
        let cells = options.sampling_cells.unwrap_or(if N == 2 {
            PROFILE_SAMPLING_CELLS
        } else {
            SURFACE_SAMPLING_CELLS
        });
        let mut stats = measure(&model, points, &domain, cells);
        stats.condition_number = condition_number;
        stats.offset_min_mm = min_offset * frame.scale;
        stats.offset_max_mm = max_offset * frame.scale;
        stats.refinement_iterations = refinement_iterations;
        stats.side_segments = probes.len();
        stats.side_segments_crossed_again = probes.crossed_again(&model.poly);
        Ok(Fitted {
            model,
            method: options.method,
            stats,
            domain,
        })
    };
    let fitted = offset_sets[..candidates.len()]
        .par_iter()
        .map(fit_candidate)
        .collect::<Result<Vec<_>, _>>()?;
    let best = fitted
        .into_iter()
        .reduce(|best, candidate| {
            if candidate.stats.closer_than(&best.stats) {
                candidate
            } else {
                best
            }
        })
        .expect("at least one offset is tried");
    Ok(best)
}

/// Rejects point sets that lie on a line (2-D) or a plane (3-D): their spread has a vanishing direction.
fn check_spread<const N: usize>(points: &[SVector<f64, N>]) -> Result<(), FitError> {
    let mean = points.iter().sum::<SVector<f64, N>>() / points.len() as f64;
    let covariance = points
        .iter()
        .map(|p| (p - mean) * (p - mean).transpose())
        .fold(nalgebra::SMatrix::<f64, N, N>::zeros(), |a, b| a + b);
    let eigen = small::symmetric_eigen(&covariance);
    let smallest = eigen[0].0;
    let largest = eigen[N - 1].0;
    // A spread thinner than 1e-5 of the length (0.1 um across 10 mm) is a line or plane measured with noise:
    // inside and outside would mean nothing for a model of it.
    if largest <= 0.0 || smallest <= largest * 1e-10 {
        let what = match N {
            2 => "straight line",
            _ => "plane",
        };
        return Err(FitError::Degenerate { dims: N, what });
    }
    Ok(())
}

/// Segments across the data along each point's normal, from inside to outside, each end half-way to the medial
/// axis (the deepest offset that stays nearer its own point than any other), so never past the middle of a thin
/// section. The surface crosses each such segment once, at the point. A model whose zero set crosses one more than
/// once has a sliver of spurious surface beside the data (fitting distances alone can grow one inside a thin
/// trailing edge), and there deviations get the wrong sign. A model that misses a segment altogether (the rounded
/// tip of a sharp edge, which no single polynomial follows) is not counted: its distances show it.
pub(crate) struct SideProbes<const N: usize> {
    segments: Vec<(SVector<f64, N>, SVector<f64, N>)>,
}

/// Samples along a side segment: enough to see a sliver a tenth of the segment wide.
const SIDE_SAMPLES: usize = 12;

impl<const N: usize> SideProbes<N> {
    /// The segments, from the offsets whose largest is PROBE_REACH.
    fn new(unit: &[SVector<f64, N>], normals: &[SVector<f64, N>], offsets: &[Offsets]) -> Self {
        // Segments shallower than this could be crossed twice through the probe noise alone.
        let deep_enough = |d: Option<f64>| d.filter(|d| *d >= PROBE_MIN_DEPTH);
        let segments = unit
            .iter()
            .zip(normals)
            .zip(offsets)
            .filter_map(|((u, n), &o)| {
                let inside = deep_enough(o.inside)?;
                let outside = deep_enough(o.outside)?;
                Some((u - n * (0.5 * inside), u + n * (0.5 * outside)))
            })
            .collect();
        Self { segments }
    }

    /// How many segments the polynomial's zero set (in normalised coordinates) crosses more than once.
    fn crossed_again(&self, poly: &Poly<N>) -> usize {
        self.segments
            .par_iter()
            .filter(|(inside, outside)| {
                let mut previous = poly.value(inside);
                let mut changes = 0;
                for k in 1..=SIDE_SAMPLES {
                    let t = k as f64 / SIDE_SAMPLES as f64;
                    let value = poly.value(&(inside + (outside - inside) * t));
                    if value * previous < 0.0 {
                        changes += 1;
                    }
                    previous = value;
                }
                changes > 1
            })
            .count()
    }

    fn len(&self) -> usize {
        self.segments.len()
    }
}

/// Ridge penalty per coefficient: kappa * rows * beta_|e| * (prod e_k!) / |e|!, with beta_k the mean of |u|^(2k)
/// over the data. The factorial ratio makes sum w a^2 a rotation-invariant norm of each homogeneous part.
fn ridge_weights<const N: usize>(
    basis: &Basis<N>,
    unit: &[SVector<f64, N>],
    kappa: f64,
) -> Vec<f64> {
    let moments: Vec<f64> = (0..=basis.degree())
        .map(|k| {
            unit.iter()
                .map(|u| u.norm_squared().powi(k as i32))
                .sum::<f64>()
                / unit.len() as f64
        })
        .collect();
    let rows = 3.0 * unit.len() as f64;
    basis
        .exponents()
        .iter()
        .map(|e| {
            let total: usize = e.iter().map(|&x| x as usize).sum();
            let ratio =
                e.iter().map(|&x| factorial(x as usize)).product::<f64>() / factorial(total);
            kappa * rows * moments[total] * ratio
        })
        .collect()
}

/// Solves the (regularised) 3L system: the data rows (already reduced, target 0), for each point an offset row on
/// each side where it has a safe offset (target -c inside, +c outside), and the ridge rows (`ridge`: the square
/// roots of the weights). Returns the coefficients and the condition number.
fn solve_three_level<const N: usize>(
    monomials: &Monomials<N>,
    data_rows: &Reduced,
    unit: &[SVector<f64, N>],
    normals: &[SVector<f64, N>],
    offsets: &[Offsets],
    ridge: Option<&[f64]>,
) -> Result<(Vec<f64>, f64), FitError> {
    let offset_rows = Reduced::of_rows(unit.len(), 2, monomials.len(), |i, rows| {
        let (u, n, o) = (&unit[i], &normals[i], &offsets[i]);
        if let Some(c) = o.inside {
            monomials.fill(&(u - n * c), rows.push(-c));
        }
        if let Some(c) = o.outside {
            monomials.fill(&(u + n * c), rows.push(c));
        }
    });
    Reduced::stack(&[data_rows.clone(), offset_rows], ridge)
        .solve()
        .ok_or(FitError::Singular)
}

/// Current foot points of the data in normalised coordinates, refreshed for each trial model.
struct Feet<const N: usize> {
    points: Vec<SVector<f64, N>>,
    distances: Vec<f64>,
}

/// Feet of every data point on `poly`'s zero set, each started from `starts` (the previous feet) or, failing that,
/// from the point's own projection onto the curve, and checked. `None` when some point has no foot: the candidate
/// model is then rejected as a step.
fn feet_of<const N: usize>(
    poly: &Poly<N>,
    unit: &[SVector<f64, N>],
    starts: &[SVector<f64, N>],
) -> Option<Feet<N>> {
    let checked = |u: &SVector<f64, N>, start: &SVector<f64, N>| {
        lagrange_newton(poly, u, start).filter(|f| !crosses_zero_set(poly, u, &f.point))
    };
    // Each point's foot depends only on its own start: the points are done in parallel.
    let feet: Vec<Foot<N>> = unit
        .par_iter()
        .zip(starts)
        .map(|(u, start)| {
            checked(u, start).or_else(|| {
                let projected = project_to_zero_set(poly, u, 0.5)?;
                checked(u, &projected)
            })
        })
        .collect::<Option<_>>()?;
    Some(Feet {
        points: feet.iter().map(|f| f.point).collect(),
        distances: feet.iter().map(|f| f.distance).collect(),
    })
}

/// Levenberg-Marquardt on the exact distances. Returns the refined polynomial and the iteration count, or `None`
/// when the starting model is too far from the data for foot points to be found (the 3L answer then stands).
///
/// No ridge term and no constraint on the zero set away from the data: a ridge weight is relative to algebraic
/// residuals and would dominate distances of a few microns, and forbidding new zero-set components blocks the
/// optimum even for the paper's own published quartic, which has a second branch inside twice its data's box.
/// Spurious branches are therefore reported in the fit statistics (zero_set_components), not hidden. What is
/// constrained, when `probes` are given, is the side: no step may cross more side segments more than once than the
/// start does, since a sliver of zero set inside a thin edge would flip the sign of every deviation there.
fn refine_orthogonal<const N: usize>(
    start: &Poly<N>,
    monomials: &Monomials<N>,
    unit: &[SVector<f64, N>],
    probes: Option<&SideProbes<N>>,
) -> Option<(Poly<N>, usize)> {
    // With probes, a step may not put more of them on the wrong side than the start does.
    let allowed_slivers = probes.map(|p| p.crossed_again(start));
    let keeps_sides = |candidate: &Poly<N>| match (probes, allowed_slivers) {
        (Some(p), Some(allowed)) => p.crossed_again(candidate) <= allowed,
        _ => true,
    };
    let projected: Vec<SVector<f64, N>> = unit
        .par_iter()
        .map(|u| project_to_zero_set(start, u, 0.5))
        .collect::<Option<_>>()?;
    let mut poly = normalise_gradient(start.clone(), &projected);
    let mut feet = feet_of(&poly, unit, &projected)?;
    let sum_of_squares = |feet: &Feet<N>| feet.distances.iter().map(|d| d * d).sum::<f64>();
    let mut current = sum_of_squares(&feet);
    let mut damping: f64 = 1e-3;
    let m = poly.coeffs().len();
    let n = unit.len();
    let mut iterations = 0;
    while iterations < ODR_MAX_ITERATIONS && current > 0.0 {
        iterations += 1;
        // Rows: distances (d_i changes by m(f_i) . da / |grad P(f_i)|), then a gauge row that forbids a pure change
        // of scale (P and lambda P have the same zero set), then the damping rows. The first two are reduced once
        // per iteration; each damping tried then only stacks its diagonal under that triangle.
        let coeffs = DVector::from_column_slice(poly.coeffs());
        let gauge = coeffs.normalize() * (n as f64).sqrt();
        let jacobian = Reduced::of_rows(n + 1, 1, m, |i, rows| {
            if i == n {
                rows.push(0.0).copy_from_slice(gauge.as_slice());
                return;
            }
            let (_, g) = poly.value_gradient(&feet.points[i]);
            let gn = g.norm();
            let row = rows.push(-feet.distances[i]);
            monomials.fill(&feet.points[i], row);
            row.iter_mut().for_each(|v| *v /= gn);
        });
        let column_norms: Vec<f64> = jacobian
            .column_norms()
            .iter()
            .map(|c| c.max(1e-12))
            .collect();
        let mut accepted = false;
        for _ in 0..12 {
            let diagonal: Vec<f64> = column_norms.iter().map(|c| damping.sqrt() * c).collect();
            let damped = Reduced::stack(std::slice::from_ref(&jacobian), Some(&diagonal));
            let Some((step, _)) = damped.solve() else {
                damping *= 10.0;
                continue;
            };
            let candidate_coeffs: Vec<f64> = coeffs.iter().zip(&step).map(|(a, s)| a + s).collect();
            let candidate =
                normalise_gradient(Poly::new(poly.degree(), candidate_coeffs), &feet.points);
            if let Some(candidate_feet) = feet_of(&candidate, unit, &feet.points) {
                let value = sum_of_squares(&candidate_feet);
                if value < current && keeps_sides(&candidate) {
                    let improvement = (current - value) / current;
                    poly = candidate;
                    feet = candidate_feet;
                    current = value;
                    damping = (damping / 3.0).max(1e-12);
                    accepted = true;
                    if improvement < 1e-9 {
                        return Some((poly, iterations));
                    }
                    break;
                }
            }
            damping *= 5.0;
        }
        if !accepted {
            break;
        }
    }
    Some((poly, iterations))
}

/// Rescales P so that its gradient has unit RMS length at the given points (P is then distance-like near them).
fn normalise_gradient<const N: usize>(mut poly: Poly<N>, at: &[SVector<f64, N>]) -> Poly<N> {
    // The gradients in parallel, their sum in order: the same scale whatever the number of threads, and the
    // same as a plain sequential sum, so the refinement takes the steps it took before it ran in parallel.
    let squares: Vec<f64> = at
        .par_iter()
        .map(|p| poly.value_gradient(p).1.norm_squared())
        .collect();
    let mean_square = squares.iter().sum::<f64>() / at.len() as f64;
    let factor = 1.0 / mean_square.sqrt();
    if factor.is_finite() {
        poly.coeffs_mut().iter_mut().for_each(|c| *c *= factor);
    }
    poly
}

/// Fit statistics of a world-coordinate model against the points it was fitted to.
fn measure<const N: usize>(
    model: &IpModel<N>,
    points: &[SVector<f64, N>],
    domain: &Aabb<N>,
    cells: usize,
) -> FitStats {
    let samples = ZeroSetSamples::new(model, &domain.scaled(2.0), cells);
    let exact = ExactDistance::new(model, &samples);
    let mut sum_squares = 0.0;
    let mut max = (0.0f64, points[0]);
    let mut failed = 0;
    let mut counted = 0;
    let feet: Vec<_> = points
        .par_chunks(MEASURE_RUN)
        .flat_map_iter(|run| exact.feet_along_scan(run))
        .collect();
    for (p, foot) in points.iter().zip(feet) {
        match foot {
            Ok(foot) => {
                counted += 1;
                sum_squares += foot.distance * foot.distance;
                if foot.distance.abs() > max.0 {
                    max = (foot.distance.abs(), *p);
                }
            }
            Err(_) => failed += 1,
        }
    }
    FitStats {
        points: points.len(),
        rms_distance_mm: (sum_squares / counted.max(1) as f64).sqrt(),
        max_distance_mm: max.0,
        max_distance_at: max.1.iter().copied().collect(),
        condition_number: f64::NAN,
        zero_set_components: samples.components(),
        branches_beside_data: samples.branches_beside(points, BESIDE_DATA * domain.diagonal()),
        offset_min_mm: 0.0,
        offset_max_mm: 0.0,
        refinement_iterations: 0,
        points_without_foot: failed,
        side_segments: 0,
        side_segments_crossed_again: 0,
    }
}

#[cfg(test)]
pub(crate) mod tests;
