//! The probing lines of a curve scan round a sharp edge: a fan through a pivot inside the master's edge.
//!
//! Round a sharp edge the taught nominals are one point, the apex, with a fan of normals, and a curve scan probes
//! each along its normal: every line passes through the master's apex. A part whose edge lies inside the master's
//! (a blade short of chord moves each end 0.5-1.8 mm at 1-2 %) is then found only within about the ball's radius
//! of the master's apex; beyond it the lines beside and round the edge pass the part's edge by more than the ball's
//! radius and the machine stops with "Surface not found", and just within it the ball only grazes the edge (its
//! centres bunch, 0.5-1 deg a point: BENCHMARKS.md, stop 49).
//!
//! So the lines round the edge, and those of the faces within the pivot's depth of it, pass through a pivot
//! `depth` inside the master's apex along the edge's bisector, each aimed at the ball centre the planned ball has
//! on the master there. The planned centres, which the clearance check sweeps, are unchanged, and a ball of the
//! planned radius stops on the master where it did. A part's edge up to `depth` plus the ball's radius inside the
//! master's lies within every line's reach, and one at about `depth` inside is rolled round evenly.

use nalgebra::{Point3, Vector2, Vector3};
use zeroset_drivers::machine::{Nominal, Xyz};

use crate::analysis::edges::SharpEdge;

/// The pivot's depth inside the master's apex, as a fraction of the planned ball's radius at most. A ball smaller
/// than the planned one meets the fan's outer lines (those aimed near a face's normal) on that face just behind the
/// apex instead of on it, its contacts still moving along the face towards the apex: at 2/3, a 1 mm ball on a fan
/// planned for 1.5 mm touches the faces up to 0.3 mm behind the apex on the lines more than about 69 deg off the
/// bisector (the line 85 deg off passes 0.8 mm from the apex). Deeper, those contacts reach farther behind: at 4/3 a
/// blade 1 mm long, so the pivot 3 mm inside its edge, read its chord 5.3 um long (BENCHMARKS.md, stop 50).
const MAX_DEPTH_PER_RADIUS: f64 = 2.0 / 3.0;

/// A sharp edge of a curve scan's profile as the scan's fan probes it, in machine coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeFan {
    /// The master's apex, mm.
    pub apex: Point3<f64>,
    /// How deep inside it the fan's lines pivot, mm.
    pub depth_mm: f64,
}

/// How deep inside the master's edges a scan's fans pivot, mm: no more than the part may lie off the master
/// (`max_deviation_mm`, the reach of every probing line), nor than [`MAX_DEPTH_PER_RADIUS`] of the planned ball.
pub(super) fn pivot_depth_mm(max_deviation_mm: f64, ball_radius_mm: f64) -> f64 {
    max_deviation_mm.min(MAX_DEPTH_PER_RADIUS * ball_radius_mm)
}

