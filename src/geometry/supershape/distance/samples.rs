//! Seeds for the nearest-point search: every surface sampled on a parametric grid mapped into the
//! model frame, the intersection curves found where a grid step crosses another surface, the
//! vertices where a grid cell or a box edge is crossed by two more, and the boxes' own edges and
//! corners; only the samples that lie on the solid's boundary are kept, in an
//! R-tree.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::Point3;
use rstar::{PointDistance, RTree, RTreeObject, AABB};

use super::lagrange::project;
use super::model::{Model, Primitive};

/// What part of the boundary a sample lies on: surfaces by their index in the model, an edge's pair
/// and a vertex's triple in increasing order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Feature {
    Surface(usize),
    Edge(usize, usize),
    Vertex(usize, usize, usize),
}

impl Feature {
    fn edge(a: usize, b: usize) -> Self {
        Feature::Edge(a.min(b), a.max(b))
    }

    fn vertex(a: usize, b: usize, c: usize) -> Self {
        let mut sorted = [a, b, c];
        sorted.sort_unstable();
        Feature::Vertex(sorted[0], sorted[1], sorted[2])
    }

    pub fn surfaces(&self) -> Vec<usize> {
        match *self {
            Feature::Surface(a) => vec![a],
            Feature::Edge(a, b) => vec![a, b],
            Feature::Vertex(a, b, c) => vec![a, b, c],
        }
    }
}

#[derive(Debug, Clone, Copy)]
pub(super) struct Sample {
    pub point: [f64; 3],
    pub feature: Feature,
}

impl RTreeObject for Sample {
    type Envelope = AABB<[f64; 3]>;

    fn envelope(&self) -> Self::Envelope {
        AABB::from_point(self.point)
    }
}

impl PointDistance for Sample {
    fn distance_2(&self, p: &[f64; 3]) -> f64 {
        (0..3).map(|i| (self.point[i] - p[i]).powi(2)).sum()
    }
}

/// The boundary samples and the largest gap (mm) between neighbouring samples of a grid: every
/// boundary point lies within about that distance of a sample of its own patch or edge.
pub(super) struct Samples {
    pub tree: RTree<Sample>,
    pub gap: f64,
}

/// A surface's samples on a rows x columns parametric grid, row-major, in the model frame.
struct Grid {
    points: Vec<Point3<f64>>,
    rows: usize,
    columns: usize,
    /// Whether the columns wrap around (a supershape's longitude).
    wraps: bool,
}

impl Grid {
    /// The four corners of every grid cell.
    fn cells(&self) -> impl Iterator<Item = [usize; 4]> + '_ {
        let (rows, columns) = (self.rows, self.columns);
        let across = if self.wraps { columns } else { columns - 1 };
        (0..rows.saturating_sub(1)).flat_map(move |i| {
            (0..across).map(move |j| {
                let next = (j + 1) % columns;
                [
                    i * columns + j,
                    i * columns + next,
                    (i + 1) * columns + j,
                    (i + 1) * columns + next,
                ]
            })
        })
    }

    /// The index pairs of grid neighbours along rows and columns.
    fn neighbours(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let (rows, columns) = (self.rows, self.columns);
        (0..rows).flat_map(move |i| {
            (0..columns).flat_map(move |j| {
                let here = i * columns + j;
                let across = if j + 1 < columns {
                    Some(here + 1)
                } else if self.wraps {
                    Some(i * columns)
                } else {
                    None
                };
                let down = (i + 1 < rows).then_some(here + columns);
                across
                    .into_iter()
                    .chain(down)
                    .map(move |there| (here, there))
            })
        })
    }
}

