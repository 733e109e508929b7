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

use foldhash::{HashMap, HashMapExt};

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::band::{Bits, Grid};
use super::leaves::Leaves;
use super::regula_falsi;
use super::MeshError;

/// A triangulated surface with, for each vertex, the primitives whose surfaces hold it (the
/// second equal to the first unless the vertex lies on an intersection curve).
pub(super) struct Surface {
    pub vertices: Vec<Point3<f64>>,
    pub on: Vec<(usize, usize)>,
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
    // The grid edges whose roots are wanted, (inside end, outside end), in vertex order.
    let mut crossings: Vec<(Point3<f64>, Point3<f64>)> = Vec::new();
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
                        crossings
                            .push((grid.vertex_point(corners[i]), grid.vertex_point(corners[o])));
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
    // Solved on every core, then taken in order, so that a failure reported is the first edge's.
    let solved: Vec<Result<(Point3<f64>, usize), MeshError>> = crossings
        .par_iter()
        .map(|(inside, outside)| edge_root(leaves, *inside, *outside, epsilon))
        .collect();
    let solved: Vec<(Point3<f64>, usize)> = solved.into_iter().collect::<Result<_, _>>()?;
    let mut surface = Surface {
        vertices: solved.iter().map(|(point, _)| *point).collect(),
        on: solved.iter().map(|(_, leaf)| (*leaf, *leaf)).collect(),
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

/// The point where the solid's sign flips between `inside` (in) and `outside`, with the primitive
/// whose surface holds it. While several primitives change sign along the segment it is halved,
/// keeping the half where the solid's sign flips; then the one primitive left is solved on the
/// segment by regula falsi (`regula_falsi`) until |f| is far below epsilon.
fn edge_root(
    leaves: &Leaves,
    inside: Point3<f64>,
    outside: Point3<f64>,
    epsilon: f64,
) -> Result<(Point3<f64>, usize), MeshError> {
    let (mut a, mut b) = (inside, outside);
    let (mut sa, mut sb) = (leaves.signs(&a), leaves.signs(&b));
    for _ in 0..MAX_HALVINGS {
        let flipped: Vec<usize> = (0..sa.len()).filter(|&i| sa[i] != sb[i]).collect();
        if let [leaf] = flipped[..] {
            // The other primitives agree at both ends, but one of them may still be entered and
            // left in between (an edge clipping a box's corner): the root counts only where
            // they all keep their end signs; otherwise halve on.
            let root = solve_on_segment(leaves, leaf, a, b, epsilon)?;
            let at_root = leaves.signs(&root);
            if (0..sa.len()).all(|k| k == leaf || at_root[k] == sa[k]) {
                return Ok((root, leaf));
            }
        }
        let m = nalgebra::center(&a, &b);
        let sm = leaves.signs(&m);
        if leaves.classify(&sm) {
            (a, sa) = (m, sm);
        } else {
            (b, sb) = (m, sm);
        }
    }
    // The segment has shrunk to rounding: several surfaces meet here. Keep the primitive that is
    // closest to zero; the tree's residual is checked on every vertex at the end.
    let m = nalgebra::center(&a, &b);
    let leaf = (0..sa.len())
        .filter(|&i| sa[i] != sb[i])
        .min_by(|&i, &j| {
            let (fi, fj) = (leaves.leaves[i].value(&m), leaves.leaves[j].value(&m));
            fi.abs().total_cmp(&fj.abs())
        })
        .ok_or(MeshError::NoRoot { near: m })?;
    Ok((m, leaf))
}

/// The root of one primitive's function along [a, b], where it changes sign.
fn solve_on_segment(
    leaves: &Leaves,
    leaf: usize,
    a: Point3<f64>,
    b: Point3<f64>,
    epsilon: f64,
) -> Result<Point3<f64>, MeshError> {
    let at = |t: f64| a + (b - a) * t;
    let f = |t: f64| leaves.leaves[leaf].value(&at(t));
    regula_falsi::root(f, (f(0.0), f(1.0)), 1e-3 * epsilon)
        .map(at)
        .ok_or(MeshError::NoRoot { near: a })
}
