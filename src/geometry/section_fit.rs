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

/// How far a fit may move the section, each of the displacements it reports held within +-limit (`None`: free):
/// blade software's best fit with constraints, where a section may only be moved as far as its position tolerance
/// allows and what is left counts as form.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct FitLimits {
    pub dchord_mm: Option<f64>,
    pub dn_mm: Option<f64>,
    pub rotation_deg: Option<f64>,
}

impl FitLimits {
    /// The bounds of (dchord, dn, rotation in rad).
    fn bounds(&self) -> [f64; 3] {
        [
            self.dchord_mm.unwrap_or(f64::INFINITY),
            self.dn_mm.unwrap_or(f64::INFINITY),
            self.rotation_deg.map_or(f64::INFINITY, f64::to_radians),
        ]
    }
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
    /// Which of (dchord, dn, rotation) the fit left at its limit: the section lies farther off than it may be moved.
    pub at_limit: [bool; 3],
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

/// The fit's unknowns: how the section is displaced from the nominal along the chord and the thickness direction
/// (mm) and turned about the pivot (rad, counter-clockwise), the quantities reported and limited.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Placement {
    /// (dchord, dn, turn).
    x: Vector3<f64>,
}

impl Placement {
    /// This placement moved by `step`, each unknown held within its limit `bound`.
    fn stepped(&self, step: &Vector3<f64>, bound: &Vector3<f64>) -> Placement {
        Placement {
            x: (self.x + step).zip_map(bound, |x, b| x.clamp(-b, b)),
        }
    }
}

/// The section's own axes: the pivot its turn is about, the chord's unit direction and the thickness direction
/// (the chord turned +90 degrees). A measured point p is brought onto the nominal by the inverse of a placement:
/// q = R(-turn) (p - pivot - displacement) + pivot.
struct SectionAxes {
    pivot: Vector2<f64>,
    along: Vector2<f64>,
    across: Vector2<f64>,
}

impl SectionAxes {
    fn displacement(&self, placement: &Placement) -> Vector2<f64> {
        self.along * placement.x[0] + self.across * placement.x[1]
    }

    fn apply(&self, placement: &Placement, p: &Vector2<f64>) -> Vector2<f64> {
        Rotation2::new(-placement.x[2]) * (p - self.pivot - self.displacement(placement))
            + self.pivot
    }

    /// How q moves with each unknown: d q / d (dchord, dn, turn).
    fn derivatives(&self, placement: &Placement, p: &Vector2<f64>) -> [Vector2<f64>; 3] {
        let back = Rotation2::new(-placement.x[2]);
        let arm = back * (p - self.pivot - self.displacement(placement));
        [
            -(back * self.along),
            -(back * self.across),
            Vector2::new(arm.y, -arm.x),
        ]
    }
}

