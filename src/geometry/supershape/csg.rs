//! A solid as a CSG tree of globally deformed supershapes (seed 000 sections 2-3): primitives at the
//! leaves, R-function Booleans at the inner nodes, and at every node the deformations that place it
//! in its parent's frame. The implicit function of the tree is F(P) = F_can(D^-1(P)) with the inverse
//! deformations applied from the root down to each leaf (seed 000 eq. 9), combined upwards by the
//! R-functions. Positive inside, zero on the surface, negative outside, like its primitives.
//!
//! Every node keeps an axis-aligned bounding box in the model frame, sampled from its primitives'
//! parametric surfaces. Classifying a point (inside or outside) skips every subtree whose box does not
//! hold it: outside a box a subtree's solid is empty there, and an R-function's sign depends only on
//! its arguments' signs, so the answer is exact and large trees (the seed's hub: 54 primitives,
//! 31 Booleans) cost only the primitives near the point.

use nalgebra::{Matrix3, Point3, Vector3};
use serde::{Deserialize, Serialize};

use super::deform::Deformations;
use super::rfunc::{Boolean, RFunction};
use super::shape::Supershape;

/// One node of the tree, placed in its parent's frame by `place` (canonical -> parent).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Node {
    #[serde(default, skip_serializing_if = "is_identity")]
    pub place: Deformations,
    #[serde(flatten)]
    pub kind: NodeKind,
}

fn is_identity(place: &Deformations) -> bool {
    place.0.is_empty()
}

/// What a node is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "node", rename_all = "snake_case")]
pub enum NodeKind {
    /// A supershape, measured by its radial implicit function (seed 000 eq. 7), 1 - OP/OI.
    Supershape { shape: Supershape },
    /// A box centred on the origin with the given half extents (mm), for the truncations of seed 001
    /// section 5. Its radial function, 1 - max_i |x_i| / h_i, is also 1 - OP/OI.
    Cuboid { half_extents: [f64; 3] },
    /// Two subtrees combined by an R-function.
    Boolean {
        op: Boolean,
        rfunction: RFunction,
        left: Box<Node>,
        right: Box<Node>,
    },
}

impl Node {
    pub fn supershape(shape: Supershape, place: Deformations) -> Self {
        Self {
            place,
            kind: NodeKind::Supershape { shape },
        }
    }

    pub fn cuboid(half_extents: [f64; 3], place: Deformations) -> Self {
        Self {
            place,
            kind: NodeKind::Cuboid { half_extents },
        }
    }

    pub fn boolean(op: Boolean, rfunction: RFunction, left: Node, right: Node) -> Self {
        Self {
            place: Deformations::default(),
            kind: NodeKind::Boolean {
                op,
                rfunction,
                left: Box::new(left),
                right: Box::new(right),
            },
        }
    }

    /// The implicit function at `p`, given in this node's parent frame.
    pub fn value(&self, p: &Point3<f64>) -> f64 {
        let q = self.place.inverse(p);
        match &self.kind {
            NodeKind::Supershape { shape } => shape.radial(&q),
            NodeKind::Cuboid { half_extents } => cuboid_value(half_extents, &q).0,
            NodeKind::Boolean {
                op,
                rfunction,
                left,
                right,
            } => rfunction.combine(*op, left.value(&q), right.value(&q)),
        }
    }

    /// The implicit function and its gradient at `p` (parent frame), by the chain rule through the
    /// R-functions and the deformations' Jacobians.
    pub fn value_and_gradient(&self, p: &Point3<f64>) -> (f64, Vector3<f64>) {
        let (q, jacobian): (Point3<f64>, Matrix3<f64>) = self.place.inverse_with_jacobian(p);
        let (value, gradient_in_q) = match &self.kind {
            NodeKind::Supershape { shape } => (shape.radial(&q), shape.radial_gradient(&q)),
            NodeKind::Cuboid { half_extents } => cuboid_value(half_extents, &q),
            NodeKind::Boolean {
                op,
                rfunction,
                left,
                right,
            } => {
                let (f1, g1) = left.value_and_gradient(&q);
                let (f2, g2) = right.value_and_gradient(&q);
                let (value, d1, d2) = rfunction.combine_with_partials(*op, f1, f2);
                (value, g1 * d1 + g2 * d2)
            }
        };
        (value, jacobian.transpose() * gradient_in_q)
    }

