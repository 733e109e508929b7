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

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::band::{Bits, Grid};
use super::keys::SortedKeys;
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

/// The surface in the band's cells, found on every core: the corners' signs, each crossed cell's pieces of
/// surface (by the grid edges they cross), the edges' roots. The crossed edges are numbered in the order of
/// their keys and the pieces kept in the order of the cells, so the mesh (or the error) is the same whatever the
/// number of cores.
pub(super) fn march(
    leaves: &Leaves,
    grid: &Grid,
    cells: &[[u64; 3]],
    epsilon: f64,
) -> Result<Surface, MeshError> {
    // The cells' corners as bits over the grid's vertices (their ids in order, no sort), their signs as bits.
    let corners = Bits::new(grid.vertex_count());
    cells.par_iter().for_each(|cell| {
        for c in 0..8 {
            corners.insert(grid.vertex_id(corner(cell, c)));
        }
    });
    let ids: Vec<u64> = corners.iter().collect();
    let signs = Bits::new(grid.vertex_count());
    ids.par_iter()
        .filter(|&&id| leaves.inside(&grid.vertex_point(grid.vertex_ijk(id))))
        .for_each(|&id| signs.insert(id));
    let pieces: Vec<Piece> = cells
        .par_iter()
        .flat_map_iter(|cell| cell_pieces(grid, &signs, cell).into_iter().flatten())
        .collect();
    let edges = SortedKeys::new(pieces.par_iter().flat_map_iter(Piece::edges).collect());
    // Each crossed edge as (inside end, outside end) by vertex id.
    let crossings: Vec<(u64, u64)> = edges
        .keys()
        .par_iter()
        .map(|&key| {
            let (low, high) = edge_ends(grid, key);
            if signs.contains(low) {
                (low, high)
            } else {
                (high, low)
            }
        })
        .collect();
    // The leaves' values at each end, taken once per grid vertex: a vertex ends four crossing edges on average.
    let ends = SortedKeys::new(
        crossings
            .par_iter()
            .flat_map_iter(|&(i, o)| [i, o])
            .collect(),
    );
    let end_values: Vec<(Point3<f64>, LeafValues)> = ends
        .keys()
        .par_iter()
        .map(|&id| {
            let p = grid.vertex_point(grid.vertex_ijk(id));
            (p, leaves.values(&p))
        })
        .collect();
    let end = |id: u64| {
        let k = ends.position(id).expect("every crossing's end is listed");
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
    let vertex_of = |key: u64| edges.position(key).expect("every crossed edge is listed") as u32;
    let loops: Vec<[u32; 4]> = pieces
        .par_iter()
        .map(|piece| {
            std::array::from_fn(|k| {
                if k < piece.count {
                    vertex_of(piece.edges[k])
                } else {
                    0
                }
            })
        })
        .collect();
    for (loop_ids, piece) in loops.iter().zip(&pieces) {
        push_polygon(&mut surface, &loop_ids[..piece.count]);
    }
    Ok(surface)
}

/// Corner c of a cell.
fn corner(cell: &[u64; 3], c: usize) -> [u64; 3] {
    [0, 1, 2].map(|axis| cell[axis] + corner_offset(c)[axis])
}

/// A grid edge of the Kuhn triangulation by one number: its lower end's vertex id times 8 plus the set of axes
/// along which its upper end is one step further (1 to 7: the cube's edges, face diagonals and main diagonal).
/// Both ends of every edge of a Kuhn tetrahedron are so ordered, as its corners lie on a monotone path.
fn edge_key(grid: &Grid, cell: &[u64; 3], low: usize, high: usize) -> u64 {
    debug_assert!(low & high == low && low != high);
    grid.vertex_id(corner(cell, low)) * 8 + (high ^ low) as u64
}

/// The vertex ids of an edge's lower and upper ends.
fn edge_ends(grid: &Grid, key: u64) -> (u64, u64) {
    let low = key / 8;
    let ijk = grid.vertex_ijk(low);
    (low, grid.vertex_id(corner(&ijk, (key % 8) as usize)))
}

/// The piece of surface in one tetrahedron: the grid edges it crosses, by key, in cyclic order (a triangle round
/// a lone corner, or the quadrilateral between two inside and two outside corners), turned so that its normal
/// points from inside to outside.
struct Piece {
    edges: [u64; 4],
    count: usize,
}

impl Piece {
    fn edges(&self) -> impl Iterator<Item = u64> + '_ {
        self.edges[..self.count].iter().copied()
    }
}

