//! The exact Euclidean distance (mm) from a point to the surface of a supershape CSG solid, signed
//! positive outside the material (the station's deviation convention), with the nearest surface point
//! and the outward normal there.
//!
//! The boundary of a CSG solid is made of the primitives' surface patches that survive the Booleans,
//! the intersection curves where two patches meet (sharp edges) and the points where three meet. The
//! nearest boundary point is therefore one of: a point of a patch where p - x is normal to the
//! surface, a point of an edge where p - x is normal to the curve, or a vertex. Each candidate is
//! solved exactly from the orthogonality (Lagrange) conditions by Newton's method
//! ([`lagrange`]), seeded from boundary samples held in an R-tree ([`samples`]), and kept only if it
//! lies on the solid's boundary (the other primitives' signs say so, [`model::Model::on_boundary`]).
//! The answer is the nearest kept candidate. Nothing here is first order: neither the radial value
//! 1 - OP/OI nor |F| / |grad F|.
//!
//! [`SolidDistance::foot_in_section`] does the same within a section plane z = z0 (a planar profile
//! scan): the plane joins each feature's constraints, so patches become section curves and edges
//! the points where they pierce the plane.
//!
//! Completeness: the search walks the samples by increasing distance until one leads to a solution
//! on the boundary, at distance d, then solves from every sample within d plus the sampling gap (a
//! grid cell's diagonal), so every patch or edge that comes closer than d has had a Newton solve
//! seeded within one gap of its nearest point. A feature narrower than the sampling gap (a sliver)
//! can be missed ([`SolidDistance::with_spacing`] refines the samples), and so can a vertex (three
//! surfaces meeting) whose edges are shorter than a grid cell, as vertices are seeded where a grid
//! cell or a box edge is crossed by two more surfaces; a query whose foot is a missed vertex gets
//! `None` or, where the ordered walk reaches another boundary part first, a distance too large.

mod lagrange;
mod model;
mod samples;

use nalgebra::{Matrix3, Point3, Vector3};

use super::csg::Solid;
use lagrange::{nearest_on, project, Surfaces};
use model::Model;
use samples::{sample, Feature, Sample, Samples};

/// Neighbouring samples about 1/128 of the solid's bounding-box diagonal apart: 0.4 mm on a 50 mm
/// part, close enough for Newton's basin on the surfaces a part model uses.
const SAMPLES_PER_DIAGONAL: f64 = 128.0;
/// Bound on the samples visited in order before one leads to the boundary.
const MAX_VISITED: usize = 20_000;

/// What part of the boundary the nearest point lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FootKind {
    /// Inside a primitive's surface patch: p - foot is along the surface normal.
    Face,
    /// On an intersection curve of two surfaces (a sharp edge): p - foot lies in the normal cone.
    Edge,
    /// Where three surfaces meet (a box corner, or a box edge through a supershape).
    Vertex,
}

/// The nearest point of the solid's boundary to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Foot {
    /// |p - point|, positive when p is outside the material, negative inside.
    pub distance_mm: f64,
    /// The nearest point on the boundary (model frame).
    pub point: Point3<f64>,
    /// The outward unit normal of the solid at `point`; at an edge or vertex, the direction from the
    /// foot to p (outward), which lies in the normal cone there.
    pub normal: Vector3<f64>,
    pub kind: FootKind,
}

/// The distance to one solid, with its boundary samples precomputed.
pub struct SolidDistance {
    solid: Solid,
    model: Model,
    samples: Samples,
}

impl SolidDistance {
    /// Prepares the distance to `solid` with boundary samples about 1/128 of its bounding box's
    /// diagonal apart.
    pub fn new(solid: &Solid) -> Self {
        Self::with_spacing(solid, solid.bounds().diagonal() / SAMPLES_PER_DIAGONAL)
    }

    /// Prepares the distance with neighbouring boundary samples about `spacing_mm` apart: finer for
    /// a part whose smallest feature (a small bore, a narrow face) is under the default spacing.
    pub fn with_spacing(solid: &Solid, spacing_mm: f64) -> Self {
        let model = Model::new(solid);
        let samples = sample(&model, spacing_mm);
        Self {
            solid: solid.clone(),
            model,
            samples,
        }
    }

    /// The nearest boundary point to `p`. `None` if the solid has no boundary samples (empty) or no
    /// solve ended on the boundary, which happens when the nearest point is a vertex the samples
    /// missed (every patch's and edge's own nearest point is then hidden).
    pub fn foot(&self, p: &Point3<f64>) -> Option<Foot> {
        let (distance, point, feature) = self.search(p, |feature, seed| {
            let max_step = self.max_step(p, seed);
            match feature {
                Feature::Surface(s) => nearest_on::<1, 4>(&self.model, [s], p, seed, max_step),
                Feature::Edge(a, b) => nearest_on::<2, 5>(&self.model, [a, b], p, seed, max_step),
                Feature::Vertex(a, b, c) => project(&self.model, [a, b, c], seed, max_step),
            }
        })?;
        Some(self.foot_at(p, distance, point, feature, Some))
    }

    /// The 2-D distance within the section plane through `p` normal to the model's z axis (the plane
    /// z = p.z of a planar profile scan): the nearest point of the solid's section curve, which is
    /// made of the patches' sections (Lagrange conditions with the plane as one more constraint)
    /// and the points where edges pierce the plane. The normal is the section curve's, in the plane.
    pub fn foot_in_section(&self, p: &Point3<f64>) -> Option<Foot> {
        let section = Section {
            model: &self.model,
            z: p.z,
        };
        let plane = self.model.surfaces.len();
        let (distance, point, feature) = self.search(p, |feature, seed| {
            let seed = Point3::new(seed.x, seed.y, p.z);
            let max_step = self.max_step(p, &seed);
            match feature {
                Feature::Surface(s) => nearest_on::<2, 5>(&section, [s, plane], p, &seed, max_step),
                Feature::Edge(a, b) => project(&section, [a, b, plane], &seed, max_step),
                // Three surfaces and the plane meet only by accident.
                Feature::Vertex(..) => None,
            }
        })?;
        Some(self.foot_at(p, distance, point, feature, |n| {
            Vector3::new(n.x, n.y, 0.0).try_normalize(1e-12)
        }))
    }