    /// The number of primitives (supershapes and cuboids) and of Boolean nodes in the tree.
    pub fn counts(&self) -> (usize, usize) {
        match &self.kind {
            NodeKind::Boolean { left, right, .. } => {
                let (pl, bl) = left.counts();
                let (pr, br) = right.counts();
                (pl + pr, bl + br + 1)
            }
            _ => (1, 0),
        }
    }
}

/// The radial function of a box and its gradient: 1 - max_i |x_i| / h_i.
fn cuboid_value(half_extents: &[f64; 3], q: &Point3<f64>) -> (f64, Vector3<f64>) {
    let (axis, ratio) = (0..3).map(|i| (i, q[i].abs() / half_extents[i])).fold(
        (0, f64::NEG_INFINITY),
        |best, next| {
            if next.1 > best.1 {
                next
            } else {
                best
            }
        },
    );
    let mut gradient = Vector3::zeros();
    gradient[axis] = -q[axis].signum() / half_extents[axis];
    (1.0 - ratio, gradient)
}

/// An axis-aligned box in the model frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aabb {
    pub min: Point3<f64>,
    pub max: Point3<f64>,
}

impl Aabb {
    fn empty() -> Self {
        Self {
            min: Point3::from(Vector3::repeat(f64::INFINITY)),
            max: Point3::from(Vector3::repeat(f64::NEG_INFINITY)),
        }
    }

    fn grow(&mut self, p: &Point3<f64>) {
        self.min = self.min.inf(p);
        self.max = self.max.sup(p);
    }

    fn union(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.inf(&other.min),
            max: self.max.sup(&other.max),
        }
    }

    pub fn intersection(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.sup(&other.min),
            max: self.max.inf(&other.max),
        }
    }

    fn padded(&self, margin: f64) -> Aabb {
        Aabb {
            min: self.min - Vector3::repeat(margin),
            max: self.max + Vector3::repeat(margin),
        }
    }

    pub fn contains(&self, p: &Point3<f64>) -> bool {
        (0..3).all(|i| p[i] >= self.min[i] && p[i] <= self.max[i])
    }

    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).norm()
    }
}

/// Longitudes and latitudes sampled on each primitive to bound it. The box is then padded by 2% of
/// its diagonal: between samples a surface bulges out by at most a small fraction of its size for the
/// shapes a part model uses (exponents up to 20 at 128 x 64 samples).
const BOUND_SAMPLES: (usize, usize) = (128, 64);
const BOUND_PADDING: f64 = 0.02;

/// A tree with its bounding boxes: the model the station, the recovery and the mesher share.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(from = "Node", into = "Node")]
pub struct Solid {
    root: Node,
    /// Boxes in pre-order of the tree's nodes, in the model frame.
    bounds: Vec<Aabb>,
}

impl From<Node> for Solid {
    fn from(root: Node) -> Self {
        Solid::new(root)
    }
}

impl From<Solid> for Node {
    fn from(solid: Solid) -> Self {
        solid.root
    }
}

impl Solid {
    pub fn new(root: Node) -> Self {
        let mut bounds = Vec::new();
        bound(&root, &[], &mut bounds);
        Self { root, bounds }
    }

    pub fn root(&self) -> &Node {
        &self.root
    }

    /// The implicit function of the whole tree at a point of the model frame.
    pub fn value(&self, p: &Point3<f64>) -> f64 {
        self.root.value(p)
    }

    pub fn value_and_gradient(&self, p: &Point3<f64>) -> (f64, Vector3<f64>) {
        self.root.value_and_gradient(p)
    }

    /// The box around the whole solid.
    pub fn bounds(&self) -> Aabb {
        self.bounds[0]
    }

    /// Every node's box in the model frame, in pre-order of the tree (root first, then the left
    /// subtree, then the right), for walkers of the tree such as the mesher.
    pub fn node_bounds(&self) -> &[Aabb] {
        &self.bounds
    }

    /// Whether `p` lies inside the solid (F > 0), skipping the subtrees whose box does not hold it.
    pub fn contains(&self, p: &Point3<f64>) -> bool {
        let mut index = 0;
        self.contains_below(&self.root, p, p, &mut index)
    }

