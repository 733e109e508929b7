//! The ball rolling round an edge: a run of centres on one circle, whose centre is the edge's (or its round's)
//! middle.
//!
//! Why the quartic is not enough there: a scan turns the ball round a sharp or small-radius edge in steps of a few
//! degrees, so the centre path's curvature jumps from about 0 on a face to 1 / r on the roll within one step, and
//! the steps themselves shrink from the face's spacing to the roll's. A window of nine centres that straddles the
//! jump still fits a quartic to the noise (the path is smooth to first order), but its slope is off by tens of
//! milliradians: on the simulated propeller's sharp trailing edge (1 mm ball, 10 deg steps, 2 um noise) the
//! contacts whose windows reach from the roll onto the face stood 17 and 27 um proud of the edge, and the chord
//! ended on them. Along the roll itself a quartic of nine centres spends five coefficients on a circle, and its
//! slope's noise (0.34 sigma / h) moves each contact along the ball by r times that, off the edge's apex.
//!
//! A circle has three parameters and describes the roll exactly, whatever the edge's radius (a sharp edge's centre
//! path is a circle of the ball's radius about the apex; a round of radius R gives one of radius R + r about its
//! middle). So where the centres round the point being compensated lie on one circle within the noise, over a run
//! that may reach back beyond the quartic's window but not ahead of the centres come so far, and that circle is an
//! edge's (its surface radius at most [`MAX_EDGE_RADIUS`] of the ball's), the contact is taken from it: the centre
//! moved towards the circle's middle by the ball's radius. Where the centres from the point on lie on a sharp
//! edge's circle but have not turned far enough yet to place it ([`RollThrough::TooShortYet`]), the compensator
//! waits for more. A face's centres leave the circle by the square of their distance from the roll, so only a
//! face's point within a tenth of a millimetre or so of the roll's end can be taken as the roll's (its contact
//! then moves along the face towards the edge, and off it by no more than the noise allows).

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};

/// Centres before the point being compensated that a run may reach back to (beyond the quartic's window): a 1 mm
/// ball turning 10 deg per point takes 16 points round a sharp 20 deg trailing edge.
pub(super) const REACH_BACK: usize = 24;

/// A run of centres is a roll when their circle's surface radius (its radius less the ball's) is at most this
/// fraction of the ball's radius: there the quartic cannot follow the path at the steps a scan takes; wider rounds
/// (an airfoil's nose) are left to it, which follows them exactly.
const MAX_EDGE_RADIUS: f64 = 0.25;

/// Every centre of a roll lies this many noise sigmas or less from its circle.
const MAX_SIGMAS: f64 = 4.0;

/// A centre lies on the circle of the run beside it within this many noise sigmas inside it (the circle's own
/// noise added to the centre's, extrapolated one step) ...
const PREDICTION_SIGMAS: f64 = 6.0;

/// ... and this many outside it. A face's centre beside the roll stands outside the circle, by `s^2 / 2 r` at `s`
/// along the face from the roll's end, and the circle refitted through it leans inside the apex by as much: with
/// 6 sigma either side, a roll's last contacts stood 11 um inside on the simulated propeller's blade C, whose faces
/// beside its trailing edges were scanned at 0.085 mm, two of their centres within 12 um. A face's centre that
/// joins now lies within 0.11 mm of the roll's end, and its contact, taken off the circle, 6 um or less off the
/// apex; a roll's own centre this far out (one in 700) ends its run a centre early.
const OUTSIDE_SIGMAS: f64 = 3.0;

/// Residuals are allowed at least this much (mm), as for the quartic: noise-free paths fit to round-off.
const RESIDUAL_FLOOR_MM: f64 = 1e-4;

/// A roll has at least this many centres ...
const MIN_POINTS: usize = 5;

/// ... turning through at least this much from its first to its last, rad: 40 deg, five centres at a scan's
/// usual 10 deg steps. Over less a short arc's circle is no surer than the quartic.
const MIN_TURN_RAD: f64 = 0.69;

/// A run is taken as a round edge's (its radius fitted) only over at least this many centres; a shorter run's is
/// a sharp edge's or none. With a free radius a short run's circle takes in a face's centre next to the roll (the
/// radius swings by a tenth of a millimetre to reach it), and it leans the contacts along the ball by tens of
/// microns.
const MIN_ROUND_POINTS: usize = 2 * MIN_POINTS - 1;

