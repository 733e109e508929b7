//! Numerical tracing of a curve given as the common zero set of two equations in (u, v, t) (seed 002, section 3):
//! the predictor steps along grad F x grad G, the corrector projects back by Newton's method with the minimum-norm
//! update of the 2 x 3 system; the curve stops at t = 0 and t = 1 (where it is clipped exactly) or when it closes.

use nalgebra::{Matrix2, Matrix2x3, Vector2, Vector3};

use super::ball_system::{BallSweep, CurveSystem, SurfaceTime};

/// Corrector iterations before a point is declared off the curve.
const NEWTON_ITERATIONS: usize = 40;
/// Newton stops when the update is below this (radians and units of t, both of order 1).
const NEWTON_STEP_TOL: f64 = 1e-15;
/// A corrected point must satisfy the equations to this (relative to their scale) or it is rejected.
const ACCEPT_RESIDUAL: f64 = 1e-10;

/// Newton's updates can move t off a bound it should stay on by rounding (a curve at fixed t = 0 or 1); such
/// excursions are clamped rather than taken for the curve leaving the domain.
const T_ROUNDING: f64 = 1e-12;

/// A traced curve: its points in surface-time space, and whether it closed on itself.
#[derive(Debug, Clone)]
pub struct TracedCurve {
    pub points: Vec<SurfaceTime>,
    pub closed: bool,
}

/// Newton's projection onto the zero set, optionally holding t fixed (then a 2 x 2 solve in (u, v)).
pub fn correct(
    system: &impl CurveSystem,
    start: SurfaceTime,
    fixed_t: bool,
    scale: f64,
) -> Option<SurfaceTime> {
    let mut q = start;
    for _ in 0..NEWTON_ITERATIONS {
        let (f, j) = system.evaluate(&q);
        let delta = if fixed_t {
            let j2 = Matrix2::new(j[(0, 0)], j[(0, 1)], j[(1, 0)], j[(1, 1)]);
            let d = j2.lu().solve(&f)?;
            Vector3::new(d.x, d.y, 0.0)
        } else {
            min_norm_step(&j, &f)?
        };
        q = q.shifted(&-delta);
        q.s = q.s.rechart();
        if delta.amax() < NEWTON_STEP_TOL {
            break;
        }
    }
    let (f, _) = system.evaluate(&q);
    (f.amax() <= ACCEPT_RESIDUAL * scale).then_some(q)
}

/// The minimum-norm solution of J d = f: d = J^T (J J^T)^-1 f.
fn min_norm_step(j: &Matrix2x3<f64>, f: &Vector2<f64>) -> Option<Vector3<f64>> {
    let y = (j * j.transpose()).lu().solve(f)?;
    Some(j.transpose() * y)
}

/// The tangent grad f1 x grad f2 at q, in q's chart.
pub fn tangent(system: &impl CurveSystem, q: &SurfaceTime) -> Vector3<f64> {
    let (_, j) = system.evaluate(q);
    let a: Vector3<f64> = j.row(0).transpose();
    let b: Vector3<f64> = j.row(1).transpose();
    a.cross(&b)
}

/// A chart-independent version of a tangent: the velocity of the unit normal (3-D) and of t.
fn spatial(q: &SurfaceTime, d: &Vector3<f64>) -> (Vector3<f64>, f64) {
    let f = q.s.frame();
    (f.n_u * d.x + f.n_v * d.y, d.z)
}

/// The metric the tracer measures steps in: how far (mm) the world point A(t)S moves at most.
fn travel(sweep: &BallSweep<'_>, dn: &Vector3<f64>, dt: f64) -> f64 {
    sweep.radius_mm * dn.norm() + sweep.speed_bound() * dt.abs()
}

fn distance(sweep: &BallSweep<'_>, a: &SurfaceTime, b: &SurfaceTime) -> f64 {
    travel(sweep, &(a.normal() - b.normal()), a.t - b.t)
}

/// Traces from `start` (on the curve) in the direction `sign` (+1 or -1 along grad f1 x grad f2 at the start),
/// with steps of about `step_mm` of travel of the world point, for t in [0, 1].
pub fn trace(
    sweep: &BallSweep<'_>,
    system: &impl CurveSystem,
    start: SurfaceTime,
    sign: f64,
    step_mm: f64,
    max_steps: usize,
    scale: f64,
) -> TracedCurve {
    let mut points = vec![start];
    let mut q = start;
    let mut previous = {
        let d = tangent(system, &q) * sign;
        spatial(&q, &d)
    };
    for _ in 0..max_steps {
        let mut d = tangent(system, &q);
        let (dn, dt) = spatial(&q, &d);
        if dn.dot(&previous.0) * sweep.radius_mm + dt * previous.1 * sweep.speed_bound() < 0.0 {
            d = -d;
        }
        let speed = {
            let (dn, dt) = spatial(&q, &d);
            travel(sweep, &dn, dt)
        };
        if speed == 0.0 {
            break;
        }
        let mut h = step_mm / speed;
        let next = loop {
            if let Some(next) = correct(system, q.shifted(&(d * h)), false, scale) {
                if distance(sweep, &next, &q) < 2.0 * step_mm {
                    break Some(next);
                }
            }
            h *= 0.5;
            if h * speed < 1e-6 * step_mm {
                break None;
            }
        };
        let Some(mut next) = next else { break };
        if (next.t - next.t.clamp(0.0, 1.0)).abs() <= T_ROUNDING {
            next.t = next.t.clamp(0.0, 1.0);
        }
        if next.t < 0.0 || next.t > 1.0 {
            let bound = next.t.clamp(0.0, 1.0);
            let mut clipped = next;
            clipped.t = bound;
            if let Some(end) = correct(system, clipped, true, scale) {
                if distance(sweep, &end, &q) > 1e-9 * step_mm {
                    points.push(end);
                }
            }
            return TracedCurve {
                points,
                closed: false,
            };
        }
        if points.len() > 3 && distance(sweep, &next, &start) < 0.75 * step_mm {
            // Keep the last point unless it nearly repeats the first, so that no chord exceeds a step.
            if distance(sweep, &next, &start) > 0.25 * step_mm {
                points.push(next);
            }
            return TracedCurve {
                points,
                closed: true,
            };
        }
        previous = spatial(&q, &d);
        points.push(next);
        q = next;
    }
    TracedCurve {
        points,
        closed: false,
    }
}

/// Traces the whole curve through `start`: both directions, joined, unless the first already closes.
pub fn trace_through(
    sweep: &BallSweep<'_>,
    system: &impl CurveSystem,
    start: SurfaceTime,
    step_mm: f64,
    max_steps: usize,
    scale: f64,
) -> TracedCurve {
    let forward = trace(sweep, system, start, 1.0, step_mm, max_steps, scale);
    if forward.closed {
        return forward;
    }
    let backward = trace(sweep, system, start, -1.0, step_mm, max_steps, scale);
    let mut points: Vec<SurfaceTime> = backward.points.into_iter().rev().collect();
    points.extend(forward.points.into_iter().skip(1));
    TracedCurve {
        points,
        closed: false,
    }
}

/// Distance (in the tracer's metric) from q to the nearest point of a traced curve.
pub fn distance_to_curve(sweep: &BallSweep<'_>, curve: &TracedCurve, q: &SurfaceTime) -> f64 {
    curve
        .points
        .iter()
        .map(|p| distance(sweep, p, q))
        .fold(f64::INFINITY, f64::min)
}
