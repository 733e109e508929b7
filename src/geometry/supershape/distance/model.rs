//! The solid seen by the distance search: its primitives flattened out of the CSG tree with the chain
//! of places from the root down to each, the smooth surfaces that bound them (a supershape's surface,
//! or one face of a box), and the Boolean expression over the primitives' insides.
//!
//! An R-function's sign is the Boolean of its arguments' signs (seed 000 section 2), so the solid's
//! inside is that Boolean of the primitives' insides, whatever R-function the tree uses. That lets the
//! search ask whether a point lying on some surfaces is on the solid's boundary by imposing each side
//! of those surfaces in turn (see [`Model::on_boundary`]).

use nalgebra::{Matrix3, Point3, Vector3};

use super::super::csg::{Node, NodeKind, Solid};
use super::super::deform::{Deformation, Deformations};
use super::super::rfunc::Boolean;
use super::super::shape::Supershape;
use super::lagrange::Surfaces;

/// A primitive in its canonical frame.
#[derive(Debug, Clone, Copy)]
pub(super) enum Primitive {
    Supershape(Supershape),
    Cuboid([f64; 3]),
}

/// One primitive and the places from the root down to it.
#[derive(Debug, Clone)]
pub(super) struct Leaf {
    /// The nodes' places, root first; a model point reaches the canonical frame by inverting them in
    /// this order (seed 000 eq. 9).
    chain: Vec<Deformations>,
    pub primitive: Primitive,
    /// The index of the leaf's first surface in [`Model::surfaces`].
    pub first_surface: usize,
    /// Whether every deformation on the chain is affine (rigid or scale), so that a box face stays a
    /// plane and its function has a zero Hessian.
    affine: bool,
}

impl Leaf {
    pub fn to_model(&self, q: &Point3<f64>) -> Point3<f64> {
        self.chain.iter().rev().fold(*q, |x, place| place.apply(&x))
    }

    fn to_canonical(&self, x: &Point3<f64>) -> Point3<f64> {
        self.chain.iter().fold(*x, |q, place| place.inverse(&q))
    }

    /// The canonical point and the Jacobian of the model-to-canonical map.
    fn to_canonical_with_jacobian(&self, x: &Point3<f64>) -> (Point3<f64>, Matrix3<f64>) {
        self.chain
            .iter()
            .fold((*x, Matrix3::identity()), |(q, jacobian), place| {
                let (next, local) = place.inverse_with_jacobian(&q);
                (next, local * jacobian)
            })
    }
}

/// A smooth surface of a primitive: its whole surface for a supershape, one face plane for a box.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Surface {
    pub leaf: usize,
    /// For a box face: the axis and whether it is the face at +h (true) or -h (false).
    pub face: Option<(usize, bool)>,
}

#[derive(Debug, Clone)]
enum Expr {
    Leaf(usize),
    Op(Boolean, Box<Expr>, Box<Expr>),
}

/// The flattened solid.
#[derive(Debug, Clone)]
pub(super) struct Model {
    pub leaves: Vec<Leaf>,
    pub surfaces: Vec<Surface>,
    expr: Expr,
    /// Finite-difference step (mm) for the Hessians of the surface functions.
    hessian_step: f64,
}

impl Model {
    pub fn new(solid: &Solid) -> Self {
        let mut leaves = Vec::new();
        let mut surfaces = Vec::new();
        let expr = flatten(solid.root(), &[], &mut leaves, &mut surfaces);
        // Forward differences of an analytic gradient: truncation ~ h / size, round-off
        // ~ 1e-16 size / h; h = 1e-6 of the model's size keeps both near 1e-6 relative, which only
        // slows Newton's quadratic convergence, never moves its fixed point.
        let hessian_step = 1e-6 * solid.bounds().diagonal().max(1.0);
        Self {
            leaves,
            surfaces,
            expr,
            hessian_step,
        }
    }

