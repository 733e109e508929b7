//! Marching tetrahedra over the band of cells: each cube split into the six Kuhn tetrahedra that
//! share its main diagonal (so neighbouring cubes agree on every face diagonal), and in each
//! tetrahedron the piece of surface between its inside and outside corners. A surface vertex sits
//! on a grid edge and is shared by every tetrahedron around that edge, a surface edge lies in a
//! tetrahedron face shared by exactly two tetrahedra: the result is closed and edge-manifold by
//! construction, with no ambiguous case to resolve (unlike marching cubes).
//!
//! Each vertex is the root of the primitive whose sign flips along the grid edge, found on that
//! primitive's own function (the tree's value is a product of R-function partials times it, and
//! cheaper to get exactly): the vertex remembers its primitive for the sharp-edge step.

use std::borrow::Cow;

use foldhash::{HashMap, HashMapExt};

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::band::{Bits, Grid};
use super::leaves::{LeafValues, Leaves};
use super::regula_falsi;
use super::MeshError;

/// A triangulated surface with, for each vertex, the primitives whose surfaces hold it (the
/// second equal to the first unless the vertex lies on an intersection curve).
pub(super) struct Surface {
    pub vertices: Vec<Point3<f64>>,
    pub on: Vec<(usize, usize)>,
    /// Whether |F| < epsilon was already proved for the vertex where it was made (from the leaves' values that
    /// its own step took there); the mesh's final check evaluates the others.
    pub checked: Vec<bool>,
    pub triangles: Vec<[u32; 3]>,
}

/// Corner offsets of a cube, corner c at (c & 1, c >> 1 & 1, c >> 2 & 1).
fn corner_offset(c: usize) -> [u64; 3] {
    [(c & 1) as u64, (c >> 1 & 1) as u64, (c >> 2 & 1) as u64]
}

