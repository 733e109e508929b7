//! What the clearance check needs to know about the part: a conservative distance to its surface.

use nalgebra::Point3;

/// The nearest approach between a query (a point or a segment) and the part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Proximity {
    /// A lower bound of the Euclidean distance to the part's surface (mm); zero or negative when the query meets
    /// the material (a conservative implementation may report it negative a little early).
    pub distance_mm: f64,
    /// The point of the query (the point itself, or a point of the segment) nearest the part.
    pub query_point: Point3<f64>,
    /// The point of the part's model nearest the query.
    pub part_point: Point3<f64>,
}

/// A part model the clearance check can measure against. Implementations must never overestimate: the
/// conservative advancement of [`super::clearance`] steps over whatever gap they report.
pub trait PartDistance {
    /// Proximity of a point.
    fn point_proximity(&self, p: &Point3<f64>) -> Proximity;

    /// Proximity of the segment [a, b]: zero when it crosses the surface, negative when it lies wholly inside.
    fn segment_proximity(&self, a: &Point3<f64>, b: &Point3<f64>) -> Proximity;

    /// A lower bound of the Euclidean distance from p to the part surface, negative inside.
    fn distance(&self, p: &Point3<f64>) -> f64 {
        self.point_proximity(p).distance_mm
    }
}