/// Fits the measured `points` to the nominal measured by `measure` (one [`Measured`] per point, `None` where a
/// point has no foot), rotating about `pivot`, each displacement held within `limits`; `chord` is the section's
/// chord direction (any length), which the displacement is reported along.
pub(crate) fn fit_section(
    points: &[Vector2<f64>],
    pivot: Vector2<f64>,
    chord: Vector2<f64>,
    mode: FitMode,
    method: FitMethod,
    limits: &FitLimits,
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
    let along = chord.try_normalize(0.0).unwrap_or_else(Vector2::x);
    let axes = SectionAxes {
        pivot,
        along,
        across: Vector2::new(-along.y, along.x),
    };
    // A parameter the mode does not move is held at zero, like one limited to zero.
    let bound = limits.bounds();
    let bound = Vector3::from_fn(|k, _| if k < unknowns { bound[k] } else { 0.0 });
    let measure_all = |placement: &Placement| -> Result<Vec<Measured>, SectionFitError> {
        let moved: Vec<Vector2<f64>> = points.iter().map(|p| axes.apply(placement, p)).collect();
        measure(&moved)
            .into_iter()
            .enumerate()
            .map(|(index, m)| m.ok_or(SectionFitError::NoFoot { index }))
            .collect()
    };
    let mut placement = Placement {
        x: Vector3::zeros(),
    };
    let before: Vec<f64> = measure_all(&placement)?
        .iter()
        .map(|m| m.distance_mm)
        .collect();
    let reach = points
        .iter()
        .map(|p| (p - pivot).norm())
        .fold(0.0, f64::max);
    let mut measured = measure_all(&placement)?;
    // The minimum zone starts from the least-squares fit: its linear programmes then only refine a placement that
    // is already close, and the zone they end with can never be wider than least squares' band.
    let stages: &[FitMethod] = match method {
        FitMethod::L2 => &[FitMethod::L2],
        FitMethod::MinZone => &[FitMethod::L2, FitMethod::MinZone],
    };
    for &stage in stages {
        let mut settled = unknowns == 0;
        // How far the minimum zone's linear programme may move a point (mm): a trust region, see [`ZoneStep`].
        let mut trust = 4.0 * current_worst(&measured).max(1e-6);
        for _ in 0..MAX_STEPS {
            if settled {
                break;
            }
            // Each row: how the point's distance changes with (dchord, dn, turn) of the current placement.
            let rows: Vec<(f64, Vector3<f64>)> = points
                .iter()
                .zip(&measured)
                .map(|(p, m)| {
                    let [a, b, turn] = axes.derivatives(&placement, p);
                    let row = Vector3::new(m.normal.dot(&a), m.normal.dot(&b), m.normal.dot(&turn));
                    (m.distance_mm, row)
                })
                .collect();
            // The step keeps the placement within its limits.
            let room = Step {
                lower: -bound - placement.x,
                upper: bound - placement.x,
            };
            settled = match stage {
                FitMethod::L2 => {
                    // A step counts only if it improves the fit: the linear model is poor where the normals turn
                    // fast (a sharp edge, where the distance may switch to the edge's wedge). A step that does not
                    // improve is halved until it does; none that does ends the fit. A halved step stays within the
                    // limits: they bound a box, and the placement and the whole step lie in it.
                    let mut trial = l2_step(&rows, &room);
                    let mut moved = Vector2::new(trial.x, trial.y).norm() + trial.z.abs() * reach;
                    let current = sum_of_squares(&measured);
                    let mut improved = None;
                    for _ in 0..30 {
                        let candidate = placement.stepped(&trial, &bound);
                        let next = measure_all(&candidate)?;
                        if sum_of_squares(&next) < current * (1.0 - L2_GAIN) {
                            improved = Some((candidate, next));
                            break;
                        }
                        trial /= 2.0;
                        moved /= 2.0;
                    }
                    match improved {
                        Some((candidate, next)) => {
                            placement = candidate;
                            measured = next;
                            moved < SETTLED_MM
                        }
                        None => true,
                    }
                }
                FitMethod::MinZone => {
                    let (step, predicted) = minzone_step(&rows, &room, trust)?;
                    let zone = ZoneStep {
                        placement: &mut placement,
                        measured: &mut measured,
                        trust: &mut trust,
                        reach,
                        bound: &bound,
                    };
                    zone.take(step, predicted, &measure_all)?
                }
            };
        }
        if !settled {
            return Err(SectionFitError::NoConvergence(MAX_STEPS));
        }
    }
    let after: Vec<f64> = measured.iter().map(|m| m.distance_mm).collect();
    // At a limit: within what a settled step may still move it (a nanometre; for the turn, a nanometre at the
    // farthest point). A limit of zero pins its parameter by the part file's choice and is not reported as reached.
    let settled_within = [SETTLED_MM, SETTLED_MM, SETTLED_MM / reach.max(1e-9)];
    let at_limit = [0, 1, 2].map(|k| {
        k < unknowns
            && bound[k].is_finite()
            && bound[k] > 0.0
            && bound[k] - placement.x[k].abs() <= settled_within[k]
    });
    Ok(SectionFit {
        dchord_mm: placement.x[0],
        dn_mm: placement.x[1],
        rotation_deg: placement.x[2].to_degrees(),
        form_before: Form::of(&before),
        form: Form::of(&after),
        before_mm: before,
        after_mm: after,
        at_limit,
    })
}