/// The six Kuhn tetrahedra of a cube: the monotone paths from corner 0 to corner 7.
const TETRAHEDRA: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// The surface in the band's cells. The corners' signs and the edges' roots, the costly part,
/// are found on every core; which edges cross and how their vertices join is decided in one pass
/// over the cells in order, so the mesh (or the error) is the same whatever the number of cores.
pub(super) fn march(
    leaves: &Leaves,
    grid: &Grid,
    cells: &[[u64; 3]],
    epsilon: f64,
) -> Result<Surface, MeshError> {
    let corners_of = |cell: &[u64; 3]| -> [[u64; 3]; 8] {
        std::array::from_fn(|c| [0, 1, 2].map(|axis| cell[axis] + corner_offset(c)[axis]))
    };
    // The cells' corners as bits over the grid's vertices (their ids in order, no sort), their signs as bits.
    let corners = Bits::new(grid.vertex_count());
    for cell in cells {
        for ijk in corners_of(cell) {
            corners.insert(grid.vertex_id(ijk));
        }
    }
    let ids: Vec<u64> = corners.iter().collect();
    let inside_flags: Vec<bool> = ids
        .par_iter()
        .map(|&id| leaves.inside(&grid.vertex_point(grid.vertex_ijk(id))))
        .collect();
    let signs = Bits::new(grid.vertex_count());
    for (&id, _) in ids.iter().zip(&inside_flags).filter(|(_, &inside)| inside) {
        signs.insert(id);
    }
    let mut roots: HashMap<(u64, u64), u32> = HashMap::new();
    // The grid edges whose roots are wanted, (inside end, outside end) by vertex id, in vertex order.
    let mut crossings: Vec<(u64, u64)> = Vec::new();
    let mut loops: Vec<Vec<u32>> = Vec::new();
    for cell in cells {
        let corners = corners_of(cell);
        let ids = corners.map(|ijk| grid.vertex_id(ijk));
        let inside: [bool; 8] = std::array::from_fn(|c| signs.contains(ids[c]));
        if inside.iter().all(|&s| s == inside[0]) {
            continue;
        }
        for tet in TETRAHEDRA {
            // Fixed arrays, not vectors: this runs for every tetrahedron of every crossed cell.
            let (mut ins, mut outs) = ([0; 4], [0; 4]);
            let (mut n_in, mut n_out) = (0, 0);
            for c in tet {
                if inside[c] {
                    ins[n_in] = c;
                    n_in += 1;
                } else {
                    outs[n_out] = c;
                    n_out += 1;
                }
            }
            if n_in == 0 || n_out == 0 {
                continue;
            }
            let (ins, outs) = (&ins[..n_in], &outs[..n_out]);
            // The surface's corners in cyclic order: a triangle around a lone corner, or the
            // quadrilateral between two inside and two outside corners.
            let (quad, triangle);
            let edges: &[(usize, usize)] = match (n_in, n_out) {
                (1, _) => {
                    triangle = [(ins[0], outs[0]), (ins[0], outs[1]), (ins[0], outs[2])];
                    &triangle
                }
                (_, 1) => {
                    triangle = [(ins[0], outs[0]), (ins[1], outs[0]), (ins[2], outs[0])];
                    &triangle
                }
                _ => {
                    quad = [
                        (ins[0], outs[0]),
                        (ins[0], outs[1]),
                        (ins[1], outs[1]),
                        (ins[1], outs[0]),
                    ];
                    &quad
                }
            };
            // Orientation from the edges' midpoints in grid units (never degenerate, unlike the
            // roots, which may crowd at a corner): normals point from inside to outside.
            let offset = |c: usize| Vector3::from(corner_offset(c).map(|v| v as f64));
            let mid = |(a, b): (usize, usize)| (offset(a) + offset(b)) * 0.5;
            let outward = outs.iter().map(|&c| offset(c)).sum::<Vector3<f64>>() / outs.len() as f64
                - ins.iter().map(|&c| offset(c)).sum::<Vector3<f64>>() / ins.len() as f64;
            let normal = (mid(edges[1]) - mid(edges[0])).cross(&(mid(edges[2]) - mid(edges[0])));
            let mut loop_ids: Vec<u32> = edges
                .iter()
                .map(|&(i, o)| {
                    let key = (ids[i].min(ids[o]), ids[i].max(ids[o]));
                    *roots.entry(key).or_insert_with(|| {
                        crossings.push((ids[i], ids[o]));
                        (crossings.len() - 1) as u32
                    })
                })
                .collect();
            if normal.dot(&outward) < 0.0 {
                loop_ids.reverse();
            }
            loops.push(loop_ids);
        }
    }
    // The leaves' values at each end, taken once per grid vertex: a vertex ends four crossing edges on average.
    let mut ends: Vec<u64> = crossings.iter().flat_map(|&(i, o)| [i, o]).collect();
    ends.sort_unstable();
    ends.dedup();
    let end_values: Vec<(Point3<f64>, LeafValues)> = ends
        .par_iter()
        .map(|&id| {
            let p = grid.vertex_point(grid.vertex_ijk(id));
            (p, leaves.values(&p))
        })
        .collect();
    let end = |id: u64| {
        let k = ends
            .binary_search(&id)
            .expect("every crossing's end is listed");
        (end_values[k].0, &end_values[k].1)
    };
    // Solved on every core, then taken in order, so that a failure reported is the first edge's.
    let solved: Vec<Result<Root, MeshError>> = crossings
        .par_iter()
        .map(|&(inside, outside)| edge_root(leaves, end(inside), end(outside), epsilon))
        .collect();
    let solved: Vec<Root> = solved.into_iter().collect::<Result<_, _>>()?;
    let mut surface = Surface {
        vertices: solved.iter().map(|root| root.point).collect(),
        on: solved.iter().map(|root| (root.leaf, root.leaf)).collect(),
        checked: solved.iter().map(|root| root.on_surface).collect(),
        triangles: Vec::new(),
    };
    for loop_ids in &loops {
        push_polygon(&mut surface, loop_ids);
    }
    Ok(surface)
}

