//! Sharp edges where two primitives' surfaces meet (seed 000 section 4: the intersection curves
//! kept by vertices on them). Marching tetrahedra cuts such an edge off with a band of triangles
//! whose vertices lie on one surface or the other. Every mesh edge from a vertex of primitive i to
//! one of primitive j crosses the intersection curve C_ij: it is split at a point of C_ij found by
//! Gauss-Newton on the pair f_i = f_j = 0 (the paper refines intersection vertices on the
//! primitives until |F| < epsilon; here both primitives are solved at once). A split replaces the
//! edge's two triangles by four, the same on both sides, so the mesh stays closed and oriented,
//! and in a triangle with two split edges the new vertices are joined by an edge that follows the
//! curve. Curve edges longer than delta are then split at their midpoint pulled onto the curve.

use foldhash::{HashMap, HashMapExt};

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::super::csg::Solid;
use super::leaves::Leaves;
use super::regula_falsi;
use super::tetra::Surface;

const MAX_NEWTON_STEPS: u32 = 30;
const MAX_DELTA_PASSES: u32 = 12;

pub(super) fn sharpen(
    leaves: &Leaves,
    solid: &Solid,
    surface: &mut Surface,
    epsilon: f64,
    delta: f64,
) {
    // Edges joining vertices of two different primitives cross their intersection curve.
    let splits = choose_splits(surface, |surface, a, b| {
        let ((i, i2), (j, j2)) = (surface.on[a], surface.on[b]);
        if i != i2 || j != j2 || i == j {
            return None;
        }
        let (pa, pb) = (surface.vertices[a], surface.vertices[b]);
        let start = balance_point(leaves, i, j, pa, pb, epsilon);
        let point = curve_point(leaves, i, j, start, epsilon)?;
        acceptable(leaves, solid, epsilon, &point, &start, (pb - pa).norm())
            .then_some((point, (i, j)))
    });
    apply_splits(surface, splits);
    // Curve edges longer than delta are split on the curve.
    for _ in 0..MAX_DELTA_PASSES {
        let splits = choose_splits(surface, |surface, a, b| {
            let ((i, j), pair_b) = (surface.on[a], surface.on[b]);
            if i == j || pair_b != (i, j) {
                return None;
            }
            let (pa, pb) = (surface.vertices[a], surface.vertices[b]);
            let length = (pb - pa).norm();
            if length <= delta {
                return None;
            }
            let start = nalgebra::center(&pa, &pb);
            let point = curve_point(leaves, i, j, start, epsilon)?;
            acceptable(leaves, solid, epsilon, &point, &start, length).then_some((point, (i, j)))
        });
        if splits.is_empty() {
            break;
        }
        apply_splits(surface, splits);
    }
}

/// A split point is kept if the whole tree vanishes there (the curve point is not buried inside
/// another primitive) and it stays near the edge it replaces (so no triangle folds over).
fn acceptable(
    leaves: &Leaves,
    solid: &Solid,
    epsilon: f64,
    point: &Point3<f64>,
    start: &Point3<f64>,
    length: f64,
) -> bool {
    (point - start).norm() <= 0.5 * length && vanishes(leaves, solid, epsilon, point)
}

/// |F| < epsilon for the whole tree at `point`: proved from the bounds of its primitives near it, as the mesh's
/// final check does, else by the tree's value.
fn vanishes(leaves: &Leaves, solid: &Solid, epsilon: f64, point: &Point3<f64>) -> bool {
    leaves.proves_on_surface(point, epsilon) || solid.value(point).abs() < epsilon
}

type Split = (Point3<f64>, (usize, usize));

/// The split point of every edge (visited once, from the triangle where it runs from the lower
/// vertex index to the higher) that `decide` splits, decided on every core.
fn choose_splits(
    surface: &Surface,
    decide: impl Fn(&Surface, usize, usize) -> Option<Split> + Sync,
) -> HashMap<(u32, u32), Split> {
    surface
        .triangles
        .par_iter()
        .flat_map_iter(|t| (0..3).map(move |k| (t[k], t[(k + 1) % 3])))
        .filter(|(a, b)| a < b)
        .filter_map(|(a, b)| decide(surface, a as usize, b as usize).map(|split| ((a, b), split)))
        .collect::<Vec<_>>()
        .into_iter()
        .collect()
}