/// ... and only over a run that turns through at least this much, rad (80 deg, nine centres at a scan's usual
/// 10 deg steps).
const MIN_ROUND_TURN_RAD: f64 = 1.39;

/// A run's edge is round only where its free radius stands this many of its own standard deviations from 0 ...
const ROUND_SIGNIFICANCE: f64 = 4.0;

/// ... fitted without this many centres at each end of the run, where a face's centre next to the roll may have
/// joined it.
const ROUND_TRIM: usize = 1;

/// Gauss-Newton steps of the circle fit, after its algebraic start.
const FIT_STEPS: usize = 6;

/// One centre of a run, in the section plane (2-D, mm): where it is, the radius `rho` of the ball's circle in the
/// plane there, and the in-plane direction of its reported normal (only orients the material side).
#[derive(Debug, Clone, Copy)]
pub(super) struct RollSample {
    pub centre: Vector2<f64>,
    pub rho: f64,
    pub normal: Vector2<f64>,
}

/// What the centres say of a roll through a point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum RollThrough {
    /// A roll: the in-plane unit direction from its middle to the point's centre (the contact is the centre moved
    /// back `rho` along it) and the edge's surface radius, mm.
    Roll {
        outward: Vector2<f64>,
        edge_radius_mm: f64,
    },
    /// The centres from the point to the newest lie on an edge's circle, but turn less than [`MIN_TURN_RAD`] so
    /// far: the roll may go on, and the next centres can tell.
    TooShortYet,
    /// No run of centres through the point is a roll, nor can later centres make one.
    NotARoll,
}

/// The roll through the point `at` of `samples` (the point's centres before it and up to the newest).
///
/// The run ends at the latest sample with which the point's centres still lie on one circle, then reaches back
/// as far as they do.
pub(super) fn roll_through(samples: &[RollSample], at: usize, noise_sigma_mm: f64) -> RollThrough {
    let tolerance = (MAX_SIGMAS * noise_sigma_mm).max(RESIDUAL_FLOOR_MM);
    let ball = samples[at].rho;
    let edge_circle = |run: &[RollSample]| {
        if !bends_like_an_edge(run, ball) {
            return None;
        }
        let sharp = Circle::algebraic(run)?.sharpened(run)?;
        // A round's free radius is no surer than the noise over a short arc, however many centres it has (a roll
        // in steps of 2 deg over 9 centres read a sharp edge as a 0.1 mm round, and its contacts 10-30 um off),
        // and an edge is taken as round only where its centres say so beyond the noise.
        let circle = if run.len() < MIN_ROUND_POINTS
            || sharp.turn(run).abs() < MIN_ROUND_TURN_RAD
            || !shows_a_round(run, noise_sigma_mm)
        {
            sharp
        } else {
            Circle::fit(run).filter(|c| c.is_edge(ball))?
        };
        circle.holds(run, tolerance).then_some(circle)
    };
    // A centre joins a run only if it lies on the circle of the run without it: a face's centre next to the roll
    // leaves the circle by the square of its distance from the roll's end, which a refit would take in, leaning
    // the circle and every contact taken from it.
    // A face's centre only ever stands outside the circle: see [`OUTSIDE_SIGMAS`]. Both limits allow for a circle
    // as sure as a centre where it predicts; one less sure (a run bunched over a few degrees) widens them by as
    // much (see [`Circle::extrapolation`]).
    let predicted = |circle: &Circle, run: &[RollSample], centre: &RollSample| {
        let residual = circle.residual(centre);
        let widen = circle.extrapolation(run, centre).max(1.0).sqrt();
        residual >= -PREDICTION_SIGMAS / MAX_SIGMAS * tolerance * widen
            && residual <= OUTSIDE_SIGMAS / MAX_SIGMAS * tolerance * widen
    };
    // ... of the same kind as the run's: a sharp edge's, or a round one's fitted with its radius.
    let on_circle_of = |kind: &Circle, run: &[RollSample], centre: &RollSample| {
        kind.refit(run).is_some_and(|c| predicted(&c, run, centre))
    };
    // The run from a core of centres `start..=end`, reaching back as far as its centres lie on its circle: its
    // length and what it makes of the point.
    let run_from = |mut start: usize, end: usize| {
        let mut circle = edge_circle(&samples[start..=end])?;
        if !on_circle_of(&circle, &samples[start..end], &samples[end])
            || !on_circle_of(&circle, &samples[start + 1..=end], &samples[start])
        {
            return None;
        }
        while start > 0 && predicted(&circle, &samples[start..=end], &samples[start - 1]) {
            match edge_circle(&samples[start - 1..=end]) {
                Some(wider) => circle = wider,
                None => break,
            }
            start -= 1;
        }
        Some((
            end - start,
            circle.roll_at(&samples[start..=end], at - start)??,
        ))
    };
    // The latest end first; from the fewest centres that can show a sharp edge, and from the fewest that can show
    // a round one, the longer run (a round's first centres fit a sharp edge's circle too, but their run stops
    // where the round's goes on).
    let roll = (at..samples.len()).rev().find_map(|end| {
        [MIN_POINTS, MIN_ROUND_POINTS]
            .into_iter()
            .filter_map(|points| run_from((end + 1).checked_sub(points)?.min(at), end))
            .max_by_key(|(length, _)| *length)
            .map(|(_, roll)| roll)
    });
    if let Some((outward, edge_radius_mm)) = roll {
        RollThrough::Roll {
            outward,
            edge_radius_mm,
        }
    } else if roll_may_follow(samples, at, tolerance) {
        RollThrough::TooShortYet
    } else {
        RollThrough::NotARoll
    }
}