    /// The function of surface `s` at model point `x`: positive on the primitive's inner side, zero
    /// on the surface. A supershape's radial function (seed 000 eq. 7), 1 - side q_a / h_a for a face.
    pub fn value(&self, s: usize, x: &Point3<f64>) -> f64 {
        let surface = self.surfaces[s];
        let leaf = &self.leaves[surface.leaf];
        let q = leaf.to_canonical(x);
        match (leaf.primitive, surface.face) {
            (Primitive::Supershape(shape), _) => shape.radial(&off_axis(q)),
            (Primitive::Cuboid(half), Some((axis, positive))) => {
                1.0 - side(positive) * q[axis] / half[axis]
            }
            (Primitive::Cuboid(_), None) => unreachable!("a box surface is always a face"),
        }
    }

    /// Whether `x` is inside the solid when the listed surfaces' sides are imposed (true: on the
    /// primitive's inner side) instead of evaluated; every other surface is evaluated at `x`.
    pub fn inside_with(&self, x: &Point3<f64>, imposed: &[(usize, bool)]) -> bool {
        self.evaluate(&self.expr, x, imposed, &[])
    }

    /// Whether `x`, lying on every surface of `active`, is on the solid's boundary: near `x` the
    /// active surfaces cut space into 2^k sectors (k <= 3, crossing transversally), and `x` is on the
    /// boundary exactly when the sectors are not all inside or all outside.
    pub fn on_boundary(&self, x: &Point3<f64>, active: &[usize]) -> bool {
        // The leaves without an active surface answer the same in every sector.
        let fixed: Vec<Option<bool>> = (0..self.leaves.len())
            .map(|l| {
                let touched = active.iter().any(|&s| self.surfaces[s].leaf == l);
                (!touched).then(|| self.leaf_inside(l, x, &[]))
            })
            .collect();
        let sectors = 1usize << active.len();
        let mut imposed = [(0, false); 3];
        let mut first = None;
        for sector in 0..sectors {
            for (k, &s) in active.iter().enumerate() {
                imposed[k] = (s, sector >> k & 1 == 1);
            }
            let inside = self.evaluate(&self.expr, x, &imposed[..active.len()], &fixed);
            match first {
                None => first = Some(inside),
                Some(f) if f != inside => return true,
                _ => {}
            }
        }
        false
    }

    /// The Boolean expression at `x`; `fixed` holds the leaves' insides already known (if any).
    fn evaluate(
        &self,
        expr: &Expr,
        x: &Point3<f64>,
        imposed: &[(usize, bool)],
        fixed: &[Option<bool>],
    ) -> bool {
        match expr {
            Expr::Leaf(l) => fixed
                .get(*l)
                .copied()
                .flatten()
                .unwrap_or_else(|| self.leaf_inside(*l, x, imposed)),
            Expr::Op(op, left, right) => {
                let left = self.evaluate(left, x, imposed, fixed);
                let right = self.evaluate(right, x, imposed, fixed);
                match op {
                    Boolean::Union => left || right,
                    Boolean::Intersection => left && right,
                    Boolean::Difference => left && !right,
                }
            }
        }
    }

    fn leaf_inside(&self, l: usize, x: &Point3<f64>, imposed: &[(usize, bool)]) -> bool {
        let leaf = &self.leaves[l];
        let imposed_on = |s: usize| imposed.iter().find(|(t, _)| *t == s).map(|(_, v)| *v);
        match leaf.primitive {
            Primitive::Supershape(shape) => imposed_on(leaf.first_surface)
                .unwrap_or_else(|| shape.radial(&off_axis(leaf.to_canonical(x))) > 0.0),
            Primitive::Cuboid(half) => {
                let q = leaf.to_canonical(x);
                // Inside the box is inside all six faces.
                (0..6).all(|k| {
                    let (axis, positive) = (k / 2, k % 2 == 1);
                    imposed_on(leaf.first_surface + k)
                        .unwrap_or_else(|| side(positive) * q[axis] < half[axis])
                })
            }
        }
    }