/// The pieces of surface in one cell's six tetrahedra: none unless its corners' signs differ.
fn cell_pieces(grid: &Grid, signs: &Bits, cell: &[u64; 3]) -> [Option<Piece>; 6] {
    let inside: [bool; 8] =
        std::array::from_fn(|c| signs.contains(grid.vertex_id(corner(cell, c))));
    if inside.iter().all(|&s| s == inside[0]) {
        return Default::default();
    }
    TETRAHEDRA.map(|tet| {
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
            return None;
        }
        let (ins, outs) = (&ins[..n_in], &outs[..n_out]);
        let (quad, triangle);
        let corners: &[(usize, usize)] = match (n_in, n_out) {
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
        let normal =
            (mid(corners[1]) - mid(corners[0])).cross(&(mid(corners[2]) - mid(corners[0])));
        let mut edges = [0; 4];
        for (k, &(i, o)) in corners.iter().enumerate() {
            edges[k] = edge_key(grid, cell, i.min(o), i.max(o));
        }
        if normal.dot(&outward) < 0.0 {
            edges[..corners.len()].reverse();
        }
        Some(Piece {
            edges,
            count: corners.len(),
        })
    })
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
    // The ends exactly (a + (b - a) need not round to b): a root at an end carries that end's value.
    let at = |t: f64| if t == 1.0 { b } else { a + (b - a) * t };
    let f = |t: f64| leaves.leaves[leaf].value(&at(t));
    let ends = (fa.unwrap_or_else(|| f(0.0)), fb.unwrap_or_else(|| f(1.0)));
    regula_falsi::root(f, ends, 1e-3 * epsilon)
        .map(|(t, value)| (at(t), value))
        .ok_or(MeshError::NoRoot { near: a })
}

#[cfg(test)]
mod tests {
    use super::super::super::csg::Aabb;
    use super::*;
    use std::collections::HashMap;

    #[test]
    fn a_root_marked_proved_is_proved_by_the_leaves_near_it_and_lies_on_the_tree() {
        // The brake hub at a 2 mm cell: the final check skips the roots proved where they were made, from the
        // values the root's own check took (its leaf's from the solver, the others' evaluated). The same proof
        // taken afresh must hold for each, and the tree's own value must be within epsilon.
        let solid = super::super::hub::brake_hub();
        let leaves = Leaves::new(&solid);
        let grid = Grid::new(&solid.bounds(), 2.0);
        let cells = super::super::band::band(&leaves, &grid);
        let epsilon = 1e-6;
        let surface = march(&leaves, &grid, &cells, epsilon).unwrap();
        let proved: Vec<&Point3<f64>> = surface
            .vertices
            .iter()
            .zip(&surface.checked)
            .filter(|(_, &checked)| checked)
            .map(|(v, _)| v)
            .collect();
        // Nearly all of them: a root where two surfaces meet to rounding is left to the final check.
        assert!(
            proved.len() * 100 >= surface.vertices.len() * 99,
            "{} of {} proved",
            proved.len(),
            surface.vertices.len()
        );
        for v in proved {
            assert!(leaves.proves_on_surface(v, epsilon), "{v}");
            assert!(solid.value(v).abs() < epsilon, "{v}");
        }
    }

    #[test]
    fn edge_keys_name_each_grid_edge_once_and_give_back_its_ends() {
        let grid = Grid::new(
            &Aabb {
                min: Point3::origin(),
                max: Point3::new(3.0, 2.0, 4.0),
            },
            1.0,
        );
        // Every tetrahedron edge of every cell, from both of its cells' (or more) views.
        let mut by_key: HashMap<u64, (u64, u64)> = HashMap::new();
        for cell in (0..4).flat_map(|i| (0..3).flat_map(move |j| (0..5).map(move |k| [i, j, k]))) {
            for tet in TETRAHEDRA {
                for (x, &a) in tet.iter().enumerate() {
                    for &b in &tet[x + 1..] {
                        let key = edge_key(&grid, &cell, a, b);
                        let ends = (
                            grid.vertex_id(corner(&cell, a)),
                            grid.vertex_id(corner(&cell, b)),
                        );
                        assert_eq!(edge_ends(&grid, key), ends);
                        assert_eq!(*by_key.entry(key).or_insert(ends), ends);
                    }
                }
            }
        }
        // One key per edge: as many keys as distinct pairs of ends.
        let mut pairs: Vec<(u64, u64)> = by_key.values().copied().collect();
        pairs.sort_unstable();
        pairs.dedup();
        assert_eq!(pairs.len(), by_key.len());
        // Kuhn's tetrahedra use 19 of a cube's 28 segments (its 12 edges, one diagonal of each face, one main
        // diagonal): from each vertex of the 5 x 4 x 6 lattice of these 4 x 3 x 5 cells, the 7 to it + mask that
        // stay in the lattice.
        let mut expected = 0;
        for mask in 1..8u64 {
            let [dx, dy, dz] = [mask & 1, mask >> 1 & 1, mask >> 2 & 1];
            expected += (5 - dx) * (4 - dy) * (6 - dz);
        }
        assert_eq!(by_key.len() as u64, expected);
    }
}