/// The room a step has in each unknown: from `lower` to `upper` (0 to 0 for one the fit does not move).
struct Step {
    lower: Vector3<f64>,
    upper: Vector3<f64>,
}

impl Step {
    fn free(&self, k: usize) -> bool {
        self.lower[k] < self.upper[k]
    }
}

/// What a stage minimises: the sum of squared deviations, or the largest absolute one.
/// The least-squares objective: the sum of squared distances.
fn sum_of_squares(measured: &[Measured]) -> f64 {
    measured.iter().map(|m| m.distance_mm * m.distance_mm).sum()
}

/// The least improvement of the sum of squares that counts as one: its rounding.
const L2_GAIN: f64 = 1e-13;

fn current_worst(measured: &[Measured]) -> f64 {
    measured
        .iter()
        .map(|m| m.distance_mm.abs())
        .fold(0.0, f64::max)
}

/// The Gauss-Newton step of least squares: minimises the sum of (d + row . step)^2 within the step's room. The
/// problem is a convex quadratic in at most 3 unknowns (normal equations of at most 3 x 3: the rows are unit normals
/// and lever arms, well conditioned for a section that is not a circle about the pivot), so its bounded minimum is
/// found exactly by trying each unknown free, at its lower or at its upper bound, and keeping the best of the
/// answers that lie within the room: the minimum has some such set of active bounds, and for that set it is the
/// unconstrained minimum of the rest.
fn l2_step(rows: &[(f64, Vector3<f64>)], room: &Step) -> Vector3<f64> {
    let mut normal = Matrix3::zeros();
    let mut gradient = Vector3::zeros();
    for (d, row) in rows {
        normal += row * row.transpose();
        gradient += row * *d;
    }
    let cost = |step: &Vector3<f64>| step.dot(&(normal * step)) + 2.0 * gradient.dot(step);
    // Not moving is always within the room (the placement is within its limits), and it costs nothing: no step
    // may be worse, even where a singular free set leaves the true minimum unsolved.
    let mut best = (0.0, Vector3::zeros());
    // Each unknown: 0 free, 1 at its lower bound, 2 at its upper bound; one it does not move sits at 0.
    for code in 0..27 {
        let state = [code % 3, code / 3 % 3, code / 9];
        let mut step = Vector3::zeros();
        let mut free = Vec::new();
        let mut possible = true;
        for k in 0..3 {
            match (room.free(k), state[k]) {
                (false, 0) => {}
                (false, _) => possible = false,
                (true, 0) => free.push(k),
                (true, 1) => step[k] = room.lower[k],
                (true, _) => step[k] = room.upper[k],
            }
            possible &= step[k].is_finite();
        }
        if !possible {
            continue;
        }
        // The free unknowns minimise with the others held: H_ff s_f = -(g_f + H_fc s_c).
        let rhs = -(gradient + normal * step);
        let solved = match free.len() {
            0 => Some(Vec::new()),
            _ => {
                let h = nalgebra::DMatrix::from_fn(free.len(), free.len(), |i, j| {
                    normal[(free[i], free[j])]
                });
                let r = nalgebra::DVector::from_fn(free.len(), |i, _| rhs[free[i]]);
                h.cholesky().map(|c| c.solve(&r).iter().copied().collect())
            }
        };
        let Some(values) = solved else {
            continue;
        };
        for (k, v) in free.iter().zip(values) {
            step[*k] = v;
        }
        // Within the room, allowing for the rounding of the solve.
        let slack = |k: usize| 1e-12 * (1.0 + step[k].abs());
        if (0..3).any(|k| step[k] < room.lower[k] - slack(k) || step[k] > room.upper[k] + slack(k))
        {
            continue;
        }
        let step = step.zip_zip_map(&room.lower, &room.upper, |s, lo, hi| s.clamp(lo, hi));
        let value = cost(&step);
        if value < best.0 {
            best = (value, step);
        }
    }
    best.1
}

