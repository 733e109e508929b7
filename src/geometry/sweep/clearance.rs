//! Clearance between the swept stylus and the part for planned motions, by conservative advancement: at time t
//! the body is d(t) from the part, and no body point moves faster than V (the motion's speed bound), so the
//! distance cannot fall by more than V * dt over a step dt. Stepping dt = (d - margin) / V therefore never steps
//! over a place where the stylus comes closer than the margin, however thin the part's features.
//!
//! Each stylus part is measured as a capsule (see [`super::stylus::BodyCapsule`]), against a part model that
//! reports lower bounds ([`PartDistance`]); the clearance found is thus a lower bound too.

use nalgebra::Point3;

use super::motion::Motion;
use super::part::PartDistance;
use super::stylus::{BodyCapsule, Stylus};

/// The smallest step, in mm of travel of the fastest body point. When the gap to the margin is below it the
/// advancement still moves on by this much, so the certified bound can fall short of the margin by at most half
/// of it (0.05 um); it also bounds the error of the first contact time to RESOLUTION_MM / V.
pub const RESOLUTION_MM: f64 = 1e-4;

/// The outcome of checking one motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Clearance {
    /// The smallest distance (mm) found between stylus and part over the samples of the motion.
    pub min_distance_mm: f64,
    /// The time of that sample.
    pub at_t: f64,
    /// The part point nearest the stylus there (mm, the part's frame: machine coordinates for a fixed part).
    pub at_point: Point3<f64>,
    /// The stylus point nearest the part there: on the axis of the nearest stylus part, moved out by its radius.
    pub stylus_point: Point3<f64>,
    /// Which part of the stylus ("ball", "shank", "extension").
    pub stylus_part: &'static str,
    /// A certified lower bound of the distance over the whole motion, between samples included (Lipschitz bound).
    pub lower_bound_mm: f64,
    /// The first sample at which the stylus touches or enters the part; the true first contact lies within
    /// RESOLUTION_MM / (speed bound) before it.
    pub first_contact_t: Option<f64>,
    /// Number of distance evaluations.
    pub samples: usize,
}

/// The closest stylus part at one instant.
struct Gap {
    distance_mm: f64,
    part_point: Point3<f64>,
    stylus_point: Point3<f64>,
    stylus_part: &'static str,
}

fn gap_at(capsules: &[BodyCapsule], motion: &Motion, part: &impl PartDistance, t: f64) -> Gap {
    let pose = motion.pose(t);
    capsules
        .iter()
        .map(|cap| {
            let (a, b) = (pose * cap.a, pose * cap.b);
            let near = if a == b {
                part.point_proximity(&a)
            } else {
                part.segment_proximity(&a, &b)
            };
            let towards_part = (near.part_point - near.query_point)
                .try_normalize(0.0)
                .unwrap_or_default();
            Gap {
                distance_mm: near.distance_mm - cap.radius_mm,
                part_point: near.part_point,
                stylus_point: near.query_point + towards_part * cap.radius_mm,
                stylus_part: cap.name,
            }
        })
        .min_by(|x, y| x.distance_mm.total_cmp(&y.distance_mm))
        .expect("a stylus has at least its shank")
}

