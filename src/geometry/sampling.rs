//! A sampled zero set: F evaluated on a regular grid over a box, the cells where F changes sign, their connected
//! components (a spurious branch near the data shows up as an extra component), and points projected onto the zero
//! set from those cells (seeds for the exact distance, so that Newton starts on the near side of a thin section).

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use super::implicit::Implicit;
use super::nearest::PointIndex;

/// A cell counts as sharply curved when the zero set turns by more than this (radians, roughly) across it.
const CURVED_CELL_BEND: f64 = 0.5;

/// An axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Aabb<const N: usize> {
    #[serde(with = "super::implicit::vector_as_array")]
    pub min: SVector<f64, N>,
    #[serde(with = "super::implicit::vector_as_array")]
    pub max: SVector<f64, N>,
}

impl<const N: usize> Aabb<N> {
    /// The bounding box of the points; `None` for no points.
    pub fn of_points(points: &[SVector<f64, N>]) -> Option<Self> {
        let first = points.first()?;
        Some(points.iter().fold(
            Self {
                min: *first,
                max: *first,
            },
            |b, p| Self {
                min: b.min.inf(p),
                max: b.max.sup(p),
            },
        ))
    }

    /// The box with the same centre and every side multiplied by `factor`.
    pub fn scaled(&self, factor: f64) -> Self {
        let center = (self.min + self.max) / 2.0;
        let half = (self.max - self.min) / 2.0 * factor;
        Self {
            min: center - half,
            max: center + half,
        }
    }

    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).norm()
    }
}

/// The zero set of F sampled over a box.
pub struct ZeroSetSamples<const N: usize> {
    /// The grid's samples first, then those added where the zero set bends sharply.
    points: Vec<SVector<f64, N>>,
    coarse: usize,
    index: PointIndex<N>,
    components: usize,
    /// The component of each grid sample (`points[..coarse]`).
    component_of: Vec<usize>,
    cell_size: f64,
}

impl<const N: usize> ZeroSetSamples<N> {
    /// Samples F over `bounds` with `cells` grid cells along the longest side (cubic cells).
    pub fn new(f: &impl Implicit<N>, bounds: &Aabb<N>, cells: usize) -> Self {
        Self::with_counts(f, bounds, Grid::cubic(bounds, cells).counts)
    }

    /// Samples F over `bounds` with `counts[k]` cells along axis k (cells may be elongated: a blade surface that
    /// varies slowly along the profile axis needs few cells along it).
    pub fn with_counts(f: &impl Implicit<N>, bounds: &Aabb<N>, counts: [usize; N]) -> Self {
        let extent = bounds.max - bounds.min;
        let cell =
            SVector::<f64, N>::from_fn(|k, _| extent[k].max(f64::MIN_POSITIVE) / counts[k] as f64);
        let cell_size = cell.max();
        let grid = Grid {
            origin: bounds.min,
            cell,
            counts,
        };
        let signs = grid.corner_signs(f);
        let crossing = grid.crossing_cells(&signs);
        let (components, cell_component) = grid.label_components(&crossing);
        let (mut points, component_of): (Vec<_>, Vec<usize>) = crossing
            .iter()
            .enumerate()
            .filter(|(_, &c)| c)
            .filter_map(|(index, _)| {
                project_to_zero_set(f, &grid.cell_center(index), 1.5 * cell.norm())
                    .map(|p| (p, cell_component[index]))
            })
            .unzip();
        let coarse = points.len();
        // Surfaces are not refined: a 3-D block at the resolution that helps is thousands of evaluations of a
        // polynomial with hundreds of terms per sample, which made a stack's distances take a minute.
        if N == 2 {
            points.extend(grid.refine_where_curved(f, &points));
        }
        let index = PointIndex::new(&points);
        Self {
            points,
            coarse,
            index,
            components,
            component_of,
            cell_size,
        }
    }