/// Inserts the split vertices and re-triangulates every triangle with split edges; each edge is
/// split identically for its two triangles.
fn apply_splits(surface: &mut Surface, splits: HashMap<(u32, u32), Split>) {
    let mut inserted = HashMap::with_capacity(splits.len());
    let mut keys: Vec<_> = splits.keys().copied().collect();
    keys.sort_unstable();
    // A triangle with fewer than two ends of split edges among its corners keeps its shape: most of them, which
    // then need no look-up of their edges.
    let mut split_end = vec![false; surface.vertices.len()];
    for &(a, b) in &keys {
        split_end[a as usize] = true;
        split_end[b as usize] = true;
    }
    for key in keys {
        let (point, (i, j)) = splits[&key];
        surface.vertices.push(point);
        surface.on.push((i.min(j), i.max(j)));
        // Kept only where it vanishes (`acceptable`).
        surface.checked.push(true);
        inserted.insert(key, (surface.vertices.len() - 1) as u32);
    }
    let split_of = |a: u32, b: u32| inserted.get(&(a.min(b), a.max(b))).copied();
    let old = std::mem::take(&mut surface.triangles);
    let mut triangles = Vec::with_capacity(old.len() + 4 * inserted.len());
    for t in old {
        if t.iter().filter(|&&v| split_end[v as usize]).count() < 2 {
            triangles.push(t);
            continue;
        }
        let mids: [Option<u32>; 3] = std::array::from_fn(|k| split_of(t[k], t[(k + 1) % 3]));
        let count = mids.iter().flatten().count();
        // Rotate so that the split edges come first: mids[0] for a single split, mids[0] and
        // mids[1] for two.
        let rotation = match count {
            1 => mids.iter().position(Option::is_some).unwrap_or(0),
            2 => (mids.iter().position(Option::is_none).unwrap_or(0) + 1) % 3,
            _ => 0,
        };
        let [a, b, c] = std::array::from_fn(|k| t[(k + rotation) % 3]);
        let m: [Option<u32>; 3] = std::array::from_fn(|k| mids[(k + rotation) % 3]);
        match (count, m) {
            (1, [Some(m0), _, _]) => triangles.extend([[a, m0, c], [m0, b, c]]),
            (2, [Some(m0), Some(m1), _]) => {
                triangles.push([m0, b, m1]);
                let p = |v: u32| surface.vertices[v as usize];
                if (p(a) - p(m1)).norm() <= (p(m0) - p(c)).norm() {
                    triangles.extend([[a, m0, m1], [a, m1, c]]);
                } else {
                    triangles.extend([[a, m0, c], [m0, m1, c]]);
                }
            }
            (3, [Some(m0), Some(m1), Some(m2)]) => {
                triangles.extend([[a, m0, m2], [m0, b, m1], [m2, m1, c], [m0, m1, m2]])
            }
            _ => triangles.push(t),
        }
    }
    surface.triangles = triangles;
}

/// The point of segment [a, b] (a on primitive i, b on j) where |f_i| = |f_j| (the gap |f_i| - |f_j| is at most 0
/// at a and at least 0 at b), by regula falsi: a start for the curve search near the segment. Its midpoint if the
/// gap does not change sign along it.
fn balance_point(
    leaves: &Leaves,
    i: usize,
    j: usize,
    a: Point3<f64>,
    b: Point3<f64>,
    epsilon: f64,
) -> Point3<f64> {
    let at = |t: f64| a + (b - a) * t;
    let gap = |t: f64| {
        let p = at(t);
        leaves.leaves[i].value(&p).abs() - leaves.leaves[j].value(&p).abs()
    };
    let t = regula_falsi::root(gap, (gap(0.0), gap(1.0)), 1e-3 * epsilon).map_or(0.5, |(t, _)| t);
    at(t)
}

/// A point of the intersection curve of primitives i and j near `start`: Gauss-Newton on
/// (f_i, f_j) = 0 with the minimum-norm step (the 2 x 3 Jacobian's pseudo-inverse), until both
/// values are far below epsilon. None where the surfaces are nearly tangent or it does not
/// converge.
pub(super) fn curve_point(
    leaves: &Leaves,
    i: usize,
    j: usize,
    start: Point3<f64>,
    epsilon: f64,
) -> Option<Point3<f64>> {
    let mut x = start;
    for _ in 0..MAX_NEWTON_STEPS {
        let (fi, gi) = leaves.leaves[i].value_and_gradient(&x);
        let (fj, gj) = leaves.leaves[j].value_and_gradient(&x);
        if fi.abs().max(fj.abs()) < 1e-3 * epsilon {
            return Some(x);
        }
        let (a, b, c) = (gi.dot(&gi), gi.dot(&gj), gj.dot(&gj));
        let det = a * c - b * b;
        // sin^2 of the angle between the normals below 1e-6: too tangent to meet in a sharp edge.
        if det.is_nan() || det <= 1e-6 * a * c {
            return None;
        }
        let (li, lj) = ((c * fi - b * fj) / det, (a * fj - b * fi) / det);
        let step: Vector3<f64> = gi * li + gj * lj;
        x -= step;
        if !x.coords.iter().all(|v| v.is_finite()) {
            return None;
        }
    }
    None
}
