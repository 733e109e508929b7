//! The cells of a regular grid that the solid's surface can cross, found from the primitives'
//! parametric forms (seed 000 section 4, initialisation: each primitive's parametric grid mapped
//! through the hierarchical deformations). The solid's surface is a subset of the union of its
//! primitives' surfaces, and the sign of the tree changes only across a primitive's surface, so a
//! cell that no primitive surface crosses holds no piece of the mesh: only the band around the
//! sampled surfaces is classified, not the whole box.

use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::atomic::{AtomicU64, Ordering};

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use super::super::csg::{Aabb, NodeKind};
use super::leaves::{Leaf, Leaves};

/// A regular grid of cubic cells over the solid's box, one cell of margin on every side.
pub(super) struct Grid {
    origin: Point3<f64>,
    cell: f64,
    /// Vertices along each axis.
    dims: [u64; 3],
}

impl Grid {
    pub fn new(bounds: &Aabb, cell: f64) -> Self {
        let origin = bounds.min - Vector3::repeat(cell);
        let span = bounds.max - bounds.min;
        let dims = [0, 1, 2].map(|axis| (span[axis] / cell).ceil() as u64 + 3);
        Self { origin, cell, dims }
    }

    pub fn vertex_count(&self) -> u64 {
        self.dims.iter().product()
    }

    pub fn vertex_ijk(&self, id: u64) -> [u64; 3] {
        ijk_of(self.dims, id)
    }

    pub fn vertex_id(&self, ijk: [u64; 3]) -> u64 {
        id_of(self.dims, ijk)
    }

    pub fn vertex_point(&self, ijk: [u64; 3]) -> Point3<f64> {
        self.origin + Vector3::new(ijk[0] as f64, ijk[1] as f64, ijk[2] as f64) * self.cell
    }

    /// The cell holding `p` (cells are named by their lowest vertex), if inside the grid.
    fn cell_of(&self, p: &Point3<f64>) -> Option<[u64; 3]> {
        let mut ijk = [0; 3];
        for axis in 0..3 {
            let t = ((p[axis] - self.origin[axis]) / self.cell).floor();
            if t.is_nan() || t < 0.0 || t >= (self.dims[axis] - 1) as f64 {
                return None;
            }
            ijk[axis] = t as u64;
        }
        Some(ijk)
    }

    /// Cells along each axis.
    fn cells_along(&self) -> [u64; 3] {
        self.dims.map(|d| d - 1)
    }

    fn cell_count(&self) -> u64 {
        self.cells_along().iter().product()
    }

    /// A cell's id: its place in the order z, then y, then x (that of its lowest vertex's id).
    fn cell_id(&self, ijk: [u64; 3]) -> u64 {
        id_of(self.cells_along(), ijk)
    }

    fn cell_ijk(&self, id: u64) -> [u64; 3] {
        ijk_of(self.cells_along(), id)
    }

    /// Whether a cell has all its vertices inside the grid.
    fn has_cell(&self, ijk: [i64; 3]) -> bool {
        (0..3).all(|axis| ijk[axis] >= 0 && (ijk[axis] as u64) + 1 < self.dims[axis])
    }
}

/// The id of (i, j, k) among `dims` points or cells: x fastest, then y, then z.
fn id_of(dims: [u64; 3], ijk: [u64; 3]) -> u64 {
    ijk[0] + dims[0] * (ijk[1] + dims[1] * ijk[2])
}

fn ijk_of(dims: [u64; 3], id: u64) -> [u64; 3] {
    [
        id % dims[0],
        (id / dims[0]) % dims[1],
        id / (dims[0] * dims[1]),
    ]
}

/// Base parametric grid before refinement: fine enough that a patch cannot fold over a whole lobe
/// of the shapes a part model uses (symmetry numbers up to 12 around theta).
const BASE_SUPERSHAPE: (usize, usize) = (48, 24);
const BASE_FACE: usize = 4;
/// Depth limit of the patch refinement: 2^14 subdivisions of a base patch along each parameter (a split
/// across one parameter counts as one level).
const MAX_DEPTH: u32 = 28;