    /// The longest side of a grid cell: seeds are within about this of the zero set's nearest point.
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }

    /// Connected components of the zero set inside the box (cells joined through shared faces).
    pub fn components(&self) -> usize {
        self.components
    }

    /// Components that no point of `data` lies nearest to but that come within `near` of one: spurious branches
    /// beside the data, where a measured point off the part may find its foot on the wrong curve. A branch far
    /// out in the box, which no measured point reaches, is not counted: it changes no deviation.
    pub fn branches_beside(&self, data: &[SVector<f64, N>], near: f64) -> usize {
        let grid_samples = &self.points[..self.coarse];
        if grid_samples.is_empty() || data.is_empty() {
            return 0;
        }
        // A lone component is the one the data lie nearest to: no branch beside them.
        if self.components <= 1 {
            return 0;
        }
        let samples = PointIndex::new(grid_samples);
        // The components some point lies nearest to, the points in parallel.
        let carries = data
            .par_iter()
            .fold(
                || vec![false; self.components],
                |mut carries, p| {
                    if let Some(i) = samples.nearest(p) {
                        carries[self.component_of[i]] = true;
                    }
                    carries
                },
            )
            .reduce(
                || vec![false; self.components],
                |a, b| a.iter().zip(&b).map(|(a, b)| *a || *b).collect(),
            );
        if carries.iter().all(|&c| c) {
            return 0;
        }
        let data_index = PointIndex::new(data);
        // The samples in parallel too (a nearest search beside a dense scan is long); a minimum is the same in
        // any order.
        let closest = grid_samples
            .par_iter()
            .zip(&self.component_of)
            .filter(|(_, &component)| !carries[component])
            .fold(
                || vec![f64::INFINITY; self.components],
                |mut closest, (sample, &component)| {
                    if let Some(j) = data_index.nearest(sample) {
                        closest[component] = closest[component].min((data[j] - sample).norm());
                    }
                    closest
                },
            )
            .reduce(
                || vec![f64::INFINITY; self.components],
                |a, b| a.iter().zip(&b).map(|(a, b)| a.min(*b)).collect(),
            );
        closest.iter().filter(|&&d| d <= near).count()
    }

    pub fn points(&self) -> &[SVector<f64, N>] {
        &self.points
    }

    /// The nearest sample to `p`, and whether it lies where the zero set bends sharply within a grid cell (near
    /// a sharp edge, where the distance has several local minima close together).
    pub fn nearest(&self, p: &SVector<f64, N>) -> Option<(SVector<f64, N>, bool)> {
        self.index
            .nearest(p)
            .map(|i| (self.points[i], i >= self.coarse))
    }

    /// Samples by increasing distance from `p`.
    pub fn nearest_iter(&self, p: &SVector<f64, N>) -> impl Iterator<Item = SVector<f64, N>> + '_ {
        self.index.nearest_iter(p).map(|i| self.points[i])
    }
}

/// Moves `start` onto the zero set along the gradient (Newton's projection), giving up after `max_travel`.
pub fn project_to_zero_set<const N: usize>(
    f: &impl Implicit<N>,
    start: &SVector<f64, N>,
    max_travel: f64,
) -> Option<SVector<f64, N>> {
    let mut x = *start;
    for _ in 0..30 {
        let (v, g) = f.value_gradient(&x);
        let g2 = g.norm_squared();
        if g2 == 0.0 || !g2.is_finite() {
            return None;
        }
        let step = g * (v / g2);
        x -= step;
        if (x - start).norm() > max_travel {
            return None;
        }
        if step.norm() <= 1e-12 * (1.0 + x.norm()) {
            return Some(x);
        }
    }
    None
}

struct Grid<const N: usize> {
    origin: SVector<f64, N>,
    cell: SVector<f64, N>,
    counts: [usize; N],
}

impl<const N: usize> Grid<N> {
    /// A grid of cubic cells with `cells` along the longest side of `bounds`.
    fn cubic(bounds: &Aabb<N>, cells: usize) -> Self {
        let extent = bounds.max - bounds.min;
        let side = extent.max() / cells as f64;
        Self {
            origin: bounds.min,
            cell: SVector::repeat(side),
            counts: std::array::from_fn(|k| ((extent[k] / side).ceil() as usize).max(1)),
        }
    }

    fn corner_counts(&self) -> [usize; N] {
        std::array::from_fn(|k| self.counts[k] + 1)
    }

    fn corner_signs(&self, f: &impl Implicit<N>) -> Vec<bool> {
        let counts = self.corner_counts();
        let total: usize = counts.iter().product();
        (0..total)
            .into_par_iter()
            .map(|i| {
                let idx = unflatten(i, &counts);
                let p =
                    self.origin + SVector::<f64, N>::from_fn(|k, _| idx[k] as f64 * self.cell[k]);
                f.value(&p) > 0.0
            })
            .collect()
    }