/// Samples every surface of `model` so that neighbouring samples are at most about `spacing` apart.
pub(super) fn sample(model: &Model, spacing: f64) -> Samples {
    let mut kept = Vec::new();
    let mut gap: f64 = 0.0;
    for s in 0..model.surfaces.len() {
        let grid = surface_grid(model, s, spacing);
        let on_boundary: Vec<bool> = grid
            .points
            .iter()
            .map(|x| model.on_boundary(x, &[s]))
            .collect();
        for (x, _) in grid.points.iter().zip(&on_boundary).filter(|(_, b)| **b) {
            kept.push(Sample {
                point: x.coords.into(),
                feature: Feature::Surface(s),
            });
        }
        for (a, b) in grid.neighbours() {
            if on_boundary[a] || on_boundary[b] {
                gap = gap.max((grid.points[a] - grid.points[b]).norm());
            }
            if on_boundary[a] != on_boundary[b] {
                kept.extend(edge_crossings(
                    model,
                    s,
                    &grid.points[a],
                    &grid.points[b],
                    spacing,
                ));
            }
        }
        for corners in grid.cells() {
            if corners.iter().any(|&c| on_boundary[c]) && !corners.iter().all(|&c| on_boundary[c]) {
                let points = corners.map(|c| grid.points[c]);
                kept.extend(triple_points(model, s, &points, spacing));
            }
        }
    }
    for l in 0..model.leaves.len() {
        if let Primitive::Cuboid(half) = model.leaves[l].primitive {
            let (edges, edge_gap) = box_edges(model, l, &half, spacing);
            kept.extend(edges);
            gap = gap.max(edge_gap);
        }
    }
    // A grid cell's diagonal is at most sqrt 2 of its longer side.
    Samples {
        tree: RTree::bulk_load(kept),
        gap: gap * std::f64::consts::SQRT_2,
    }
}

/// The points of the curves where `s` meets another surface between its neighbouring samples `a`
/// and `b`, when they lie on the solid's boundary.
fn edge_crossings(
    model: &Model,
    s: usize,
    a: &Point3<f64>,
    b: &Point3<f64>,
    spacing: f64,
) -> Vec<Sample> {
    let mut found = Vec::new();
    for t in 0..model.surfaces.len() {
        if t == s || model.surfaces[t].leaf == model.surfaces[s].leaf {
            continue;
        }
        let (ga, gb) = (model.value(t, a), model.value(t, b));
        if (ga > 0.0) == (gb > 0.0) {
            continue;
        }
        let seed = a + (b - a) * (ga / (ga - gb));
        if let Some(x) = project(model, [s, t], &seed, spacing) {
            if (x - seed).norm() < 2.0 * spacing && model.on_boundary(&x, &[s, t]) {
                found.push(Sample {
                    point: x.coords.into(),
                    feature: Feature::edge(s, t),
                });
            }
        }
    }
    found
}

/// The points where `s` meets two other surfaces inside the grid cell with corners `points`, when
/// they lie on the solid's boundary (vertices where three primitives meet).
fn triple_points(model: &Model, s: usize, points: &[Point3<f64>; 4], spacing: f64) -> Vec<Sample> {
    let crossing: Vec<usize> = (0..model.surfaces.len())
        .filter(|&t| model.surfaces[t].leaf != model.surfaces[s].leaf)
        .filter(|&t| {
            let inside = points.map(|x| model.value(t, &x) > 0.0);
            inside.iter().any(|&v| v) && !inside.iter().all(|&v| v)
        })
        .collect();
    let centre = Point3::from(
        points
            .iter()
            .map(|x| x.coords)
            .sum::<nalgebra::Vector3<f64>>()
            / 4.0,
    );
    let mut found = Vec::new();
    for (k, &t) in crossing.iter().enumerate() {
        for &u in &crossing[k + 1..] {
            found.extend(vertex_near(model, [s, t, u], &centre, spacing));
        }
    }
    found
}

/// The vertex of three surfaces near `seed`, if it is on the boundary.
fn vertex_near(
    model: &Model,
    surfaces: [usize; 3],
    seed: &Point3<f64>,
    spacing: f64,
) -> Option<Sample> {
    let x = project(model, surfaces, seed, spacing)?;
    ((x - seed).norm() < 2.0 * spacing && model.on_boundary(&x, &surfaces)).then(|| Sample {
        point: x.coords.into(),
        feature: Feature::vertex(surfaces[0], surfaces[1], surfaces[2]),
    })
}