/// Centres behind a point that show the path bending where a roll may start: the quartic's half window.
const BENDING_BEHIND: usize = 4;

/// The least turn of a run's reported normals that shows a roll starting, rad (1 deg): more than a machine's
/// normals wander along a face.
const MIN_NORMAL_TURN_RAD: f64 = 0.0175;

/// Whether a roll may be starting at the point `at`: the centres from it to the newest lie on a sharp edge's
/// circle, convex and turning less than [`MIN_TURN_RAD`] so far, and the centres after it leave the line of the
/// few before it or the reported normals turn with them (either says they are not a finely scanned face's, which
/// any circle as wide as the ball fits over a short stretch). In steps of a few degrees, the first centres of a
/// roll are too close together for [`bends_like_an_edge`] to see their circle.
fn roll_may_follow(samples: &[RollSample], at: usize, tolerance: f64) -> bool {
    let run = &samples[at..];
    if run.len() < 3 {
        return false;
    }
    let behind = &samples[at.saturating_sub(BENDING_BEHIND)..=at];
    let starts_a_roll =
        |circle: &Circle| circle.holds(run, tolerance) && circle.roll_at(run, 0) == Some(None);
    if let Some(circle) = Circle::algebraic(run).and_then(|c| c.sharpened(run)) {
        if starts_a_roll(&circle)
            && (behind.len() > 2 && leaves_the_line(behind, &samples[at + 1..], tolerance)
                || normals_turn_with(&circle, run))
        {
            return true;
        }
    }
    // Over a few degrees the centres' own circle may lie anywhere along them (its sag is under the noise, and its
    // fit's middle slides along the arc): the one the reported normals point from is tried too, as it is.
    // First, cheaply: the normals turn by at least half the angle the centres' span subtends on a ball's circle
    // (a face bending wider than the ball turns its normals by less).
    let (first, last) = (&run[0], &run[run.len() - 1]);
    let normals = first.normal.angle(&last.normal);
    normals >= 0.5 * (last.centre - first.centre).norm() / first.rho
        && Circle::from_normals(run)
            .is_some_and(|circle| normals_turn_with(&circle, run) && starts_a_roll(&circle))
}

/// Whether the reported normals of a run turn with its centres about the circle's middle: by at least half as much,
/// the same way, and by at least [`MIN_NORMAL_TURN_RAD`]. A finely scanned face's centres fit a ball-wide circle
/// over a short stretch too, but its normals stay put.
///
/// Why besides [`leaves_the_line`]: a roll in steps of half a degree (a blade's edge 0.95 mm inside the master's,
/// grazed by probing lines through the master's apex) starts right after the roll's first centres, which the line
/// of the few centres before it bends through; its centres did not leave that line within the look-ahead, and 14
/// of its contacts took the quartic over centres 10 um apart, 28-83 um off the apex. Waiting costs only latency:
/// a point that waits comes out as it would have at once once the centres tell.
fn normals_turn_with(circle: &Circle, run: &[RollSample]) -> bool {
    let turn = |from: Vector2<f64>, to: Vector2<f64>| from.perp(&to).atan2(from.dot(&to));
    let (first, last) = (&run[0], &run[run.len() - 1]);
    let normals = turn(first.normal, last.normal);
    normals.abs() >= MIN_NORMAL_TURN_RAD && {
        // The run turns less than MIN_TURN_RAD about the circle, so its ends tell its turn.
        let centres = turn(first.centre - circle.middle, last.centre - circle.middle);
        normals.signum() == centres.signum() && normals.abs() >= 0.5 * centres.abs()
    }
}

