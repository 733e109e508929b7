//! The best fit of a measured section to its nominal, in the section's plane: the rigid motion (two translations
//! and a rotation about a pivot, or the translations only) that brings the measured points onto the nominal, by
//! least squares (L2) or by minimum zone (Chebyshev: the narrowest band about the nominal that holds every point),
//! and what is left after it, the section's form error. What blade software reports per section: where the section
//! lies (shifted along the chord, along the thickness, twisted) and how far its shape is off once that is removed.
//!
//! The nominal is given as a distance oracle: for each point, its signed normal distance to the nominal (positive
//! on the outside) and the nominal's outward unit normal at the foot. Both fits are Gauss-Newton on those
//! distances: each step solves the linearised problem (a least-squares solve, or a small linear programme for the
//! minimum zone) and the distances are measured again, until the step is below a nanometre.

use nalgebra::{Matrix3, Rotation2, Vector2, Vector3};

/// What the fit may move.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FitMode {
    /// Nothing: the deviations as measured.
    None,
    /// The two translations in the section plane.
    Translation,
    /// The translations and the rotation about the pivot.
    Full,
}

/// What the fit minimises.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FitMethod {
    /// The sum of squared normal deviations.
    L2,
    /// The largest absolute normal deviation (the minimum zone about the nominal).
    MinZone,
}

/// A point's signed normal distance to the nominal (mm, positive outside) and the nominal's outward unit normal at
/// its foot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Measured {
    pub distance_mm: f64,
    pub normal: Vector2<f64>,
}

/// The form error of a section: its normal deviations after the fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Form {
    pub min_mm: f64,
    pub max_mm: f64,
    pub rms_mm: f64,
    /// The width of the narrowest band centred on the nominal that holds every point: twice the largest absolute
    /// deviation.
    pub zone_mm: f64,
}

impl Form {
    fn of(deviations: &[f64]) -> Form {
        let min = deviations.iter().copied().fold(f64::INFINITY, f64::min);
        let max = deviations.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let rms = (deviations.iter().map(|d| d * d).sum::<f64>() / deviations.len() as f64).sqrt();
        Form {
            min_mm: min,
            max_mm: max,
            rms_mm: rms,
            zone_mm: 2.0 * min.abs().max(max.abs()),
        }
    }
}

/// Where the measured section lies against its nominal, and its form once that is removed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SectionFit {
    /// How the measured section is displaced from the nominal, mm: along the chord, and along the thickness
    /// direction (the chord turned by +90 degrees in the plane).
    pub dchord_mm: f64,
    pub dn_mm: f64,
    /// How the measured section is turned from the nominal about the pivot, degrees, counter-clockwise positive.
    pub rotation_deg: f64,
    /// Each point's normal deviation as measured, and after the fit.
    pub before_mm: Vec<f64>,
    pub after_mm: Vec<f64>,
    pub form_before: Form,
    pub form: Form,
}

/// Why a section could not be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(crate) enum SectionFitError {
    #[error("{needed} points are needed for this fit, the section has {got}")]
    TooFewPoints { needed: usize, got: usize },
    #[error(
        "point {index} of the section has no foot on the nominal (after moving it by the fit)"
    )]
    NoFoot { index: usize },
    #[error(
        "the fit did not settle in {0} steps: the section may not be a section of this nominal"
    )]
    NoConvergence(usize),
    #[error("the minimum-zone step could not be solved: {0}")]
    Programme(String),
}

/// Gauss-Newton steps before giving up.
const MAX_STEPS: usize = 100;
/// A step moving no point by more than this (mm, a nanometre) ends the fit.
const SETTLED_MM: f64 = 1e-6;
/// A minimum-zone step narrowing the band by less than this (mm) is no step.
const ZONE_GAIN_MM: f64 = 1e-11;

/// A rigid motion of the section plane: rotate by `angle` about `pivot`, then translate by `shift`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Motion {
    shift: Vector2<f64>,
    angle: f64,
}

impl Motion {
    fn apply(&self, pivot: &Vector2<f64>, p: &Vector2<f64>) -> Vector2<f64> {
        Rotation2::new(self.angle) * (p - pivot) + pivot + self.shift
    }
}