    /// The surface index of face (`axis`, `positive`) of the box at leaf `l`.
    pub fn face(&self, l: usize, axis: usize, positive: bool) -> usize {
        self.leaves[l].first_surface + 2 * axis + usize::from(positive)
    }
}

impl Surfaces for Model {
    /// The value and gradient (model frame) of surface `s` at `x`.
    fn value_and_gradient(&self, s: usize, x: &Point3<f64>) -> (f64, Vector3<f64>) {
        let surface = self.surfaces[s];
        let leaf = &self.leaves[surface.leaf];
        let (q, jacobian) = leaf.to_canonical_with_jacobian(x);
        match (leaf.primitive, surface.face) {
            (Primitive::Supershape(shape), _) => {
                let (value, gradient) = shape.radial_and_gradient(&off_axis(q));
                (value, jacobian.transpose() * gradient)
            }
            (Primitive::Cuboid(half), Some((axis, positive))) => {
                let scale = side(positive) / half[axis];
                (
                    1.0 - scale * q[axis],
                    -scale * jacobian.row(axis).transpose(),
                )
            }
            (Primitive::Cuboid(_), None) => unreachable!("a box surface is always a face"),
        }
    }

    /// The Hessian of surface `s` at `x` whose gradient there is `gradient`: zero for a face under
    /// affine places, else forward differences of the analytic gradient, symmetrised.
    fn hessian(&self, s: usize, x: &Point3<f64>, gradient: &Vector3<f64>) -> Matrix3<f64> {
        let surface = self.surfaces[s];
        if surface.face.is_some() && self.leaves[surface.leaf].affine {
            return Matrix3::zeros();
        }
        let h = self.hessian_step;
        let mut hessian = Matrix3::zeros();
        for axis in 0..3 {
            let mut shifted = *x;
            shifted[axis] += h;
            let column = (self.value_and_gradient(s, &shifted).1 - gradient) / h;
            hessian.set_column(axis, &column);
        }
        (hessian + hessian.transpose()) * 0.5
    }
}

fn side(positive: bool) -> f64 {
    if positive {
        1.0
    } else {
        -1.0
    }
}

/// The supershape's angles (seed 000 eq. 8) and so its gradient are undefined on the canonical z
/// axis, where the surface itself is smooth: a point exactly there is moved off it by a relative
/// 1e-13, far below any measurable length.
fn off_axis(q: Point3<f64>) -> Point3<f64> {
    if q.x == 0.0 && q.y == 0.0 {
        Point3::new(1e-13 * q.z.abs().max(1e-300), q.y, q.z)
    } else {
        q
    }
}

fn flatten(
    node: &Node,
    ancestors: &[Deformations],
    leaves: &mut Vec<Leaf>,
    surfaces: &mut Vec<Surface>,
) -> Expr {
    let mut chain = ancestors.to_vec();
    chain.push(node.place.clone());
    let primitive = match &node.kind {
        NodeKind::Boolean {
            op, left, right, ..
        } => {
            let left = flatten(left, &chain, leaves, surfaces);
            let right = flatten(right, &chain, leaves, surfaces);
            return Expr::Op(*op, Box::new(left), Box::new(right));
        }
        NodeKind::Supershape { shape } => Primitive::Supershape(*shape),
        NodeKind::Cuboid { half_extents } => Primitive::Cuboid(*half_extents),
    };
    let index = leaves.len();
    let first_surface = surfaces.len();
    match primitive {
        Primitive::Supershape(_) => surfaces.push(Surface {
            leaf: index,
            face: None,
        }),
        Primitive::Cuboid(_) => surfaces.extend((0..6).map(|k| Surface {
            leaf: index,
            face: Some((k / 2, k % 2 == 1)),
        })),
    }
    let affine = chain.iter().flat_map(|place| place.0.iter()).all(|d| {
        matches!(d, Deformation::Rigid(_) | Deformation::Scale(_))
            || matches!(d, Deformation::Bend { curvature } if *curvature == 0.0)
    });
    leaves.push(Leaf {
        chain,
        primitive,
        first_surface,
        affine,
    });
    Expr::Leaf(index)
}
