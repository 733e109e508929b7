//! Exact closest points between points, segments and triangles (Ericson, "Real-Time Collision Detection",
//! sections 5.1.2, 5.1.5 and 5.1.9). Written here rather than taken from parry3d because the clearance check
//! also needs to know which feature of a triangle (face, edge or vertex) is nearest, for the sign of the distance
//! to a closed mesh (angle-weighted pseudo-normals), and because parry3d pins another nalgebra version.

use nalgebra::Point3;

/// The feature of a triangle that holds the closest point. Edge `i` joins vertices `i` and `(i + 1) % 3`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TriangleFeature {
    Face,
    Edge(usize),
    Vertex(usize),
}

/// Closest point of segment [a, b] to p and its parameter in [0, 1].
pub fn closest_on_segment(p: &Point3<f64>, a: &Point3<f64>, b: &Point3<f64>) -> (Point3<f64>, f64) {
    let ab = b - a;
    let len2 = ab.norm_squared();
    if len2 == 0.0 {
        return (*a, 0.0);
    }
    let s = ((p - a).dot(&ab) / len2).clamp(0.0, 1.0);
    (a + ab * s, s)
}

/// Closest points of segments [p1, q1] and [p2, q2] (Ericson 5.1.9), as (point on the first, point on the second).
pub fn closest_between_segments(
    p1: &Point3<f64>,
    q1: &Point3<f64>,
    p2: &Point3<f64>,
    q2: &Point3<f64>,
) -> (Point3<f64>, Point3<f64>) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let (s, t) = if a == 0.0 && e == 0.0 {
        (0.0, 0.0)
    } else if a == 0.0 {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e == 0.0 {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > 0.0 {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p1 + d1 * s, p2 + d2 * t)
}

/// Closest point of triangle (a, b, c) to p and the feature that holds it (Ericson 5.1.5, Voronoi regions).
pub fn closest_on_triangle(
    p: &Point3<f64>,
    a: &Point3<f64>,
    b: &Point3<f64>,
    c: &Point3<f64>,
) -> (Point3<f64>, TriangleFeature) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, TriangleFeature::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, TriangleFeature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), TriangleFeature::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, TriangleFeature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), TriangleFeature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * w, TriangleFeature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    (
        a + ab * (vb * denom) + ac * (vc * denom),
        TriangleFeature::Face,
    )
}

/// Closest points of segment [p, q] and triangle (a, b, c), as (point on the segment, point on the triangle).
/// Either the segment pierces the triangle (distance 0), or the minimum is attained at a segment end against the
/// triangle or between the segment and one of the triangle's edges.
pub fn closest_segment_triangle(
    p: &Point3<f64>,
    q: &Point3<f64>,
    tri: [&Point3<f64>; 3],
) -> (Point3<f64>, Point3<f64>) {
    let [a, b, c] = tri;
    let normal = (b - a).cross(&(c - a));
    let dp = normal.dot(&(p - a));
    let dq = normal.dot(&(q - a));
    if (dp <= 0.0 && dq >= 0.0 || dp >= 0.0 && dq <= 0.0) && dp != dq {
        let crossing = p + (q - p) * (dp / (dp - dq));
        let (on_triangle, _) = closest_on_triangle(&crossing, a, b, c);
        let scale = 1.0 + crossing.coords.amax();
        if (on_triangle - crossing).norm() <= 1e-13 * scale {
            return (crossing, crossing);
        }
    }
    let mut best = (*p, closest_on_triangle(p, a, b, c).0);
    let mut best_d2 = (best.0 - best.1).norm_squared();
    let mut consider = |s: Point3<f64>, t: Point3<f64>| {
        let d2 = (s - t).norm_squared();
        if d2 < best_d2 {
            best_d2 = d2;
            best = (s, t);
        }
    };
    consider(*q, closest_on_triangle(q, a, b, c).0);
    for (e0, e1) in [(a, b), (b, c), (c, a)] {
        let (s, t) = closest_between_segments(p, q, e0, e1);
        consider(s, t);
    }
    best
}