/// Every cell within one cell of a parametric sample of a primitive's surface, in the order of their lowest
/// vertices' ids (z, then y, then x). A point less than a cell from a sample lies in a cell at most one step from
/// the sample's along each axis, a neighbour: every cell the surface crosses is in the band as long as every
/// surface point lies within a cell of a sample. Patches are split until their diagonals are at most half a
/// cell (see `split_patch`): a point of a flat patch then lies within 0.36 of a cell of a corner (0.71 of the
/// diagonal, for a patch shaped as a triangle at a pole), of a patch folded with an interior angle of 29 deg or
/// more (a box's edge, a star profile's tip) within a cell. Where the patch's parent was flat they stop at one
/// cell: a quarter of the samples where most of a part is walls and caps. The base patches of every primitive are
/// sampled on every core (one large primitive, the rim of a hub, would otherwise keep one core busy alone); the
/// cells are marked in bit sets over the grid.
pub(super) fn band(leaves: &Leaves, grid: &Grid) -> Vec<[u64; 3]> {
    let patches: Vec<(usize, BasePatch)> = leaves
        .leaves
        .iter()
        .enumerate()
        .flat_map(|(i, leaf)| base_patches(leaf).into_iter().map(move |patch| (i, patch)))
        .collect();
    let sampled = Bits::new(grid.cell_count());
    patches
        .par_iter()
        .for_each(|(i, patch)| sample_base_patch(&leaves.leaves[*i], patch, grid, &sampled));
    let band = Bits::new(grid.cell_count());
    let sampled: Vec<u64> = sampled.iter().collect();
    sampled.par_iter().for_each(|&id| {
        let c = grid.cell_ijk(id);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let n = [c[0] as i64 + dx, c[1] as i64 + dy, c[2] as i64 + dz];
                    if grid.has_cell(n) {
                        band.insert(grid.cell_id(n.map(|v| v as u64)));
                    }
                }
            }
        }
    });
    band.iter().map(|id| grid.cell_ijk(id)).collect()
}

/// A set of the grid's cells or vertices as bits, by id: one bit each where a hash set spent tens of bytes and
/// a hash, and its ids come out in order without a sort. Atomic, so that every core marks the one set: a set per
/// task would cost a copy of the whole grid's bits each.
pub(super) struct Bits(Vec<AtomicU64>);

impl Bits {
    pub fn new(count: u64) -> Self {
        Self((0..count.div_ceil(64)).map(|_| AtomicU64::new(0)).collect())
    }

    pub fn insert(&self, id: u64) {
        self.0[(id / 64) as usize].fetch_or(1 << (id % 64), Ordering::Relaxed);
    }

    pub fn contains(&self, id: u64) -> bool {
        self.0[(id / 64) as usize].load(Ordering::Relaxed) & (1 << (id % 64)) != 0
    }

    /// The ids in increasing order.
    pub fn iter(&self) -> impl Iterator<Item = u64> + '_ {
        self.0.iter().enumerate().flat_map(|(word, bits)| {
            let bits = bits.load(Ordering::Relaxed);
            (0..64)
                .filter(move |bit| bits & (1 << bit) != 0)
                .map(move |bit| word as u64 * 64 + bit)
        })
    }
}

/// One patch of a primitive's base parametric grid: a supershape's (theta, phi) rectangle, or a box face's
/// (u, v) rectangle on face `axis`/`side`.
enum BasePatch {
    Supershape([f64; 4]),
    Face {
        axis: usize,
        side: f64,
        rect: [f64; 4],
    },
}

fn base_patches(leaf: &Leaf) -> Vec<BasePatch> {
    match &leaf.node().kind {
        NodeKind::Supershape { .. } => {
            let (nt, np) = BASE_SUPERSHAPE;
            let (dt, dp) = (2.0 * PI / nt as f64, PI / np as f64);
            (0..nt)
                .flat_map(|i| (0..np).map(move |j| (i, j)))
                .map(|(i, j)| {
                    let (t0, p0) = (-PI + i as f64 * dt, -FRAC_PI_2 + j as f64 * dp);
                    BasePatch::Supershape([t0, t0 + dt, p0, p0 + dp])
                })
                .collect()
        }
        NodeKind::Cuboid { .. } => {
            let d = 2.0 / BASE_FACE as f64;
            let mut patches = Vec::new();
            for axis in 0..3 {
                for side in [-1.0, 1.0] {
                    for i in 0..BASE_FACE {
                        for j in 0..BASE_FACE {
                            let (u0, v0) = (-1.0 + i as f64 * d, -1.0 + j as f64 * d);
                            let rect = [u0, u0 + d, v0, v0 + d];
                            patches.push(BasePatch::Face { axis, side, rect });
                        }
                    }
                }
            }
            patches
        }
        NodeKind::Boolean { .. } => unreachable!("leaves are primitives"),
    }
}