/// Whether a run's centres show a round edge, not a sharp one: the free radius of their circle, fitted without the
/// run's end centres, is at least [`ROUND_SIGNIFICANCE`] standard deviations (from the centres' noise, `sigma`
/// mm) from zero.
///
/// Why not the free radius itself: over the arc a scan rolls round a blade's trailing edge (80-150 deg), the
/// radius and the circle's middle along the arc's bisector are nearly the same parameter, so noise of 2 um reads
/// a sharp edge as a round of 5-25 um with its middle as far inside the apex; and a face's centre within a tenth
/// of a millimetre of the roll, which may join the run as its end (see [`OUTSIDE_SIGMAS`]), lies outside the
/// sharp edge's circle and pulls the free radius up by as much again. Taken as rounds, the contacts of the
/// simulated propeller's sharp trailing edges stood 5-10 um inside their apexes, and the chords read short by
/// that (blade C r400, 0.5 % short: 5.1 um).
fn shows_a_round(run: &[RollSample], sigma: f64) -> bool {
    let inner = &run[ROUND_TRIM..run.len() - ROUND_TRIM];
    let Some(circle) = Circle::fit(inner) else {
        return false;
    };
    // The radius' variance from the Gauss-Newton normal matrix at the fit: (J^T J)^-1 sigma^2.
    let normal_matrix = inner.iter().fold(Matrix3::<f64>::zeros(), |m, s| {
        let unit = (s.centre - circle.middle).normalize();
        let gradient = Vector3::new(-unit.x, -unit.y, -1.0);
        m + gradient * gradient.transpose()
    });
    normal_matrix.try_inverse().is_some_and(|inverse| {
        circle.surface_radius.abs() > ROUND_SIGNIFICANCE * sigma * inverse[(2, 2)].sqrt()
    })
}

/// Whether any of the centres `ahead` lies farther than `tolerance` from the least-squares line of the centres
/// `behind` (through their mean, along their principal direction).
fn leaves_the_line(behind: &[RollSample], ahead: &[RollSample], tolerance: f64) -> bool {
    let mean = behind.iter().map(|s| s.centre).sum::<Vector2<f64>>() / behind.len() as f64;
    let scatter = behind.iter().fold(Matrix2::zeros(), |m, s| {
        let d = s.centre - mean;
        m + d * d.transpose()
    });
    let eigen = scatter.symmetric_eigen();
    let across = eigen
        .eigenvectors
        .column(eigen.eigenvalues.imin())
        .into_owned();
    ahead
        .iter()
        .any(|s| (s.centre - mean).dot(&across).abs() > tolerance)
}

/// Whether the circle through a run's first, middle and last centres is anywhere near an edge's for a ball of
/// in-plane radius `ball` (within twice [`MAX_EDGE_RADIUS`] of the ball's radius): a cheap look that spares a face's
/// points (their centres on a nearly straight path) the fits.
fn bends_like_an_edge(run: &[RollSample], ball: f64) -> bool {
    let (a, b, c) = (
        run[0].centre,
        run[run.len() / 2].centre,
        run[run.len() - 1].centre,
    );
    let twice_area = (b - a).perp(&(c - a)).abs();
    let circumradius = (b - a).norm() * (c - b).norm() * (c - a).norm() / (2.0 * twice_area);
    (circumradius - ball).abs() <= 2.0 * MAX_EDGE_RADIUS * ball
}

/// A circle fitted to a run's centres: its middle, and the surface radius `R` with `|c - middle| = rho + R`.
#[derive(Debug, Clone, Copy)]
struct Circle {
    middle: Vector2<f64>,
    surface_radius: f64,
}

