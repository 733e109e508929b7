//! Sharp edges of a taught profile (a blade's sharp trailing edge), found in the master's scan and kept with the
//! reference, because one implicit polynomial cannot stand for them beyond the data.
//!
//! A polynomial's zero set can only make a sharp corner where two branches cross, and the branches go on past the
//! corner: near a sharp trailing edge the model's zero set is an X. It fits the master's points to microns, but a
//! point of another blade just beyond the edge measures its distance to a continued face instead of to the edge
//! (measured on the simulated propeller: blade C's trailing edge 0.254 mm from the model, 0.448 mm from the true
//! edge). The true distance there is known without any model: from a point in an edge's normal cone (the
//! directions between the outward normals of the two faces that meet at it) the nearest point of the part is the
//! edge itself.
//!
//! The master's scan shows where its edges are: a CMM's ball rolls around a sharp edge, reporting one touched point
//! again and again while its normal turns from one face's to the other's.

use nalgebra::Vector2;
use serde::{Deserialize, Serialize};

/// Consecutive touched points within this distance of the first of their run are one point, mm (the probe's noise
/// is microns; along a face the scan's points are a step apart).
const SAME_POINT_MM: f64 = 0.02;
/// A run of one touched point is an edge when the normal turns by at least this much along it, rad.
const EDGE_TURN_RAD: f64 = 0.5;
/// Points farther than this from an edge are left to the model, mm: the faces are only straight near the edge.
const EDGE_REACH_MM: f64 = 3.0;
/// Points this close to an edge's apex measure their distance to the wedge of its faces, wherever the model's foot
/// lies (mm): the contacts of the ball's roll round the edge, which scatter about the apex by the probe's noise.
/// The polynomial strays most there (on the simulated propeller's r200 it put contacts 3 um behind the apex 31 um
/// inside the part). Farther out the faces' points keep the model: the wedge's faces come from the normals at the
/// ends of the master's roll, which can be off by degrees (at 0.2 mm, r300's put a face's point 54 um inside).
const WEDGE_MM: f64 = 0.02;
/// A model's nearest point this far beyond an edge, into its normal cone, is on the model's continuation of a
/// face, not on the part, mm.
const BEYOND_EDGE_MM: f64 = 0.01;

/// A sharp edge of a profile, in the profile's (y, z) plane: where two faces meet, and their outward normals.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SharpEdge {
    /// Where the faces meet, mm.
    pub apex: [f64; 2],
    /// The outward normal of the face the scan came from.
    pub from_normal: [f64; 2],
    /// How far the normal turns from that face's to the other's, rad, signed (counter-clockwise positive).
    pub turn_rad: f64,
}

impl SharpEdge {
    fn from(&self) -> Vector2<f64> {
        Vector2::from(self.from_normal)
    }

    fn to(&self) -> Vector2<f64> {
        let (sin, cos) = self.turn_rad.sin_cos();
        let n = self.from();
        Vector2::new(n.x * cos - n.y * sin, n.x * sin + n.y * cos)
    }

    /// The outward direction halfway between the two faces' normals: straight out of the edge's tip.
    pub(crate) fn bisector(&self) -> Vector2<f64> {
        let (sin, cos) = (self.turn_rad / 2.0).sin_cos();
        let n = self.from();
        Vector2::new(n.x * cos - n.y * sin, n.x * sin + n.y * cos)
    }

    /// Whether a direction from the apex lies in the normal cone: between the two faces' normals, the way the
    /// normal turns.
    fn in_cone(&self, offset: &Vector2<f64>) -> bool {
        let from = self.from();
        let mut angle = from.perp(offset).atan2(from.dot(offset)) * self.turn_rad.signum();
        if angle < 0.0 {
            angle += std::f64::consts::TAU;
        }
        angle <= self.turn_rad.abs()
    }

    /// The signed distance (mm, positive outside) of a point to the part near this edge, where the model cannot
    /// give it: when the point is in the edge's normal cone, within [`WEDGE_MM`] of the apex, or the model's
    /// nearest point `foot` lies beyond the edge. `None` otherwise, and for points out of the edge's reach.
    ///
    /// Near the edge the part is the wedge between the two faces: from its normal cone the nearest point is the
    /// apex; elsewhere the distance is the larger of the signed distances to the two faces' lines.
    pub fn distance(&self, point: &Vector2<f64>, foot: &Vector2<f64>) -> Option<f64> {
        let apex = Vector2::from(self.apex);
        let offset = point - apex;
        if offset.norm() > EDGE_REACH_MM {
            return None;
        }
        if self.in_cone(&offset) {
            return Some(offset.norm());
        }
        if offset.norm() <= WEDGE_MM {
            return Some(self.wedge_distance(&offset));
        }
        let beyond = foot - apex;
        if beyond.norm() > BEYOND_EDGE_MM && self.in_cone(&beyond) {
            return Some(self.wedge_distance(&offset));
        }
        None
    }

