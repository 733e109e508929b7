//! The CSG tree seen from its primitives: each leaf with the chain of placements above it (so its
//! own implicit function and parametric surface can be reached from the model frame), its box, and
//! the Boolean expression that turns the leaves' signs into the solid's. The mesher asks "which
//! primitive's surface does this root lie on", which the tree's single value cannot answer.

use nalgebra::{Matrix3, Point3, Vector3};

use super::super::csg::{Aabb, Node, NodeKind, Solid};
use super::super::deform::Deformations;
use super::super::rfunc::{Boolean, RFunction};

/// One primitive of the tree.
pub(super) struct Leaf<'a> {
    /// The primitive node; its own placement is applied by `Node::value`.
    node: &'a Node,
    /// The placements of the Boolean nodes above it, outermost (root) first.
    ancestors: Vec<&'a Deformations>,
    /// Its box in the model frame.
    bounds: Aabb,
    /// Its box cut by every ancestor's box: outside it, its surface cannot be part of the solid's.
    pub clip: Aabb,
}

enum Expr {
    Leaf(usize),
    /// A Boolean node with its box in the model frame: outside it the node's solid is not, and its value is < 0.
    Op(Boolean, RFunction, Aabb, Box<Expr>, Box<Expr>),
}

/// The tree as leaves plus the Boolean expression over their signs.
pub(super) struct Leaves<'a> {
    pub leaves: Vec<Leaf<'a>>,
    expr: Expr,
}

impl<'a> Leaves<'a> {
    pub fn new(solid: &'a Solid) -> Self {
        let mut leaves = Vec::new();
        let mut index = 0;
        let root_box = solid.node_bounds()[0];
        let expr = flatten(
            solid.root(),
            &[],
            root_box,
            solid.node_bounds(),
            &mut index,
            &mut leaves,
        );
        Self { leaves, expr }
    }

    /// The values at a model point of the leaves whose boxes hold it, all but `skip`'s; every other leaf is
    /// outside there.
    pub fn values_except(&self, p: &Point3<f64>, skip: Option<usize>) -> LeafValues {
        LeafValues(
            self.leaves
                .iter()
                .enumerate()
                .filter(|&(i, leaf)| Some(i) != skip && leaf.bounds.contains(p))
                .map(|(i, leaf)| (i, leaf.value(p)))
                .collect(),
        )
    }

    pub fn values(&self, p: &Point3<f64>) -> LeafValues {
        self.values_except(p, None)
    }

    /// The solid's inside/outside from its leaves' (seed 000: an R-function's sign is the Boolean
    /// function of its arguments' signs).
    pub fn classify(&self, values: &LeafValues) -> bool {
        evaluate(&self.expr, values)
    }

    /// The solid's inside/outside at a model point, as `classify(&values(p))` but asking each leaf only when
    /// the Boolean expression still depends on it (a union whose left side holds p needs no right side).
    pub fn inside(&self, p: &Point3<f64>) -> bool {
        self.inside_of(&self.expr, p)
    }

    fn inside_of(&self, expr: &Expr, p: &Point3<f64>) -> bool {
        match expr {
            Expr::Leaf(i) => self.leaves[*i].is_inside(p),
            Expr::Op(_, _, bounds, ..) if !bounds.contains(p) => false,
            Expr::Op(op, _, _, left, right) => match op {
                Boolean::Union => self.inside_of(left, p) || self.inside_of(right, p),
                Boolean::Intersection => self.inside_of(left, p) && self.inside_of(right, p),
                Boolean::Difference => self.inside_of(left, p) && !self.inside_of(right, p),
            },
        }
    }

    /// Whether the bounds of the tree's value at `p` ([`Self::value_bounds`]) prove |F(p)| < epsilon, with half
    /// of epsilon left for the rounding of the tree's own evaluation.
    pub fn proves_on_surface(&self, p: &Point3<f64>, epsilon: f64) -> bool {
        proves(self.value_bounds(p), epsilon)
    }