    /// `model` is the point in the model frame (for the boxes), `local` the same point in the
    /// frame of `node`'s parent; `index` walks the pre-order numbering of `bounds`.
    fn contains_below(
        &self,
        node: &Node,
        model: &Point3<f64>,
        local: &Point3<f64>,
        index: &mut usize,
    ) -> bool {
        let here = *index;
        *index += 1;
        if !self.bounds[here].contains(model) {
            *index += subtree_size(node) - 1;
            return false;
        }
        match &node.kind {
            NodeKind::Boolean {
                op, left, right, ..
            } => {
                let q = node.place.inverse(local);
                let in_left = self.contains_below(left, model, &q, index);
                let in_right = self.contains_below(right, model, &q, index);
                match op {
                    Boolean::Union => in_left || in_right,
                    Boolean::Intersection => in_left && in_right,
                    Boolean::Difference => in_left && !in_right,
                }
            }
            _ => node.value(local) > 0.0,
        }
    }
}

fn subtree_size(node: &Node) -> usize {
    match &node.kind {
        NodeKind::Boolean { left, right, .. } => 1 + subtree_size(left) + subtree_size(right),
        _ => 1,
    }
}

/// Fills `bounds` in pre-order with each node's box in the model frame; `ancestors` holds the
/// deformations of the nodes above, outermost first. Returns the node's box.
fn bound(node: &Node, ancestors: &[&Deformations], bounds: &mut Vec<Aabb>) -> Aabb {
    let here = bounds.len();
    bounds.push(Aabb::empty());
    let mut chain: Vec<&Deformations> = ancestors.to_vec();
    chain.push(&node.place);
    let to_model = |p: Point3<f64>| chain.iter().rev().fold(p, |q, d| d.apply(&q));
    let aabb = match &node.kind {
        NodeKind::Supershape { shape } => {
            let mut aabb = Aabb::empty();
            let (longitudes, latitudes) = BOUND_SAMPLES;
            for i in 0..longitudes {
                let theta =
                    -std::f64::consts::PI + std::f64::consts::TAU * i as f64 / longitudes as f64;
                for j in 0..=latitudes {
                    let phi = -std::f64::consts::FRAC_PI_2
                        + std::f64::consts::PI * j as f64 / latitudes as f64;
                    aabb.grow(&to_model(shape.point(theta, phi)));
                }
            }
            aabb.padded(BOUND_PADDING * aabb.diagonal())
        }
        NodeKind::Cuboid { half_extents } => {
            let mut aabb = Aabb::empty();
            // A box's faces under a nonlinear deformation bulge: sample each face on a grid.
            let steps = 8;
            for i in 0..=steps {
                for j in 0..=steps {
                    let (u, v) = (
                        -1.0 + 2.0 * i as f64 / steps as f64,
                        -1.0 + 2.0 * j as f64 / steps as f64,
                    );
                    for axis in 0..3 {
                        for side in [-1.0, 1.0] {
                            let mut c = [0.0; 3];
                            c[axis] = side;
                            c[(axis + 1) % 3] = u;
                            c[(axis + 2) % 3] = v;
                            aabb.grow(&to_model(Point3::new(
                                c[0] * half_extents[0],
                                c[1] * half_extents[1],
                                c[2] * half_extents[2],
                            )));
                        }
                    }
                }
            }
            aabb.padded(BOUND_PADDING * aabb.diagonal())
        }
        NodeKind::Boolean {
            op, left, right, ..
        } => {
            let l = bound(left, &chain, bounds);
            let r = bound(right, &chain, bounds);
            match op {
                Boolean::Union => l.union(&r),
                Boolean::Intersection => l.intersection(&r),
                Boolean::Difference => l,
            }
        }
    };
    bounds[here] = aabb;
    aabb
}