    /// The signed distance to the wedge of the two faces from a point `offset` from the apex outside the normal
    /// cone: the larger of its signed distances to the faces' lines.
    fn wedge_distance(&self, offset: &Vector2<f64>) -> f64 {
        offset.dot(&self.from()).max(offset.dot(&self.to()))
    }
}

/// `outline` (closed, in order round a section) with its tip at each of `edges` made sharp: its points in the
/// edge's normal cone within [`EDGE_REACH_MM`] of the apex (a polynomial's rounded or overshooting tip) replaced
/// by the apex itself, between the neighbours it falls between.
pub(crate) fn sharpen(outline: &[Vector2<f64>], edges: &[SharpEdge]) -> Vec<Vector2<f64>> {
    let mut outline = outline.to_vec();
    for edge in edges {
        let apex = Vector2::from(edge.apex);
        let beyond = |p: &Vector2<f64>| {
            let offset = p - apex;
            offset.norm() <= EDGE_REACH_MM && edge.in_cone(&offset)
        };
        let first_beyond = outline.iter().position(beyond);
        outline.retain(|p| !beyond(p));
        let n = outline.len();
        if n < 2 {
            continue;
        }
        let at = first_beyond.unwrap_or_else(|| {
            // The outline stops short of the apex: it goes in beside its nearest point, on the side it lies.
            let nearest = (0..n)
                .min_by(|&i, &j| {
                    (outline[i] - apex)
                        .norm()
                        .total_cmp(&(outline[j] - apex).norm())
                })
                .unwrap_or(0);
            let towards_next =
                (outline[(nearest + 1) % n] - outline[nearest]).dot(&(apex - outline[nearest]));
            if towards_next > 0.0 {
                nearest + 1
            } else {
                nearest
            }
        });
        outline.insert(at.min(n), apex);
    }
    outline
}