    /// As [`Self::proves_on_surface`], with the leaves' values at `p` already taken (those of every leaf whose box
    /// holds it).
    pub fn values_prove_on_surface(
        &self,
        p: &Point3<f64>,
        values: &LeafValues,
        epsilon: f64,
    ) -> bool {
        let value = |i: usize| values.value(i).unwrap_or_else(|| self.leaves[i].value(p));
        proves(self.bounds_of(&self.expr, p, &value), epsilon)
    }

    /// Bounds of the whole tree's implicit function at a model point, from the leaves whose boxes hold it (their
    /// values, exactly as `Solid::value` computes them) and the others (or whole subtrees whose boxes do not hold
    /// it) known only to be outside, (-inf, 0]: the
    /// R-functions are monotone, so their values at the ends bound the tree (see `RFunction::combine_bounds`).
    /// Most of a part's primitives are far from any one point, and a point on the surface gets bounds as narrow
    /// as its own primitive's value at a small fraction of the tree's cost. `None` under an R-function that is not
    /// monotone.
    pub fn value_bounds(&self, p: &Point3<f64>) -> Option<(f64, f64)> {
        self.bounds_of(&self.expr, p, &|i| self.leaves[i].value(p))
    }

    /// The bounds below `expr`, with `value(i)` leaf i's value at `p` where its box holds `p`.
    fn bounds_of(
        &self,
        expr: &Expr,
        p: &Point3<f64>,
        value: &dyn Fn(usize) -> f64,
    ) -> Option<(f64, f64)> {
        match expr {
            Expr::Leaf(i) => {
                let leaf = &self.leaves[*i];
                Some(if leaf.bounds.contains(p) {
                    let value = value(*i);
                    (value, value)
                } else {
                    (f64::NEG_INFINITY, 0.0)
                })
            }
            // The whole subtree outside: known only to be outside, as a leaf would be.
            Expr::Op(_, _, bounds, ..) if !bounds.contains(p) => Some((f64::NEG_INFINITY, 0.0)),
            Expr::Op(op, rfunction, _, left, right) => rfunction.combine_bounds(
                *op,
                self.bounds_of(left, p, value)?,
                self.bounds_of(right, p, value)?,
            ),
        }
    }
}

/// |F| < epsilon proved by bounds of F, with half of epsilon left for the rounding of the tree's own evaluation.
fn proves(bounds: Option<(f64, f64)>, epsilon: f64) -> bool {
    bounds.is_some_and(|(lo, hi)| lo > -0.5 * epsilon && hi < 0.5 * epsilon)
}

/// Some leaves' values at one point, in the order of the leaves: those whose boxes hold the point. A leaf not
/// among them is outside there. A few per point, where a part has tens of leaves: the mesher keeps one per
/// grid vertex at the ends of the edges the surface crosses.
#[derive(Clone)]
pub(super) struct LeafValues(Vec<(usize, f64)>);

impl LeafValues {
    pub fn value(&self, leaf: usize) -> Option<f64> {
        self.0.iter().find(|(i, _)| *i == leaf).map(|(_, v)| *v)
    }

    /// Adds a leaf's value (one not among them).
    pub fn insert(&mut self, leaf: usize, value: f64) {
        self.0.push((leaf, value));
    }

    pub fn is_inside(&self, leaf: usize) -> bool {
        self.value(leaf).is_some_and(|v| v > 0.0)
    }

    /// The leaves inside at one point and outside at the other (either may be a leaf whose box holds only
    /// one of them), in increasing order.
    pub fn flipped(&self, other: &LeafValues) -> Vec<usize> {
        let mut leaves: Vec<usize> = self.0.iter().chain(&other.0).map(|(i, _)| *i).collect();
        leaves.sort_unstable();
        leaves.dedup();
        leaves.retain(|&i| self.is_inside(i) != other.is_inside(i));
        leaves
    }
}

fn evaluate(expr: &Expr, values: &LeafValues) -> bool {
    match expr {
        Expr::Leaf(i) => values.is_inside(*i),
        Expr::Op(op, _, _, left, right) => {
            let (l, r) = (evaluate(left, values), evaluate(right, values));
            match op {
                Boolean::Union => l || r,
                Boolean::Intersection => l && r,
                Boolean::Difference => l && !r,
            }
        }
    }
}