    /// Extra samples where the zero set bends sharply within a cell (the rounded trailing edge of a blade model
    /// turns within microns): there one sample per cell cannot seed Newton next to the right local minimum of
    /// the distance, so the block of cells around such a sample is sampled again on a finer grid. A sharp bend
    /// shows as high curvature at a sample, or, when the bend is narrower than a cell and falls between samples,
    /// as neighbouring samples whose normals differ widely.
    fn refine_where_curved(
        &self,
        f: &impl Implicit<N>,
        coarse: &[SVector<f64, N>],
    ) -> Vec<SVector<f64, N>> {
        let side = self.cell.max();
        let normals: Vec<SVector<f64, N>> = coarse
            .iter()
            .map(|x| f.value_gradient(x).1.normalize())
            .collect();
        let index = PointIndex::new(coarse);
        let neighbourhood = 2.0 * self.cell.norm();
        let mut refined_blocks = std::collections::HashSet::new();
        let mut extra = Vec::new();
        for (i, x) in coarse.iter().enumerate() {
            let (_, g, h) = f.value_gradient_hessian(x);
            let tangent_projector =
                SMatrix::<f64, N, N>::identity() - normals[i] * normals[i].transpose();
            // Frobenius norm of the tangential Hessian over |grad F|: an upper bound of the largest curvature.
            let curvature = (tangent_projector * h * tangent_projector).norm() / g.norm();
            let turn_to_neighbour = index
                .nearest_iter(x)
                .skip(1)
                .take(2 * N)
                .take_while(|&j| (coarse[j] - x).norm() <= neighbourhood)
                .map(|j| normals[i].dot(&normals[j]).clamp(-1.0, 1.0).acos())
                .fold(0.0, f64::max);
            let bend = (curvature * side).max(turn_to_neighbour);
            // NaN (a vanishing gradient) counts as not curved.
            if bend.is_nan() || bend <= CURVED_CELL_BEND {
                continue;
            }
            let home: [usize; N] = std::array::from_fn(|k| {
                (((x[k] - self.origin[k]) / self.cell[k]).floor().max(0.0) as usize)
                    .min(self.counts[k] - 1)
            });
            if !refined_blocks.insert(home) {
                continue;
            }
            let divisions = ((bend * 8.0).ceil() as usize).clamp(2, if N == 2 { 64 } else { 8 });
            let lo: [usize; N] = std::array::from_fn(|k| home[k].saturating_sub(1));
            let hi: [usize; N] = std::array::from_fn(|k| (home[k] + 2).min(self.counts[k]));
            let fine = Grid {
                origin: self.origin
                    + SVector::<f64, N>::from_fn(|k, _| lo[k] as f64 * self.cell[k]),
                cell: self.cell / divisions as f64,
                counts: std::array::from_fn(|k| (hi[k] - lo[k]) * divisions),
            };
            let crossing = fine.crossing_cells(&fine.corner_signs(f));
            extra.extend(
                crossing
                    .iter()
                    .enumerate()
                    .filter(|(_, &c)| c)
                    .filter_map(|(i, _)| {
                        project_to_zero_set(f, &fine.cell_center(i), 1.5 * fine.cell.norm())
                    }),
            );
        }
        extra
    }

    fn cell_count(&self) -> usize {
        self.counts.iter().product()
    }

    fn crossing_cells(&self, signs: &[bool]) -> Vec<bool> {
        let corners = self.corner_counts();
        (0..self.cell_count())
            .into_par_iter()
            .map(|cell| {
                let idx = unflatten(cell, &self.counts);
                let mut seen = [false; 2];
                for corner in 0..(1usize << N) {
                    let c: [usize; N] = std::array::from_fn(|k| idx[k] + ((corner >> k) & 1));
                    seen[signs[flatten(&c, &corners)] as usize] = true;
                }
                seen[0] && seen[1]
            })
            .collect()
    }

    /// The number of connected components among the crossing cells, and each cell's component (0 for cells
    /// that do not cross).
    fn label_components(&self, crossing: &[bool]) -> (usize, Vec<usize>) {
        let mut sets = DisjointSets::new(crossing.len());
        for cell in (0..crossing.len()).filter(|&c| crossing[c]) {
            let idx = unflatten(cell, &self.counts);
            for k in 0..N {
                if idx[k] + 1 < self.counts[k] {
                    let mut next = idx;
                    next[k] += 1;
                    let other = flatten(&next, &self.counts);
                    if crossing[other] {
                        sets.union(cell, other);
                    }
                }
            }
        }
        let mut label_of_root = std::collections::HashMap::new();
        let labels = (0..crossing.len())
            .map(|c| {
                if !crossing[c] {
                    return 0;
                }
                let root = sets.find(c);
                let next = label_of_root.len();
                *label_of_root.entry(root).or_insert(next)
            })
            .collect();
        (label_of_root.len(), labels)
    }