/// Marks the cells holding a parametric sample of one base patch of a primitive's surface within its clip box.
fn sample_base_patch(leaf: &Leaf, patch: &BasePatch, grid: &Grid, cells: &Bits) {
    let clip = leaf.clip;
    let mut mark = |p: &Point3<f64>| {
        if clip.contains(p) {
            if let Some(c) = grid.cell_of(p) {
                cells.insert(grid.cell_id(c));
            }
        }
    };
    match (&leaf.node().kind, patch) {
        (NodeKind::Supershape { shape }, BasePatch::Supershape(rect)) => {
            let surface = |theta: f64, phi: f64| leaf.to_model(&shape.point(theta, phi));
            sample_patch(&surface, *rect, grid.cell, &mut mark);
        }
        (NodeKind::Cuboid { half_extents }, BasePatch::Face { axis, side, rect }) => {
            let surface = |u: f64, v: f64| face_point(leaf, half_extents, *axis, *side, u, v);
            sample_patch(&surface, *rect, grid.cell, &mut mark);
        }
        _ => unreachable!("a leaf's base patches are of its own kind"),
    }
}

/// A point of face `axis`/`side` of a box at face coordinates (u, v) in [-1, 1], in the model frame.
fn face_point(leaf: &Leaf, half: &[f64; 3], axis: usize, side: f64, u: f64, v: f64) -> Point3<f64> {
    let mut c = [0.0; 3];
    c[axis] = side * half[axis];
    c[(axis + 1) % 3] = u * half[(axis + 1) % 3];
    c[(axis + 2) % 3] = v * half[(axis + 2) % 3];
    leaf.to_model(&Point3::from(c))
}

/// Samples the patch [u0, u1] x [v0, v1] of a parametric surface, splitting it while its diagonals are longer
/// than a cell.
fn sample_patch(
    surface: &impl Fn(f64, f64) -> Point3<f64>,
    [u0, u1, v0, v1]: [f64; 4],
    cell: f64,
    mark: &mut impl FnMut(&Point3<f64>),
) {
    let corners = [
        surface(u0, v0),
        surface(u1, v0),
        surface(u1, v1),
        surface(u0, v1),
    ];
    split_patch(surface, [u0, u1, v0, v1], &corners, cell, false, 0, mark);
}

/// How far (in cells) the surface may stray from the bilinear patch through a patch's corners, at the points its
/// split computes, for its children to stop at a one-cell diagonal: a point of such a child then lies within
/// 0.71 + 0.1 of a cell of a corner, under the band's one-cell margin. A fold or tip inside the patch puts its
/// split points far off the bilinear patch (a third of its size and more at a right angle).
const FLAT: f64 = 0.1;