/// Fits the measured `points` to the nominal measured by `measure` (one [`Measured`] per point, `None` where a
/// point has no foot), rotating about `pivot`; `chord` is the section's chord direction (any length), which the
/// displacement is reported along.
pub(crate) fn fit_section(
    points: &[Vector2<f64>],
    pivot: Vector2<f64>,
    chord: Vector2<f64>,
    mode: FitMode,
    method: FitMethod,
    measure: impl Fn(&[Vector2<f64>]) -> Vec<Option<Measured>>,
) -> Result<SectionFit, SectionFitError> {
    let unknowns = match mode {
        FitMode::None => 0,
        FitMode::Translation => 2,
        FitMode::Full => 3,
    };
    if points.len() <= unknowns.max(1) {
        return Err(SectionFitError::TooFewPoints {
            needed: unknowns.max(1) + 1,
            got: points.len(),
        });
    }
    let measure_all = |motion: &Motion| -> Result<Vec<Measured>, SectionFitError> {
        let moved: Vec<Vector2<f64>> = points.iter().map(|p| motion.apply(&pivot, p)).collect();
        measure(&moved)
            .into_iter()
            .enumerate()
            .map(|(index, m)| m.ok_or(SectionFitError::NoFoot { index }))
            .collect()
    };
    let identity = Motion {
        shift: Vector2::zeros(),
        angle: 0.0,
    };
    let before: Vec<f64> = measure_all(&identity)?
        .iter()
        .map(|m| m.distance_mm)
        .collect();
    let reach = points
        .iter()
        .map(|p| (p - pivot).norm())
        .fold(0.0, f64::max);
    let mut motion = identity;
    let mut measured = measure_all(&motion)?;
    // The minimum zone starts from the least-squares fit: its linear programmes then only refine a motion that is
    // already close, and the zone they end with can never be wider than least squares' band.
    let stages: &[FitMethod] = match method {
        FitMethod::L2 => &[FitMethod::L2],
        FitMethod::MinZone => &[FitMethod::L2, FitMethod::MinZone],
    };
    for &stage in stages {
        let mut settled = unknowns == 0;
        // How far the minimum zone's linear programme may move a point (mm): it shrinks to the step last
        // accepted when a step had to be halved, so that a poor linear model (the worst points at a sharp edge)
        // ends in ever smaller steps, not in a zigzag.
        let mut trust = 4.0 * current_worst(&measured).max(1e-6);
        for _ in 0..MAX_STEPS {
            if settled {
                break;
            }
            // Each row: how the point's distance changes with (shift x, shift y, angle) of the current motion.
            let rows: Vec<(f64, Vector3<f64>)> = points
                .iter()
                .zip(&measured)
                .map(|(p, m)| {
                    let arm = Rotation2::new(motion.angle) * (p - pivot);
                    let turn = Vector2::new(-arm.y, arm.x);
                    let row = Vector3::new(m.normal.x, m.normal.y, m.normal.dot(&turn));
                    (m.distance_mm, row)
                })
                .collect();
            let step = match stage {
                FitMethod::L2 => l2_step(&rows, unknowns),
                FitMethod::MinZone => minzone_step(&rows, unknowns, trust)?,
            };
            let moved_by = Vector2::new(step.x, step.y).norm() + step.z.abs() * reach;
            // A step counts only if it improves the fit: the linear model is poor where the normals turn fast
            // (a sharp edge, where the distance may switch to the edge's wedge), and where the minimum zone is
            // degenerate (many points on the band at once) its programmes may wander among equal answers. A step
            // that does not improve is halved until it does; none that does ends the fit.
            let current = objective(stage, &measured);
            let mut trial = step;
            let mut moved = moved_by;
            settled = true;
            for halving in 0..30 {
                let candidate = Motion {
                    shift: motion.shift + Vector2::new(trial.x, trial.y),
                    angle: motion.angle + trial.z,
                };
                let next = measure_all(&candidate)?;
                if objective(stage, &next) < current - gain(stage, current) {
                    motion = candidate;
                    measured = next;
                    trust = if halving == 0 { 2.0 * trust } else { moved };
                    settled = moved < SETTLED_MM;
                    break;
                }
                trial /= 2.0;
                moved /= 2.0;
            }
        }
        if !settled {
            return Err(SectionFitError::NoConvergence(MAX_STEPS));
        }
    }
    let after: Vec<f64> = measured.iter().map(|m| m.distance_mm).collect();
    // The fit maps measured onto nominal: the section itself is displaced by the inverse motion.
    let displacement = -(Rotation2::new(-motion.angle) * motion.shift);
    let along = chord.try_normalize(0.0).unwrap_or_else(Vector2::x);
    let across = Vector2::new(-along.y, along.x);
    Ok(SectionFit {
        dchord_mm: displacement.dot(&along),
        dn_mm: displacement.dot(&across),
        rotation_deg: -motion.angle.to_degrees(),
        form_before: Form::of(&before),
        form: Form::of(&after),
        before_mm: before,
        after_mm: after,
    })
}