impl Circle {
    /// The algebraic circle through the centres (Kasa's: `x^2 + y^2 + D x + E y + F = 0` by least squares), the
    /// start of the orthogonal fits, its surface radius the mean `rho` taken off. `None` for centres on a line.
    fn algebraic(run: &[RollSample]) -> Option<Self> {
        let origin = run[0].centre;
        let mut normal_matrix = Matrix3::<f64>::zeros();
        let mut rhs = Vector3::<f64>::zeros();
        for s in run {
            let p = s.centre - origin;
            let row = Vector3::new(p.x, p.y, 1.0);
            normal_matrix += row * row.transpose();
            rhs -= row * p.norm_squared();
        }
        let abc = normal_matrix.lu().solve(&rhs)?;
        let middle = Vector2::new(-abc.x / 2.0, -abc.y / 2.0);
        let radius_sq = middle.norm_squared() - abc.z;
        if !(radius_sq.is_finite() && radius_sq > 0.0) {
            return None;
        }
        let mean_rho = run.iter().map(|s| s.rho).sum::<f64>() / run.len() as f64;
        Some(Circle {
            middle: middle + origin,
            surface_radius: radius_sq.sqrt() - mean_rho,
        })
    }

    /// The sharp edge's circle the reported normals point from: its middle the mean of the centres moved back
    /// their `rho` along their normals. `None` where no normal has an in-plane direction.
    fn from_normals(run: &[RollSample]) -> Option<Self> {
        let backs: Vec<Vector2<f64>> = run
            .iter()
            .filter_map(|s| Some(s.centre - s.normal.try_normalize(0.0)? * s.rho))
            .collect();
        (!backs.is_empty()).then(|| Circle {
            middle: backs.iter().sum::<Vector2<f64>>() / backs.len() as f64,
            surface_radius: 0.0,
        })
    }

    /// The least-squares circle (orthogonal distances, each centre's own `rho` taken off), refined from the
    /// algebraic one by Gauss-Newton. `None` for centres on a line or repeated.
    fn fit(run: &[RollSample]) -> Option<Self> {
        let start = Self::algebraic(run)?;
        let origin = run[0].centre;
        let mut middle = start.middle - origin;
        let mut surface_radius = start.surface_radius;
        for _ in 0..FIT_STEPS {
            let mut jtj = Matrix3::<f64>::zeros();
            let mut jtr = Vector3::<f64>::zeros();
            for s in run {
                let offset = s.centre - origin - middle;
                let distance = offset.norm();
                if distance == 0.0 {
                    return None;
                }
                let residual = distance - s.rho - surface_radius;
                let unit = offset / distance;
                let gradient = Vector3::new(-unit.x, -unit.y, -1.0);
                jtj += gradient * gradient.transpose();
                jtr += gradient * residual;
            }
            let step = jtj.lu().solve(&-jtr)?;
            middle += Vector2::new(step.x, step.y);
            surface_radius += step.z;
        }
        let middle = middle + origin;
        (middle.iter().all(|v| v.is_finite()) && surface_radius.is_finite()).then_some(Circle {
            middle,
            surface_radius,
        })
    }

    /// The circle of a sharp edge (surface radius 0: the centres a ball's radius from the apex) fitted to `run`
    /// by Gauss-Newton from this one's middle. A short run's free radius is noisy (tens of microns over five
    /// centres), which moves the contacts along the ball; where the centres cannot tell the edge from a sharp one,
    /// it is taken as sharp.
    fn sharpened(&self, run: &[RollSample]) -> Option<Self> {
        let mut middle = self.middle;
        for _ in 0..FIT_STEPS {
            let mut jtj = Matrix2::<f64>::zeros();
            let mut jtr = Vector2::<f64>::zeros();
            for s in run {
                let offset = s.centre - middle;
                let distance = offset.norm();
                if distance == 0.0 {
                    return None;
                }
                let gradient = -offset / distance;
                jtj += gradient * gradient.transpose();
                jtr += gradient * (distance - s.rho);
            }
            middle += jtj.lu().solve(&-jtr)?;
        }
        middle.iter().all(|v| v.is_finite()).then_some(Circle {
            middle,
            surface_radius: 0.0,
        })
    }