/// Checks one motion: its clearance against `margin_mm`, and the first contact if any. Once the stylus is found
/// closer than the margin, the advancement goes on towards contact (margin 0) to report the first contact time.
pub fn check_move(
    stylus: &Stylus,
    motion: &Motion,
    part: &impl PartDistance,
    margin_mm: f64,
) -> Clearance {
    let capsules: Vec<BodyCapsule> = stylus
        .capsules()
        .into_iter()
        .filter(|c| !(motion.ball_in_contact() && c.name == "ball"))
        .collect();
    let speed = motion.max_point_speed(stylus.reach_mm());
    let mut t = 0.0;
    let mut gap = gap_at(&capsules, motion, part, t);
    let mut result = Clearance {
        min_distance_mm: gap.distance_mm,
        at_t: 0.0,
        at_point: gap.part_point,
        stylus_point: gap.stylus_point,
        stylus_part: gap.stylus_part,
        lower_bound_mm: gap.distance_mm,
        first_contact_t: None,
        samples: 1,
    };
    loop {
        if gap.distance_mm <= 0.0 {
            result.first_contact_t = Some(t);
            break;
        }
        if t >= 1.0 || speed == 0.0 {
            break;
        }
        let target = if result.min_distance_mm >= margin_mm {
            margin_mm
        } else {
            0.0
        };
        let dt = (gap.distance_mm - target).max(RESOLUTION_MM) / speed;
        let next_t = (t + dt).min(1.0);
        let next = gap_at(&capsules, motion, part, next_t);
        result.samples += 1;
        // Between the samples d(s) >= max(d0 - V (s - t), d1 - V (t1 - s)) >= (d0 + d1 - V (t1 - t)) / 2.
        let between = 0.5 * (gap.distance_mm + next.distance_mm - speed * (next_t - t));
        result.lower_bound_mm = result.lower_bound_mm.min(between).min(next.distance_mm);
        if next.distance_mm < result.min_distance_mm {
            result.min_distance_mm = next.distance_mm;
            result.at_t = next_t;
            result.at_point = next.part_point;
            result.stylus_point = next.stylus_point;
            result.stylus_part = next.stylus_part;
        }
        t = next_t;
        gap = next;
    }
    result
}

/// A motion of a plan that comes closer to the part than the margin.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "move {move_index} brings the stylus {stylus_part} to {distance_mm:.4} mm of the part at ({x:.4}, {y:.4}, {z:.4}) mm \
     (t = {t:.6}), {shortfall_mm:.4} mm inside the {margin_mm} mm margin{contact}; re-plan this move further from the part",
    x = at_point.x, y = at_point.y, z = at_point.z,
    contact = match first_contact_t { Some(tc) => format!(", first contact at t = {tc:.6}"), None => String::new() }
)]
pub struct ClearanceViolation {
    /// Index of the move in the plan.
    pub move_index: usize,
    pub t: f64,
    /// Part point nearest the stylus at the closest approach (mm).
    pub at_point: Point3<f64>,
    pub stylus_part: &'static str,
    pub distance_mm: f64,
    pub margin_mm: f64,
    /// By how much the margin is missed (mm, positive).
    pub shortfall_mm: f64,
    pub first_contact_t: Option<f64>,
}

/// The clearances of every move of an accepted plan.
#[derive(Debug, Clone, PartialEq)]
pub struct PlanClearance {
    pub moves: Vec<Clearance>,
    /// Index of the move that comes closest.
    pub closest_move: usize,
    pub min_distance_mm: f64,
}

/// Checks every move of a plan in order; the first move closer than `margin_mm` refuses the plan.
pub fn check_plan(
    stylus: &Stylus,
    moves: &[Motion],
    part: &impl PartDistance,
    margin_mm: f64,
) -> Result<PlanClearance, ClearanceViolation> {
    let mut checked = Vec::with_capacity(moves.len());
    for (move_index, motion) in moves.iter().enumerate() {
        let c = check_move(stylus, motion, part, margin_mm);
        if c.min_distance_mm < margin_mm {
            return Err(ClearanceViolation {
                move_index,
                t: c.at_t,
                at_point: c.at_point,
                stylus_part: c.stylus_part,
                distance_mm: c.min_distance_mm,
                margin_mm,
                shortfall_mm: margin_mm - c.min_distance_mm,
                first_contact_t: c.first_contact_t,
            });
        }
        checked.push(c);
    }
    let (closest_move, min_distance_mm) = checked
        .iter()
        .enumerate()
        .map(|(i, c)| (i, c.min_distance_mm))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, f64::INFINITY));
    Ok(PlanClearance {
        moves: checked,
        closest_move,
        min_distance_mm,
    })
}