/// Walks the tree in the pre-order of `Solid::node_bounds`, collecting the leaves.
fn flatten<'a>(
    node: &'a Node,
    ancestors: &[&'a Deformations],
    clip: Aabb,
    bounds: &[Aabb],
    index: &mut usize,
    leaves: &mut Vec<Leaf<'a>>,
) -> Expr {
    let own = bounds[*index];
    *index += 1;
    match &node.kind {
        NodeKind::Boolean {
            op,
            rfunction,
            left,
            right,
        } => {
            let mut chain = ancestors.to_vec();
            chain.push(&node.place);
            let clip = clip.intersection(&own);
            let l = flatten(left, &chain, clip, bounds, index, leaves);
            let r = flatten(right, &chain, clip, bounds, index, leaves);
            Expr::Op(*op, *rfunction, own, Box::new(l), Box::new(r))
        }
        _ => {
            leaves.push(Leaf {
                node,
                ancestors: ancestors.to_vec(),
                bounds: own,
                clip: clip.intersection(&own),
            });
            Expr::Leaf(leaves.len() - 1)
        }
    }
}

impl Leaf<'_> {
    pub fn node(&self) -> &Node {
        self.node
    }

    /// The point in the frame the leaf's own placement maps into (its parent's).
    fn to_parent(&self, p: &Point3<f64>) -> Point3<f64> {
        self.ancestors.iter().fold(*p, |q, d| d.inverse(&q))
    }

    /// The primitive's implicit function at a model point.
    pub fn value(&self, p: &Point3<f64>) -> f64 {
        self.node.value(&self.to_parent(p))
    }

    /// The primitive's implicit function and its gradient in the model frame.
    pub fn value_and_gradient(&self, p: &Point3<f64>) -> (f64, Vector3<f64>) {
        let (q, jacobian) = self.ancestors.iter().fold(
            (*p, Matrix3::identity()),
            |(q, jacobian): (Point3<f64>, Matrix3<f64>), d| {
                let (inner, step) = d.inverse_with_jacobian(&q);
                (inner, step * jacobian)
            },
        );
        let (value, gradient) = self.node.value_and_gradient(&q);
        (value, jacobian.transpose() * gradient)
    }

    pub fn is_inside(&self, p: &Point3<f64>) -> bool {
        self.bounds.contains(p) && self.value(p) > 0.0
    }

    /// A point of the primitive's canonical frame (its parametric form) taken to the model frame
    /// through its own and its ancestors' deformations (seed 000 section 4, initialisation).
    pub fn to_model(&self, canonical: &Point3<f64>) -> Point3<f64> {
        let parent = self.node.place.apply(canonical);
        self.ancestors.iter().rev().fold(parent, |q, d| d.apply(&q))
    }
}

#[cfg(test)]
mod tests {
    use super::super::hub::brake_hub;
    use super::*;

    /// One point in each of n[0] x n[1] x n[2] cells of the solid's box, off the cells' centres.
    fn across_the_box(solid: &Solid, n: [usize; 3]) -> Vec<Point3<f64>> {
        let b = solid.bounds();
        let mut points = Vec::new();
        for i in 0..n[0] {
            for j in 0..n[1] {
                for k in 0..n[2] {
                    let t = Vector3::new(
                        (i as f64 + 0.3) / n[0] as f64,
                        (j as f64 + 0.7) / n[1] as f64,
                        (k as f64 + 0.4) / n[2] as f64,
                    );
                    points.push(b.min + (b.max - b.min).component_mul(&t));
                }
            }
        }
        points
    }

    #[test]
    fn leaf_signs_classify_like_the_solid() {
        let solid = brake_hub();
        let leaves = Leaves::new(&solid);
        assert_eq!(leaves.leaves.len(), solid.root().counts().0);
        let (mut inside, mut total) = (0, 0);
        for p in across_the_box(&solid, [40, 40, 10]) {
            assert_eq!(leaves.inside(&p), solid.contains(&p), "{p}");
            inside += usize::from(solid.contains(&p));
            total += 1;
        }
        assert!(
            inside > total / 20 && inside < total / 2,
            "{inside} of {total}"
        );
    }