    /// The circle of the same kind as this one (sharp, or round with its radius fitted) fitted to `run`; a sharp
    /// one from this one's middle (a run bunched over a few degrees has an algebraic circle anywhere along it,
    /// from which Gauss-Newton need not come back).
    fn refit(&self, run: &[RollSample]) -> Option<Self> {
        match self.surface_radius {
            0.0 => self.sharpened(run),
            _ => Self::fit(run),
        }
    }

    /// The variance of this circle's residual at the centre `s`, fitted to `run`, in units of the centres' own
    /// noise variance: `g^T (J^T J)^-1 g`, with `J` the residuals' gradients over the run's centres and `g` the
    /// one at `s`, with respect to the circle's parameters (its middle, and its radius where fitted). 0 where the
    /// run cannot tell (repeated centres).
    ///
    /// Why: a centre joins a roll where it lies on the circle of the run beside it, and that circle is only as
    /// sure as the run's spread round it. A roll bunched in steps of half a degree (a blade's trailing edge 0.95 mm
    /// inside the master's, the ball grazing it on lines through the master's apex) turns 20 deg over 18 centres
    /// before jumping 75 deg: its circle predicts the next centre only within about 5 um (one sd) at 2 um noise,
    /// and the fixed limits (6 um outside) left the roll's contacts to the quartic over centres 10 um apart.
    fn extrapolation(&self, run: &[RollSample], s: &RollSample) -> f64 {
        let unit = |c: &RollSample| (c.centre - self.middle).try_normalize(0.0);
        let Some(at) = unit(s) else { return 0.0 };
        if self.surface_radius == 0.0 {
            let jtj = run
                .iter()
                .filter_map(unit)
                .fold(Matrix2::<f64>::zeros(), |m, u| m + u * u.transpose());
            jtj.try_inverse()
                .map_or(0.0, |inverse| (at.transpose() * inverse * at)[(0, 0)])
        } else {
            let gradient = |u: Vector2<f64>| Vector3::new(u.x, u.y, 1.0);
            let jtj = run
                .iter()
                .filter_map(unit)
                .fold(Matrix3::<f64>::zeros(), |m, u| {
                    m + gradient(u) * gradient(u).transpose()
                });
            let g = gradient(at);
            jtj.try_inverse()
                .map_or(0.0, |inverse| (g.transpose() * inverse * g)[(0, 0)])
        }
    }

    /// Whether every centre of `run` lies within `tolerance` of the circle.
    fn holds(&self, run: &[RollSample], tolerance: f64) -> bool {
        run.iter().all(|s| self.residual(s).abs() <= tolerance)
    }

    /// How far the centre lies outside the circle (mm; negative inside).
    fn residual(&self, s: &RollSample) -> f64 {
        (s.centre - self.middle).norm() - s.rho - self.surface_radius
    }

    /// Whether the circle is an edge's for a ball of in-plane radius `ball`: its surface radius within
    /// [`MAX_EDGE_RADIUS`] of the ball's either side of zero (a short run's radius is noisy; a path tighter than
    /// that is no surface's offset, and the quartic flags it).
    fn is_edge(&self, ball: f64) -> bool {
        self.surface_radius.abs() <= MAX_EDGE_RADIUS * ball
    }

    /// The roll's answer for the run's sample `at`, if the run is a convex edge's (the circle's middle on the
    /// material side of every centre, as every reported normal says): `Some(None)` while the run turns through
    /// less than [`MIN_TURN_RAD`], else the point's outward direction and the edge's surface radius.
    fn roll_at(&self, run: &[RollSample], at: usize) -> Option<Option<(Vector2<f64>, f64)>> {
        let outward = |s: &RollSample| (s.centre - self.middle).normalize();
        if !run.iter().all(|s| outward(s).dot(&s.normal) > 0.0) {
            return None;
        }
        Some(
            (self.turn(run).abs() >= MIN_TURN_RAD)
                .then(|| (outward(&run[at]), self.surface_radius)),
        )
    }

    /// How far the run turns about the circle's middle, from its first centre to its last, rad (signed).
    fn turn(&self, run: &[RollSample]) -> f64 {
        let outward = |s: &RollSample| (s.centre - self.middle).normalize();
        run.windows(2)
            .map(|pair| {
                let (from, to) = (outward(&pair[0]), outward(&pair[1]));
                from.perp(&to).atan2(from.dot(&to))
            })
            .sum()
    }
}