/// What a stage minimises: the sum of squared deviations, or the largest absolute one.
fn objective(stage: FitMethod, measured: &[Measured]) -> f64 {
    match stage {
        FitMethod::L2 => measured.iter().map(|m| m.distance_mm * m.distance_mm).sum(),
        FitMethod::MinZone => current_worst(measured),
    }
}

/// The least improvement of the objective that counts as one: the rounding of its sum, or of the zone.
fn gain(stage: FitMethod, objective: f64) -> f64 {
    match stage {
        FitMethod::L2 => 1e-13 * objective,
        FitMethod::MinZone => ZONE_GAIN_MM,
    }
}

fn current_worst(measured: &[Measured]) -> f64 {
    measured
        .iter()
        .map(|m| m.distance_mm.abs())
        .fold(0.0, f64::max)
}

/// The Gauss-Newton step of least squares: minimises the sum of (d + row . step)^2 over the first `unknowns`
/// parameters (normal equations of at most 3 x 3: the rows are unit normals and lever arms, well conditioned for a
/// section that is not a circle about the pivot).
fn l2_step(rows: &[(f64, Vector3<f64>)], unknowns: usize) -> Vector3<f64> {
    let mut normal = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for (d, row) in rows {
        let row = mask(row, unknowns);
        normal += row * row.transpose();
        rhs -= row * *d;
    }
    for k in unknowns..3 {
        normal[(k, k)] = 1.0;
    }
    normal
        .cholesky()
        .map(|c| c.solve(&rhs))
        .unwrap_or_else(Vector3::zeros)
}

/// The step of the minimum zone: minimises t subject to -t <= d + row . step <= t for every point, a linear
/// programme in the step and t; the step moves no point by more than `bound` (mm), where the linearisation holds.
fn minzone_step(
    rows: &[(f64, Vector3<f64>)],
    unknowns: usize,
    bound: f64,
) -> Result<Vector3<f64>, SectionFitError> {
    use microlp::{ComparisonOp, OptimizationDirection, Problem};
    let mut problem = Problem::new(OptimizationDirection::Minimize);
    let reach = rows
        .iter()
        .map(|(_, r)| r.z.abs())
        .fold(0.0, f64::max)
        .max(1e-9);
    let vars: Vec<_> = (0..unknowns)
        .map(|k| {
            // The angle bound turns the farthest point by about as much as a shift may move it.
            let b = if k == 2 { bound / reach } else { bound };
            problem.add_var(0.0, (-b, b))
        })
        .collect();
    let t = problem.add_var(1.0, (0.0, f64::INFINITY));
    for (d, row) in rows {
        let mut upper: Vec<(microlp::Variable, f64)> =
            vars.iter().enumerate().map(|(k, v)| (*v, row[k])).collect();
        upper.push((t, -1.0));
        problem.add_constraint(upper.as_slice(), ComparisonOp::Le, -d);
        let mut lower: Vec<(microlp::Variable, f64)> = vars
            .iter()
            .enumerate()
            .map(|(k, v)| (*v, -row[k]))
            .collect();
        lower.push((t, -1.0));
        problem.add_constraint(lower.as_slice(), ComparisonOp::Le, *d);
    }
    let solution = problem
        .solve()
        .map_err(|e| SectionFitError::Programme(e.to_string()))?;
    let mut step = Vector3::zeros();
    for (k, v) in vars.iter().enumerate() {
        step[k] = solution[*v];
    }
    Ok(step)
}

fn mask(row: &Vector3<f64>, unknowns: usize) -> Vector3<f64> {
    Vector3::from_fn(|k, _| if k < unknowns { row[k] } else { 0.0 })
}

#[cfg(test)]
mod tests;