#[cfg(test)]
mod tests {
    use super::super::deform::Deformation;
    use super::super::formula::Superformula;
    use super::*;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    fn moved(x: f64, y: f64, z: f64) -> Deformations {
        Deformations(vec![Deformation::Rigid(Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.3),
        ))])
    }

    fn sphere(radius: f64, place: Deformations) -> Node {
        Node::supershape(
            Supershape {
                scale: [radius; 3],
                ..Supershape::sphere()
            },
            place,
        )
    }

    /// A hexagonal prism minus a bore, twisted, united with a tapered, bent lobed shape.
    fn tree() -> Node {
        let hexagon = Supershape {
            r1: Superformula::new(6.0, 8.0, 4.0, 4.0, 1.0, 1.0).unwrap(),
            r2: Superformula::new(4.0, 20.0, 20.0, 20.0, 1.0, 1.0).unwrap(),
            scale: [20.0, 20.0, 12.0],
        };
        let nut = Node::boolean(
            Boolean::Difference,
            RFunction::P(2),
            Node::supershape(
                hexagon,
                Deformations(vec![Deformation::Twist { rate: 0.02 }]),
            ),
            sphere(8.0, Deformations::default()),
        );
        let lobes = Node::supershape(
            Supershape {
                r1: Superformula::new(5.0, 2.0, 7.0, 7.0, 1.0, 1.0).unwrap(),
                r2: Superformula::circle(),
                scale: [6.0, 6.0, 10.0],
            },
            Deformations(vec![
                Deformation::Taper {
                    kx: 0.02,
                    ky: -0.01,
                },
                Deformation::Bend { curvature: 0.01 },
                Deformation::Rigid(Isometry3::translation(24.0, 0.0, 0.0)),
            ]),
        );
        let mut both = Node::boolean(Boolean::Union, RFunction::Alpha(0.5), nut, lobes);
        both.place = moved(5.0, -3.0, 2.0);
        both
    }

    fn grid(aabb: &Aabb, steps: usize) -> impl Iterator<Item = Point3<f64>> + '_ {
        let span = aabb.max - aabb.min;
        (0..steps).flat_map(move |i| {
            (0..steps).flat_map(move |j| {
                (0..steps).map(move |k| {
                    aabb.min
                        + span.component_mul(&Vector3::new(
                            (i as f64 + 0.37) / steps as f64,
                            (j as f64 + 0.61) / steps as f64,
                            (k as f64 + 0.13) / steps as f64,
                        ))
                })
            })
        })
    }

    #[test]
    fn pruned_classification_agrees_with_the_full_function() {
        let solid = Solid::new(tree());
        let around = solid.bounds().padded(10.0);
        let (mut inside, mut total) = (0, 0);
        for p in grid(&around, 24) {
            let full = solid.value(&p) > 0.0;
            assert_eq!(solid.contains(&p), full, "{p}");
            inside += usize::from(full);
            total += 1;
        }
        assert!(
            inside > total / 20 && inside < total / 2,
            "{inside} of {total}"
        );
    }

    #[test]
    fn every_primitive_lies_inside_its_box() {
        let solid = Solid::new(tree());
        // Points just inside the surface of the whole solid are inside its box.
        for p in grid(&solid.bounds().padded(5.0), 20) {
            if solid.value(&p) > 0.0 {
                assert!(solid.bounds().contains(&p), "{p}");
            }
        }
        // The bore is removed: the centre of the nut is outside, its wall inside.
        let place = moved(5.0, -3.0, 2.0);
        assert!(!solid.contains(&place.apply(&Point3::new(0.0, 0.0, 0.0))));
        assert!(solid.contains(&place.apply(&Point3::new(14.0, 0.0, 0.0))));
    }

    #[test]
    fn gradients_match_finite_differences() {
        let solid = Solid::new(tree());
        let h = 1e-6;
        let mut checked = 0;
        for p in grid(&solid.bounds(), 9) {
            let (value, gradient) = solid.value_and_gradient(&p);
            assert!((value - solid.value(&p)).abs() < 1e-12);
            let numeric = Vector3::from_fn(|axis, _| {
                let mut step = Vector3::zeros();
                step[axis] = h;
                (solid.value(&(p + step)) - solid.value(&(p - step))) / (2.0 * h)
            });
            // Skip the creases of max-like functions (the box, R_alpha's corner) where the
            // gradient jumps.
            if (numeric - gradient).norm() < 1e-5 * (1.0 + numeric.norm()) {
                checked += 1;
            }
        }
        assert!(checked > 9 * 9 * 9 * 95 / 100, "{checked} of 729 agree");
    }

    #[test]
    fn a_solid_round_trips_through_json() {
        let solid = Solid::new(tree());
        let json = serde_json::to_string(&solid).unwrap();
        let back: Solid = serde_json::from_str(&json).unwrap();
        assert_eq!(back, solid);
        assert_eq!(solid.root().counts(), (3, 2));
        assert!(json.contains("\"node\":\"boolean\""), "{json}");
    }

    #[test]
    fn a_cuboid_is_a_box() {
        let cuboid = Node::cuboid([2.0, 3.0, 4.0], Deformations::default());
        assert!((cuboid.value(&Point3::new(1.0, 0.0, 0.0)) - 0.5).abs() < 1e-15);
        assert!((cuboid.value(&Point3::new(0.0, 0.0, 8.0)) + 1.0).abs() < 1e-15);
        assert!(cuboid.value(&Point3::new(1.9, 2.9, 3.9)) > 0.0);
    }
}