    fn cell_center(&self, cell: usize) -> SVector<f64, N> {
        let idx = unflatten(cell, &self.counts);
        self.origin + SVector::<f64, N>::from_fn(|k, _| (idx[k] as f64 + 0.5) * self.cell[k])
    }
}

fn unflatten<const N: usize>(mut i: usize, counts: &[usize; N]) -> [usize; N] {
    std::array::from_fn(|k| {
        let v = i % counts[k];
        i /= counts[k];
        v
    })
}

fn flatten<const N: usize>(idx: &[usize; N], counts: &[usize; N]) -> usize {
    (0..N).rev().fold(0, |acc, k| acc * counts[k] + idx[k])
}

/// Union-find with path halving.
struct DisjointSets {
    parent: Vec<usize>,
}

impl DisjointSets {
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
        }
    }

    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            self.parent[x] = self.parent[self.parent[x]];
            x = self.parent[x];
        }
        x
    }

    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra] = rb;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::poly::Poly;
    use nalgebra::Vector2;

    #[test]
    fn two_circles_are_two_components_samples_lie_on_them_and_a_branch_beside_the_data_counts() {
        // (x^2 + y^2 - 1) * ((x - 3)^2 + y^2 - 1) has two unit circles centred at 0 and 3.
        // Expanded: product of (x^2 + y^2 - 1) and (x^2 - 6x + 8 + y^2).
        let a = Poly::<2>::new(2, vec![-1.0, 0.0, 0.0, 1.0, 0.0, 1.0]);
        let b = Poly::<2>::new(2, vec![8.0, -6.0, 0.0, 1.0, 0.0, 1.0]);
        struct Product(Poly<2>, Poly<2>);
        impl Implicit<2> for Product {
            fn value_gradient(&self, p: &Vector2<f64>) -> (f64, Vector2<f64>) {
                let (va, ga) = self.0.value_gradient(p);
                let (vb, gb) = self.1.value_gradient(p);
                (va * vb, ga * vb + gb * va)
            }
            fn value_gradient_hessian(
                &self,
                p: &Vector2<f64>,
            ) -> (f64, Vector2<f64>, nalgebra::Matrix2<f64>) {
                let (va, ga, ha) = self.0.value_gradient_hessian(p);
                let (vb, gb, hb) = self.1.value_gradient_hessian(p);
                (
                    va * vb,
                    ga * vb + gb * va,
                    ha * vb + hb * va + ga * gb.transpose() + gb * ga.transpose(),
                )
            }
        }
        let f = Product(a, b);
        let bounds = Aabb {
            min: Vector2::new(-2.0, -2.0),
            max: Vector2::new(5.0, 2.0),
        };
        let samples = ZeroSetSamples::new(&f, &bounds, 140);
        assert_eq!(samples.components(), 2);
        assert!(samples.points().len() > 200);
        for p in samples.points() {
            let r = p.norm().min((p - Vector2::new(3.0, 0.0)).norm());
            assert!((r - 1.0).abs() < 1e-9, "sample {p} is off both circles");
        }
        let near = samples
            .nearest_iter(&Vector2::new(3.0, 1.5))
            .next()
            .unwrap();
        assert!((near - Vector2::new(3.0, 1.0)).norm() < 0.06);
        // Data on the first circle: the second, 1 away at its nearest, is a branch beside them within 1.5 and
        // not within 0.5; data on both circles leave no branch beside them; one circle alone has none.
        let on = |centre: f64| {
            (0..500).map(move |k| {
                let t = k as f64 / 500.0 * std::f64::consts::TAU;
                Vector2::new(centre + t.cos(), t.sin())
            })
        };
        let first: Vec<Vector2<f64>> = on(0.0).collect();
        assert_eq!(samples.branches_beside(&first, 1.5), 1);
        assert_eq!(samples.branches_beside(&first, 0.5), 0);
        let both: Vec<Vector2<f64>> = on(0.0).chain(on(3.0)).collect();
        assert_eq!(samples.branches_beside(&both, 1.5), 0);
        let one = ZeroSetSamples::new(&f.0, &bounds, 140);
        assert_eq!(one.components(), 1);
        assert_eq!(one.branches_beside(&first, 10.0), 0);
    }
}