/// One patch with its corners (in the order (u0, v0), (u1, v0), (u1, v1), (u0, v1)) already on the
/// surface: marked, or split at its middle lines, the corners shared with the children. It is marked once its
/// diagonals are at most half a cell, or at most a cell where its parent was found flat (`flat_parent`: every
/// point the parent's split computed within `FLAT` cell of the parent's bilinear patch). A patch much longer
/// along one parameter than the other (a cylinder's wall patch is 8 mm round and under 1 mm high) is split
/// across that parameter only: split in four, its short side would be cut as often as its long one and sampled
/// many times more finely than the cell needs.
fn split_patch(
    surface: &impl Fn(f64, f64) -> Point3<f64>,
    [u0, u1, v0, v1]: [f64; 4],
    corners: &[Point3<f64>; 4],
    cell: f64,
    flat_parent: bool,
    depth: u32,
    mark: &mut impl FnMut(&Point3<f64>),
) {
    let spread = (corners[0] - corners[2])
        .norm()
        .max((corners[1] - corners[3]).norm());
    let enough = if flat_parent { cell } else { 0.5 * cell };
    if spread <= enough || depth == MAX_DEPTH {
        corners.iter().for_each(&mut *mark);
        return;
    }
    let (um, vm) = (0.5 * (u0 + u1), 0.5 * (v0 + v1));
    let [c00, c10, c11, c01] = *corners;
    let along_u = (c10 - c00).norm().max((c11 - c01).norm());
    let along_v = (c01 - c00).norm().max((c11 - c10).norm());
    // How far a split point lies from the bilinear patch: from the middle of its edge, or of the corners.
    let off = |p: Point3<f64>, ends: &[Point3<f64>]| {
        (p.coords - ends.iter().map(|e| e.coords).sum::<Vector3<f64>>() / ends.len() as f64).norm()
    };
    let (halves, quarters): ([Child; 2], [Child; 4]);
    let (children, stray): (&[Child], f64) = if along_u > 2.0 * along_v {
        let (bottom, top) = (surface(um, v0), surface(um, v1));
        let stray = off(bottom, &[c00, c10]).max(off(top, &[c01, c11]));
        halves = [
            ([u0, um, v0, v1], [c00, bottom, top, c01]),
            ([um, u1, v0, v1], [bottom, c10, c11, top]),
        ];
        (&halves, stray)
    } else if along_v > 2.0 * along_u {
        let (left, right) = (surface(u0, vm), surface(u1, vm));
        let stray = off(left, &[c00, c01]).max(off(right, &[c10, c11]));
        halves = [
            ([u0, u1, v0, vm], [c00, c10, right, left]),
            ([u0, u1, vm, v1], [left, right, c11, c01]),
        ];
        (&halves, stray)
    } else {
        let (bottom, right, top, left, middle) = (
            surface(um, v0),
            surface(u1, vm),
            surface(um, v1),
            surface(u0, vm),
            surface(um, vm),
        );
        quarters = [
            ([u0, um, v0, vm], [c00, bottom, middle, left]),
            ([um, u1, v0, vm], [bottom, c10, right, middle]),
            ([um, u1, vm, v1], [middle, right, c11, top]),
            ([u0, um, vm, v1], [left, middle, top, c01]),
        ];
        let stray = [
            off(bottom, &[c00, c10]),
            off(right, &[c10, c11]),
            off(top, &[c01, c11]),
            off(left, &[c00, c01]),
            off(middle, corners),
        ]
        .into_iter()
        .fold(0.0, f64::max);
        (&quarters, stray)
    };
    let flat = stray <= FLAT * cell;
    for (rect, corners) in children {
        split_patch(surface, *rect, corners, cell, flat, depth + 1, mark);
    }
}

/// A sub-patch: its parameter rectangle and its corners on the surface.
type Child = ([f64; 4], [Point3<f64>; 4]);

#[cfg(test)]
mod tests {
    use super::super::super::csg::{Node, Solid};
    use super::super::super::deform::Deformations;
    use super::super::super::formula::Superformula;
    use super::super::super::shape::Supershape;
    use super::*;

    #[test]
    fn every_point_of_stars_with_sharp_tips_lies_in_a_band_cell() {
        // Profiles with tips of about 19, 44 and 67 deg (m, n1, n2, n3), 10 mm across, at a 1 mm cell; and a
        // box-like shape whose edges are right angles. A patch that stopped at a one-cell diagonal across a tip
        // left the tip's cells out of the band.
        let profiles = [
            (7.0, 0.3, 1.0, 1.0),
            (5.0, 0.5, 1.0, 1.0),
            (3.0, 0.5, 1.0, 1.5),
            (4.0, 40.0, 40.0, 40.0),
        ];
        for (m, n1, n2, n3) in profiles {
            let shape = Supershape {
                r1: Superformula::new(m, n1, n2, n3, 1.0, 1.0).unwrap(),
                r2: Superformula::circle(),
                scale: [10.0; 3],
            };
            let solid = Solid::new(Node::supershape(shape, Deformations::default()));
            let leaves = Leaves::new(&solid);
            let grid = Grid::new(&solid.bounds(), 1.0);
            let band: Vec<u64> = band(&leaves, &grid)
                .into_iter()
                .map(|c| grid.cell_id(c))
                .collect();
            let (n_theta, n_phi) = (4000, 400);
            for i in 0..n_theta {
                let theta = -PI + 2.0 * PI * (i as f64 + 0.5) / n_theta as f64;
                for j in 0..=n_phi {
                    let phi = -FRAC_PI_2 + PI * j as f64 / n_phi as f64;
                    let p = shape.point(theta, phi);
                    let cell = grid.cell_of(&p).map(|c| grid.cell_id(c));
                    assert!(
                        cell.is_some_and(|id| band.binary_search(&id).is_ok()),
                        "profile {:?}: {p} (theta {theta}, phi {phi}) is in no band cell",
                        (m, n1, n2, n3)
                    );
                }
            }
        }
    }
}