    /// Visits the boundary samples by increasing distance from `p` until one leads to a solution on
    /// the boundary, then every sample within that distance plus the sampling gap (an unordered
    /// range query, cheaper than the ordered walk); solves `solve` (the nearest point of a feature
    /// from a seed) once per feature and neighbourhood and keeps the nearest solution.
    fn search(
        &self,
        p: &Point3<f64>,
        solve: impl Fn(Feature, &Point3<f64>) -> Option<Point3<f64>>,
    ) -> Option<(f64, Point3<f64>, Feature)> {
        let gap = self.samples.gap;
        let query = [p.x, p.y, p.z];
        let mut best: Option<(f64, Point3<f64>, Feature)> = None;
        // Seeds and feet already tried, by feature: a sample within two gaps of one of them would
        // lead Newton to the same point.
        let mut tried: Vec<(Feature, Point3<f64>)> = Vec::new();
        let mut visit = |sample: &Sample, best: &mut Option<(f64, Point3<f64>, Feature)>| {
            let seed = Point3::from(sample.point);
            let near = |(feature, q): &(Feature, Point3<f64>)| {
                *feature == sample.feature && (q - seed).norm() < 2.0 * gap
            };
            if tried.iter().any(near) {
                return;
            }
            tried.push((sample.feature, seed));
            let Some(x) = solve(sample.feature, &seed) else {
                return;
            };
            tried.push((sample.feature, x));
            if self.model.on_boundary(&x, &sample.feature.surfaces()) {
                let d = (x - p).norm();
                if best.is_none_or(|(b, _, _)| d < b) {
                    *best = Some((d, x, sample.feature));
                }
            }
        };
        for sample in self
            .samples
            .tree
            .nearest_neighbor_iter(query)
            .take(MAX_VISITED)
        {
            visit(sample, &mut best);
            if best.is_some() {
                break;
            }
        }
        let (first, _, _) = best?;
        for sample in self
            .samples
            .tree
            .locate_within_distance(query, (first + gap).powi(2))
        {
            visit(sample, &mut best);
        }
        best
    }

    /// A Newton step is bounded by the larger of the sampling gap and half the distance from the
    /// seed to p, so that it cannot leave the seed's branch at once.
    fn max_step(&self, p: &Point3<f64>, seed: &Point3<f64>) -> f64 {
        self.samples.gap.max(0.5 * (p - seed).norm())
    }

    /// The foot with its sign, kind and outward normal; `project` maps a surface normal into the
    /// space the distance is measured in (the identity in 3-D, the section plane in 2-D).
    fn foot_at(
        &self,
        p: &Point3<f64>,
        distance: f64,
        point: Point3<f64>,
        feature: Feature,
        project: impl Fn(Vector3<f64>) -> Option<Vector3<f64>>,
    ) -> Foot {
        let sign = if self.solid.contains(p) { -1.0 } else { 1.0 };
        // From the foot to p, outward: the normal at an edge, where the normal cone holds it.
        let towards_p = (distance > 1e-9).then(|| (p - point) * (sign / distance));
        let (normal, kind) = match feature {
            Feature::Surface(s) => (
                project(self.oriented_normal(s, &point)).or(towards_p),
                FootKind::Face,
            ),
            Feature::Edge(..) | Feature::Vertex(..) => {
                // On the edge itself: the mean of the faces' normals, inside the cone.
                let mean = || {
                    let sum: Vector3<f64> = feature
                        .surfaces()
                        .iter()
                        .map(|&s| self.oriented_normal(s, &point))
                        .sum();
                    project(sum.normalize()).map(|n| n.normalize())
                };
                let kind = if matches!(feature, Feature::Edge(..)) {
                    FootKind::Edge
                } else {
                    FootKind::Vertex
                };
                (towards_p.or_else(mean), kind)
            }
        };
        Foot {
            distance_mm: sign * distance,
            point,
            normal: normal.unwrap_or_else(Vector3::zeros),
            kind,
        }
    }

    /// The solid's outward unit normal on surface `s` at `x`: against the surface function's
    /// gradient where the material is on the primitive's inner side, along it where the primitive
    /// is subtracted.
    fn oriented_normal(&self, s: usize, x: &Point3<f64>) -> Vector3<f64> {
        let gradient = self.model.value_and_gradient(s, x).1.normalize();
        if self.model.inside_with(x, &[(s, true)]) {
            -gradient
        } else {
            gradient
        }
    }
}

/// The model's surfaces and, as one more surface after them, the section plane z = `z`.
struct Section<'a> {
    model: &'a Model,
    z: f64,
}

impl Surfaces for Section<'_> {
    fn value_and_gradient(&self, s: usize, x: &Point3<f64>) -> (f64, Vector3<f64>) {
        if s == self.model.surfaces.len() {
            (x.z - self.z, Vector3::z())
        } else {
            self.model.value_and_gradient(s, x)
        }
    }

    fn hessian(&self, s: usize, x: &Point3<f64>, gradient: &Vector3<f64>) -> Matrix3<f64> {
        if s == self.model.surfaces.len() {
            Matrix3::zeros()
        } else {
            self.model.hessian(s, x, gradient)
        }
    }
}

#[cfg(test)]
mod tests;