/// `nominals` (part frame, each in its profile's plane x = const, in scan order) with every one within `depth_mm`
/// of a sharp edge's apex (in that plane, (y, z)) probed along the line from the edge's pivot to the centre of a
/// ball of `ball_radius_mm` touching the master at that nominal: its point moved to where that ball touches the
/// line's way in (one radius before the centre), its normal turned along the line. The rest are as they were.
pub(crate) fn fanned(
    nominals: &[Nominal],
    edges: &[SharpEdge],
    depth_mm: f64,
    ball_radius_mm: f64,
) -> Vec<Nominal> {
    nominals
        .iter()
        .map(|nominal| {
            let point = Point3::new(nominal.point.x, nominal.point.y, nominal.point.z);
            let in_plane = Vector2::new(point.y, point.z);
            let off = |edge: &&SharpEdge| (in_plane - Vector2::from(edge.apex)).norm();
            let edge = edges
                .iter()
                .filter(|edge| off(edge) < depth_mm)
                .min_by(|a, b| off(a).total_cmp(&off(b)));
            match edge {
                Some(edge) => {
                    let normal = Vector3::new(nominal.normal.x, nominal.normal.y, nominal.normal.z);
                    let pivot = Vector2::from(edge.apex) - edge.bisector() * depth_mm;
                    let pivot = Point3::new(point.x, pivot.x, pivot.y);
                    let centre = point + normal * ball_radius_mm;
                    let line = (centre - pivot).normalize();
                    let touch = centre - line * ball_radius_mm;
                    Nominal {
                        point: Xyz::new(touch.x, touch.y, touch.z),
                        normal: Xyz::new(line.x, line.y, line.z),
                    }
                }
                None => *nominal,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thin edge pointing along +y at (y, z) = (10, 0) in the plane x = 5: faces of normals (0, +-1) turned 5 deg
    /// towards the tip, a fan of normals at the apex every 10 deg, face points every 0.3 mm before it.
    fn thin_edge() -> (SharpEdge, Vec<Nominal>) {
        let half_wedge = 5f64.to_radians();
        let (sin, cos) = half_wedge.sin_cos();
        let edge = SharpEdge {
            apex: [10.0, 0.0],
            from_normal: [sin, cos],
            turn_rad: -(std::f64::consts::PI - 2.0 * half_wedge),
        };
        let at = |y: f64, z: f64, ny: f64, nz: f64| Nominal {
            point: Xyz::new(5.0, y, z),
            normal: Xyz::new(0.0, ny, nz),
        };
        let mut nominals: Vec<Nominal> = (1..=8)
            .rev()
            .map(|k| {
                let s = 0.3 * k as f64;
                at(10.0 - s * cos, s * sin, sin, cos)
            })
            .collect();
        let steps = 17;
        for k in 0..=steps {
            let angle = (90.0 - 5.0) * (1.0 - 2.0 * k as f64 / steps as f64);
            let (s, c) = angle.to_radians().sin_cos();
            nominals.push(at(10.0, 0.0, c, s));
        }
        nominals.extend((1..=8).map(|k| {
            let s = 0.3 * k as f64;
            at(10.0 - s * cos, -s * sin, sin, -cos)
        }));
        (edge, nominals)
    }

    fn point(n: &Nominal) -> Point3<f64> {
        Point3::new(n.point.x, n.point.y, n.point.z)
    }

    fn normal(n: &Nominal) -> Vector3<f64> {
        Vector3::new(n.normal.x, n.normal.y, n.normal.z)
    }

    #[test]
    fn the_bisector_points_out_of_the_tip_whichever_face_the_scan_comes_from() {
        let (from_upper, _) = thin_edge();
        let from_lower = SharpEdge {
            from_normal: [from_upper.from_normal[0], -from_upper.from_normal[1]],
            turn_rad: -from_upper.turn_rad,
            ..from_upper
        };
        for edge in [from_upper, from_lower] {
            assert!(
                (edge.bisector() - Vector2::new(1.0, 0.0)).norm() < 1e-12,
                "{edge:?}"
            );
        }
    }

    #[test]
    fn the_pivot_is_two_thirds_of_the_planned_ball_deep_unless_the_part_may_lie_nearer() {
        assert!((pivot_depth_mm(3.0, 1.5) - 1.0).abs() < 1e-12);
        assert!((pivot_depth_mm(0.4, 1.5) - 0.4).abs() < 1e-12);
    }

    #[test]
    fn lines_near_the_edge_pass_the_pivot_and_keep_the_masters_ball_centres() {
        let (edge, nominals) = thin_edge();
        let (depth, radius) = (1.0, 1.5);
        let fan = fanned(&nominals, &[edge], depth, radius);
        let pivot = Point3::new(5.0, 9.0, 0.0);
        let mut moved = 0;
        for (before, after) in nominals.iter().zip(&fan) {
            let centre_before = point(before) + normal(before) * radius;
            let centre_after = point(after) + normal(after) * radius;
            // The planned centre, the positions the clearance check sweeps, does not move.
            assert!((centre_after - centre_before).norm() < 1e-12);
            assert!((normal(after).norm() - 1.0).abs() < 1e-12);
            let near = (Vector2::new(before.point.y, before.point.z) - Vector2::new(10.0, 0.0))
                .norm()
                < depth;
            if near {
                moved += 1;
                // The line through the new point along the new normal passes through the pivot.
                let off = point(after) - pivot;
                assert!(off.cross(&normal(after)).norm() < 1e-12, "{off}");
                assert!(off.dot(&normal(after)) > 0.0);
            } else {
                assert_eq!(before, after);
            }
        }
        // The 18 lines of the roll and the 3 face points 0.3-0.9 mm before the apex on each face.
        assert_eq!(moved, 18 + 2 * 3);
    }

    #[test]
    fn every_line_of_the_fan_finds_an_edge_up_to_its_depth_and_a_radius_inside_the_masters() {
        // A ball of 1 mm on a fan planned for 1.5 mm, 1 mm deep: an edge 1.9 mm inside the master's, where every
        // line through the apex would pass it by up to 1.9 mm (sin 85 deg x 1.9), is within 1 mm of every line of
        // the roll.
        let (edge, nominals) = thin_edge();
        let fan = fanned(&nominals, &[edge], 1.0, 1.5);
        let inner_apex = Point3::new(5.0, 10.0 - 1.9, 0.0);
        let passes = |n: &Nominal| {
            let off = inner_apex - point(n);
            (off - normal(n) * off.dot(&normal(n))).norm()
        };
        let roll = 8..8 + 18;
        let worst_fan = fan[roll.clone()].iter().map(passes).fold(0.0, f64::max);
        let worst_apex = nominals[roll].iter().map(passes).fold(0.0, f64::max);
        assert!(worst_fan < 1.0, "{worst_fan}");
        assert!(worst_apex > 1.8, "{worst_apex}");
    }
}