/// Samples along a box's twelve edges, at its eight corners and where other surfaces cross its
/// edges, where they are on the boundary, with the largest spacing along an edge.
fn box_edges(model: &Model, l: usize, half: &[f64; 3], spacing: f64) -> (Vec<Sample>, f64) {
    let leaf = &model.leaves[l];
    let corner = |signs: [bool; 3]| {
        Point3::from(nalgebra::Vector3::from_fn(|i, _| {
            if signs[i] {
                half[i]
            } else {
                -half[i]
            }
        }))
    };
    let mut found = Vec::new();
    let mut gap: f64 = 0.0;
    for along in 0..3 {
        let (b, c) = ((along + 1) % 3, (along + 2) % 3);
        for (sb, sc) in [(false, false), (false, true), (true, false), (true, true)] {
            let faces = [model.face(l, b, sb), model.face(l, c, sc)];
            let mut start = [false; 3];
            start[b] = sb;
            start[c] = sc;
            let mut end = start;
            end[along] = true;
            let (from, to) = (leaf.to_model(&corner(start)), leaf.to_model(&corner(end)));
            let count = ((to - from).norm() / spacing).ceil().max(2.0) as usize;
            let mut previous: Option<Point3<f64>> = None;
            for k in 0..=count {
                let mut q = corner(start);
                q[along] = -half[along] + 2.0 * half[along] * k as f64 / count as f64;
                let x = leaf.to_model(&q);
                if let Some(before) = previous {
                    gap = gap.max((x - before).norm());
                    // Where another primitive's surface crosses the edge: a vertex.
                    for t in 0..model.surfaces.len() {
                        if model.surfaces[t].leaf == l {
                            continue;
                        }
                        let (gb, gx) = (model.value(t, &before), model.value(t, &x));
                        if (gb > 0.0) != (gx > 0.0) {
                            let seed = before + (x - before) * (gb / (gb - gx));
                            found.extend(vertex_near(
                                model,
                                [faces[0], faces[1], t],
                                &seed,
                                spacing,
                            ));
                        }
                    }
                }
                previous = Some(x);
                if model.on_boundary(&x, &faces) {
                    found.push(Sample {
                        point: x.coords.into(),
                        feature: Feature::edge(faces[0], faces[1]),
                    });
                }
            }
        }
    }
    for k in 0..8 {
        let signs = [k & 1 == 1, k & 2 == 2, k & 4 == 4];
        let faces = [0, 1, 2].map(|axis| model.face(l, axis, signs[axis]));
        let x = leaf.to_model(&corner(signs));
        if model.on_boundary(&x, &faces) {
            found.push(Sample {
                point: x.coords.into(),
                feature: Feature::Vertex(faces[0], faces[1], faces[2]),
            });
        }
    }
    (found, gap)
}

/// The parametric grid of surface `s`, with enough rows and columns for neighbours about `spacing`
/// apart (measured on a coarse grid first).
fn surface_grid(model: &Model, s: usize, spacing: f64) -> Grid {
    let surface = model.surfaces[s];
    let leaf = &model.leaves[surface.leaf];
    let (coarse_rows, coarse_columns) = (16, 32);
    let point = |u: f64, v: f64| -> Point3<f64> {
        match (leaf.primitive, surface.face) {
            // Rows run over the latitude (cell centres, off the poles), columns over the longitude.
            (Primitive::Supershape(shape), _) => {
                leaf.to_model(&shape.point(-PI + TAU * v, -FRAC_PI_2 + PI * u))
            }
            (Primitive::Cuboid(half), Some((axis, positive))) => {
                let mut q = Point3::origin();
                q[axis] = if positive { half[axis] } else { -half[axis] };
                let (b, c) = ((axis + 1) % 3, (axis + 2) % 3);
                q[b] = half[b] * (2.0 * u - 1.0);
                q[c] = half[c] * (2.0 * v - 1.0);
                leaf.to_model(&q)
            }
            (Primitive::Cuboid(_), None) => unreachable!("a box surface is always a face"),
        }
    };
    let wraps = surface.face.is_none();
    let build = |rows: usize, columns: usize| {
        let mut points = Vec::with_capacity(rows * columns);
        for i in 0..rows {
            for j in 0..columns {
                // A supershape's rows are cell centres in latitude (no sample on the singular
                // poles) and its columns wrap; a face's grid spans its closed rectangle.
                let (u, v) = if wraps {
                    ((i as f64 + 0.5) / rows as f64, j as f64 / columns as f64)
                } else {
                    (
                        i as f64 / (rows - 1) as f64,
                        j as f64 / (columns - 1) as f64,
                    )
                };
                points.push(point(u, v));
            }
        }
        Grid {
            points,
            rows,
            columns,
            wraps,
        }
    };
    let coarse = build(coarse_rows, coarse_columns);
    let (mut along_rows, mut along_columns): (f64, f64) = (0.0, 0.0);
    for (a, b) in coarse.neighbours() {
        let length = (coarse.points[a] - coarse.points[b]).norm();
        if b == a + coarse_columns {
            along_rows = along_rows.max(length);
        } else {
            along_columns = along_columns.max(length);
        }
    }
    let refined = |count: usize, length: f64| {
        ((count as f64 * length / spacing).ceil() as usize).clamp(count, 2048)
    };
    build(
        refined(coarse_rows, along_rows),
        refined(coarse_columns, along_columns),
    )
}