    #[test]
    fn the_trees_value_lies_within_its_bounds_from_the_leaves_near_a_point() {
        let solid = brake_hub();
        let leaves = Leaves::new(&solid);
        for p in across_the_box(&solid, [30, 30, 12]) {
            let value = solid.value(&p);
            let (lo, hi) = leaves.value_bounds(&p).expect("R_p is monotone");
            assert!(
                lo <= value + 1e-12 && value <= hi + 1e-12,
                "{p}: {value} not in [{lo}, {hi}]"
            );
        }
        // On the surface the bounds are about as narrow as the value of the primitive the point lies on (at most
        // twice it, where a union's other side is far): at every vertex of the hub's mesh within a tenth of the
        // mesh's epsilon (1e-6), so that they prove its check without the tree's value.
        let mesh =
            super::super::polygonise(&solid, &super::super::MeshParams::with_cell(2.0)).unwrap();
        for v in &mesh.vertices {
            let (lo, hi) = leaves.value_bounds(v).unwrap();
            let value = solid.value(v);
            // To the tree's own rounding: x + y + |(x, y)| of a far y cancels to about 1e-16 |y|.
            assert!(
                lo - 1e-12 <= value && value <= hi + 1e-12,
                "{v}: {value} not in [{lo}, {hi}]"
            );
            assert!(lo > -1e-7 && hi < 1e-7, "{v}: [{lo}, {hi}]");
            // The proof from values already taken is the same proof.
            let values = leaves.values(v);
            for epsilon in [1e-6, 1e-15] {
                assert_eq!(
                    leaves.values_prove_on_surface(v, &values, epsilon),
                    leaves.proves_on_surface(v, epsilon)
                );
            }
        }
    }

    #[test]
    fn leaf_values_give_the_leaves_signs_and_which_flip_between_two_points() {
        let solid = brake_hub();
        let leaves = Leaves::new(&solid);
        let points = across_the_box(&solid, [12, 12, 6]);
        let mut flips = 0;
        for pair in points.windows(2) {
            let (va, vb) = (leaves.values(&pair[0]), leaves.values(&pair[1]));
            let inside = |p: &Point3<f64>, i: usize| {
                leaves.leaves[i].bounds.contains(p) && leaves.leaves[i].value(p) > 0.0
            };
            let expected: Vec<usize> = (0..leaves.leaves.len())
                .filter(|&i| inside(&pair[0], i) != inside(&pair[1], i))
                .collect();
            assert_eq!(va.flipped(&vb), expected);
            flips += expected.len();
            assert_eq!(leaves.classify(&va), solid.contains(&pair[0]));
            // Leaving one leaf out leaves its value unknown, and only its.
            let skip = leaves.leaves.len() / 2;
            let without = leaves.values_except(&pair[0], Some(skip));
            assert_eq!(without.value(skip), None);
            for i in (0..leaves.leaves.len()).filter(|&i| i != skip) {
                assert_eq!(without.value(i), va.value(i));
            }
        }
        assert!(flips > 20, "{flips} leaves flip between neighbours");
    }

    #[test]
    fn leaf_gradients_match_finite_differences() {
        let solid = brake_hub();
        let leaves = Leaves::new(&solid);
        let h = 1e-6;
        for leaf in &leaves.leaves {
            let c = nalgebra::center(&leaf.bounds.min, &leaf.bounds.max);
            let p = c + Vector3::new(0.31, -0.17, 0.23);
            let (value, gradient) = leaf.value_and_gradient(&p);
            assert!((value - leaf.value(&p)).abs() < 1e-12);
            let numeric = Vector3::from_fn(|axis, _| {
                let mut step = Vector3::zeros();
                step[axis] = h;
                (leaf.value(&(p + step)) - leaf.value(&(p - step))) / (2.0 * h)
            });
            assert!(
                (numeric - gradient).norm() < 1e-5 * (1.0 + numeric.norm()),
                "{p}: {gradient} vs {numeric}"
            );
        }
    }
}