/// A triangle, or a quadrilateral cut along its shorter diagonal (either cut keeps the loop's
/// orientation).
fn push_polygon(surface: &mut Surface, ids: &[u32]) {
    if let [a, b, c] = *ids {
        surface.triangles.push([a, b, c]);
        return;
    }
    let [a, b, c, d] = [ids[0], ids[1], ids[2], ids[3]];
    let p = |v: u32| surface.vertices[v as usize];
    if (p(a) - p(c)).norm() <= (p(b) - p(d)).norm() {
        surface.triangles.push([a, b, c]);
        surface.triangles.push([a, c, d]);
    } else {
        surface.triangles.push([a, b, d]);
        surface.triangles.push([b, c, d]);
    }
}

/// Halvings of a grid edge while more than one primitive changes sign along it.
const MAX_HALVINGS: u32 = 60;

/// A grid edge's root: the point, the primitive whose surface holds it, and whether the leaves' values there
/// proved |F| < epsilon.
struct Root {
    point: Point3<f64>,
    leaf: usize,
    on_surface: bool,
}

/// The point where the solid's sign flips between `inside` (in) and `outside`, given with their leaves' values,
/// with the primitive whose surface holds it. While several primitives change sign along the segment it is
/// halved, keeping the half where the solid's sign flips; then the one primitive left is solved on the segment
/// by regula falsi (`regula_falsi`) until |f| is far below epsilon.
fn edge_root(
    leaves: &Leaves,
    inside: (Point3<f64>, &LeafValues),
    outside: (Point3<f64>, &LeafValues),
    epsilon: f64,
) -> Result<Root, MeshError> {
    let ((mut a, mut va), (mut b, mut vb)) = (
        (inside.0, Cow::Borrowed(inside.1)),
        (outside.0, Cow::Borrowed(outside.1)),
    );
    for _ in 0..MAX_HALVINGS {
        if let [leaf] = va.flipped(&vb)[..] {
            // The other primitives agree at both ends, but one of them may still be entered and
            // left in between (an edge clipping a box's corner): the root counts only where
            // they all keep their end signs; otherwise halve on.
            let (point, value) = solve_on_segment(
                leaves,
                leaf,
                (a, va.value(leaf)),
                (b, vb.value(leaf)),
                epsilon,
            )?;
            let mut at_root = leaves.values_except(&point, Some(leaf));
            if at_root.flipped(&va).iter().all(|&k| k == leaf) {
                at_root.insert(leaf, value);
                let on_surface = leaves.values_prove_on_surface(&point, &at_root, epsilon);
                return Ok(Root {
                    point,
                    leaf,
                    on_surface,
                });
            }
        }
        let m = nalgebra::center(&a, &b);
        let vm = Cow::Owned(leaves.values(&m));
        if leaves.classify(&vm) {
            (a, va) = (m, vm);
        } else {
            (b, vb) = (m, vm);
        }
    }
    // The segment has shrunk to rounding: several surfaces meet here. Keep the primitive that is
    // closest to zero; the tree's residual is checked on every vertex at the end.
    let m = nalgebra::center(&a, &b);
    let leaf = va
        .flipped(&vb)
        .into_iter()
        .min_by(|&i, &j| {
            let (fi, fj) = (leaves.leaves[i].value(&m), leaves.leaves[j].value(&m));
            fi.abs().total_cmp(&fj.abs())
        })
        .ok_or(MeshError::NoRoot { near: m })?;
    Ok(Root {
        point: m,
        leaf,
        on_surface: false,
    })
}

/// The root of one primitive's function along [a, b], where it changes sign.
/// The ends come with the leaf's values there where they are known (its box holds them). The root comes with
/// the leaf's value there.
fn solve_on_segment(
    leaves: &Leaves,
    leaf: usize,
    (a, fa): (Point3<f64>, Option<f64>),
    (b, fb): (Point3<f64>, Option<f64>),
    epsilon: f64,
) -> Result<(Point3<f64>, f64), MeshError> {
    let at = |t: f64| a + (b - a) * t;
    let f = |t: f64| leaves.leaves[leaf].value(&at(t));
    let ends = (fa.unwrap_or_else(|| f(0.0)), fb.unwrap_or_else(|| f(1.0)));
    regula_falsi::root(f, ends, 1e-3 * epsilon)
        .map(|(t, value)| (at(t), value))
        .ok_or(MeshError::NoRoot { near: a })
}