/// The step of the minimum zone: minimises t subject to -t <= d + row . step <= t for every point, a linear
/// programme in the step and t; the step stays within its room and moves no point by more than `trust` (mm),
/// where the linearisation holds.
/// One step of the minimum zone's trust region: the linear programme's step is taken where the zone narrows by at
/// least [`ZONE_ACCEPT`] of what the programme predicted, and the trust grows after a step that did as predicted
/// and shrinks to a quarter of one that did not. Why not halving a step until it narrows the zone at all: where
/// the normals turn fast (a dense scan of a nose, a sharp edge) the linear model misleads, and a halved step that
/// gains a few nanometres was taken step after step in a zigzag that never settled (a propeller section scanned
/// every 2.5 deg round its nose: 100 steps of 40 um, the zone 10 nm narrower each).
struct ZoneStep<'a> {
    placement: &'a mut Placement,
    measured: &'a mut Vec<Measured>,
    trust: &'a mut f64,
    /// The farthest point's distance from the pivot, mm: a turn of the trust over it moves a point by the trust.
    reach: f64,
    bound: &'a Vector3<f64>,
}

/// A minimum-zone step is taken where it narrows the zone by at least this fraction of the predicted narrowing.
const ZONE_ACCEPT: f64 = 0.1;

impl ZoneStep<'_> {
    /// Takes or refuses `step`, whose programme predicted the zone `predicted` (mm); whether the fit has settled
    /// (the trust, or the narrowing the programme still finds, has fallen below what counts).
    fn take(
        self,
        step: Vector3<f64>,
        predicted: f64,
        measure_all: &impl Fn(&Placement) -> Result<Vec<Measured>, SectionFitError>,
    ) -> Result<bool, SectionFitError> {
        let current = current_worst(self.measured);
        let expected = current - predicted;
        if expected <= ZONE_GAIN_MM {
            return Ok(true);
        }
        let size = step
            .x
            .abs()
            .max(step.y.abs())
            .max(step.z.abs() * self.reach);
        let candidate = self.placement.stepped(&step, self.bound);
        let next = measure_all(&candidate)?;
        let ratio = (current - current_worst(&next)) / expected;
        if ratio >= ZONE_ACCEPT {
            *self.placement = candidate;
            *self.measured = next;
        }
        *self.trust = if ratio < 0.25 {
            0.25 * size.min(*self.trust)
        } else if ratio > 0.75 {
            2.0 * *self.trust
        } else {
            *self.trust
        };
        Ok(*self.trust < SETTLED_MM)
    }
}

/// The linear programme's step for the minimum zone, and the zone it predicts (mm).
fn minzone_step(
    rows: &[(f64, Vector3<f64>)],
    room: &Step,
    trust: f64,
) -> Result<(Vector3<f64>, f64), SectionFitError> {
    use microlp::{ComparisonOp, OptimizationDirection, Problem};
    let mut problem = Problem::new(OptimizationDirection::Minimize);
    let reach = rows
        .iter()
        .map(|(_, r)| r.z.abs())
        .fold(0.0, f64::max)
        .max(1e-9);
    let vars: Vec<(usize, microlp::Variable)> = (0..3)
        .filter(|&k| room.free(k))
        .map(|k| {
            // The turn's trust turns the farthest point by about as much as a shift may move it.
            let b = if k == 2 { trust / reach } else { trust };
            let (lo, hi) = (room.lower[k].max(-b), room.upper[k].min(b));
            (k, problem.add_var(0.0, (lo, hi)))
        })
        .collect();
    let t = problem.add_var(1.0, (0.0, f64::INFINITY));
    for (d, row) in rows {
        let mut upper: Vec<(microlp::Variable, f64)> =
            vars.iter().map(|(k, v)| (*v, row[*k])).collect();
        upper.push((t, -1.0));
        problem.add_constraint(upper.as_slice(), ComparisonOp::Le, -d);
        let mut lower: Vec<(microlp::Variable, f64)> =
            vars.iter().map(|(k, v)| (*v, -row[*k])).collect();
        lower.push((t, -1.0));
        problem.add_constraint(lower.as_slice(), ComparisonOp::Le, *d);
    }
    let solution = problem
        .solve()
        .map_err(|e| SectionFitError::Programme(e.to_string()))?;
    let mut step = Vector3::zeros();
    for (k, v) in &vars {
        step[*k] = solution[*v];
    }
    Ok((step, solution[t]))
}

#[cfg(test)]
mod tests;