/// The sharp edges in a scan: runs of one touched point along which the normal turns by more than
/// [`EDGE_TURN_RAD`]. `points` and `normals` are the profile's compensated points and outward unit normals in the
/// profile's plane, in scan order. The faces' normals are the normal on arriving at the edge and the normal of the
/// first point after it (the ball may leave the edge before a point is reported at the end of its roll).
pub fn find_sharp_edges(points: &[Vector2<f64>], normals: &[Vector2<f64>]) -> Vec<SharpEdge> {
    let turn = |a: &Vector2<f64>, b: &Vector2<f64>| a.perp(b).atan2(a.dot(b));
    let mut edges = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let mut end = start + 1;
        while end < points.len() && (points[end] - points[start]).norm() <= SAME_POINT_MM {
            end += 1;
        }
        let rolled: f64 = (start + 1..end)
            .map(|i| turn(&normals[i - 1], &normals[i]))
            .sum();
        if rolled.abs() >= EDGE_TURN_RAD {
            let apex = points[start..end].iter().sum::<Vector2<f64>>() / (end - start) as f64;
            let leaving = normals.get(end).map_or(0.0, |n| turn(&normals[end - 1], n));
            edges.push(SharpEdge {
                apex: apex.into(),
                from_normal: normals[start].into(),
                turn_rad: rolled + leaving,
            });
        }
        start = end;
    }
    edges
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wedge with its tip at the origin and its faces at +-10 degrees about the -x axis (the material between
    /// them), scanned counter-clockwise: along the lower face to the tip, the ball rolling around the tip (the
    /// touched point staying put within noise), back along the upper face.
    fn wedge_scan() -> (Vec<Vector2<f64>>, Vec<Vector2<f64>>) {
        let half = 10f64.to_radians();
        let lower_normal = Vector2::new(half.sin(), -half.cos());
        let upper_normal = Vector2::new(half.sin(), half.cos());
        let mut points = Vec::new();
        let mut normals = Vec::new();
        for k in (1..=10).rev() {
            points.push(Vector2::new(
                -(k as f64) * half.cos(),
                -(k as f64) * half.sin(),
            ));
            normals.push(lower_normal);
        }
        let (from, to) = (
            lower_normal.y.atan2(lower_normal.x),
            upper_normal.y.atan2(upper_normal.x),
        );
        for k in 0..=16 {
            let angle = from + (to - from) * k as f64 / 16.0;
            points.push(Vector2::new(1e-4 * (k % 3) as f64, 0.0));
            normals.push(Vector2::new(angle.cos(), angle.sin()));
        }
        for k in 1..=10 {
            points.push(Vector2::new(
                -(k as f64) * half.cos(),
                (k as f64) * half.sin(),
            ));
            normals.push(upper_normal);
        }
        (points, normals)
    }

    #[test]
    fn the_ball_rolling_around_a_tip_marks_one_edge() {
        let (points, normals) = wedge_scan();
        let edges = find_sharp_edges(&points, &normals);
        assert_eq!(edges.len(), 1, "{edges:?}");
        let edge = edges[0];
        assert!(Vector2::from(edge.apex).norm() < 1e-4, "{edge:?}");
        // From the lower face's normal to the upper's: 180 - 20 degrees, counter-clockwise.
        assert!(
            (edge.turn_rad - 160f64.to_radians()).abs() < 1e-9,
            "{edge:?}"
        );
    }

    #[test]
    fn an_outline_rounding_or_overshooting_the_tip_is_made_sharp_at_the_apex() {
        let (points, normals) = wedge_scan();
        let edge = find_sharp_edges(&points, &normals)[0];
        let faces = |tip: &[Vector2<f64>]| -> Vec<Vector2<f64>> {
            let lower = points[..10].iter();
            let upper = points[points.len() - 10..].iter();
            lower.chain(tip).chain(upper).copied().collect()
        };
        // A model's tip 12 um beyond the apex, and one rounded 30 um short of it.
        let beyond = faces(&[
            Vector2::new(0.008, -0.001),
            Vector2::new(0.012, 0.0),
            Vector2::new(0.008, 0.001),
        ]);
        let short = faces(&[Vector2::new(-0.03, -0.004), Vector2::new(-0.03, 0.004)]);
        for outline in [beyond, short] {
            let sharp = sharpen(&outline, &[edge]);
            let apex = Vector2::from(edge.apex);
            let tip = sharp
                .iter()
                .position(|p| *p == apex)
                .expect("the apex is in the outline");
            // Between the faces: after the lower face's last point, before the upper face's first.
            let at = |p: &Vector2<f64>| sharp.iter().position(|q| q == p).unwrap();
            assert!(
                at(&points[9]) < tip && tip < at(&points[points.len() - 10]),
                "{sharp:?}"
            );
            let farthest = sharp.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max);
            assert_eq!(farthest, apex.x, "{sharp:?}");
        }
    }

    #[test]
    fn a_round_nose_is_no_edge() {
        // A 1.5 mm nose radius scanned at 1 mm steps: the touched point moves along it.
        let (points, normals): (Vec<_>, Vec<_>) = (0..20)
            .map(|k| {
                let angle = k as f64 * (1.0 / 1.5);
                let n = Vector2::new(angle.cos(), angle.sin());
                (n * 1.5, n)
            })
            .unzip();
        assert!(find_sharp_edges(&points, &normals).is_empty());
    }

    #[test]
    fn near_the_edge_points_measure_their_distance_to_the_wedge() {
        let (points, normals) = wedge_scan();
        let edge = find_sharp_edges(&points, &normals)[0];
        let nowhere = Vector2::new(-10.0, -10.0);
        // Straight ahead of the tip and 40 degrees off it: inside the 160-degree cone, whatever the model says.
        assert!((edge.distance(&Vector2::new(0.4, 0.0), &nowhere).unwrap() - 0.4).abs() < 1e-3);
        let off = Vector2::new(40f64.to_radians().cos(), 40f64.to_radians().sin()) * 0.45;
        assert!((edge.distance(&off, &nowhere).unwrap() - 0.45).abs() < 1e-3);
        // Above the upper face, just behind the cone: the face is nearest. The model's foot decides whether the
        // model can be trusted: on the face it is, beyond the tip (on a continued face) it is not.
        let above = Vector2::new(-0.3, 0.5);
        let on_face = Vector2::new(-0.2, 0.035);
        assert_eq!(edge.distance(&above, &on_face), None);
        let beyond_tip = Vector2::new(0.3, 0.3);
        let face = 10f64.to_radians();
        let expected = above.dot(&Vector2::new(face.sin(), face.cos()));
        assert!((edge.distance(&above, &beyond_tip).unwrap() - expected).abs() < 1e-3);
        // Within 20 um of the apex the wedge answers, whatever the model's foot: a contact 3 um behind the apex
        // and 2 um above the upper face, and one 15 um behind the apex inside the wedge.
        let face = Vector2::new(face.sin(), face.cos());
        let along_upper = Vector2::new(-face.y, face.x);
        let beside = along_upper * 0.003 + face * 0.002;
        let beside_distance = edge.distance(&beside, &on_face).unwrap();
        assert!((beside_distance - 0.002).abs() < 1e-4, "{beside_distance}");
        let inside = Vector2::new(-0.015, 0.0);
        let depth = inside.dot(&face);
        assert!((edge.distance(&inside, &on_face).unwrap() - depth).abs() < 1e-4);
        // Inside the material, and out of reach: the model's.
        assert_eq!(
            edge.distance(&Vector2::new(-2.0, 0.0), &Vector2::new(-2.0, 0.3)),
            None
        );
        assert_eq!(edge.distance(&Vector2::new(6.0, 0.0), &nowhere), None);
    }
}
