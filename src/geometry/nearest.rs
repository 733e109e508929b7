//! Nearest-neighbour queries over a fixed set of points (an R*-tree from the rstar crate; it copes with the many
//! equal coordinates of planar profile stacks, where bucketed k-d trees can overflow).

use nalgebra::SVector;
use rstar::primitives::GeomWithData;
use rstar::RTree;

type Entry<const N: usize> = GeomWithData<[f64; N], usize>;

/// Index of points by position; queries return indices into the slice it was built from.
pub struct PointIndex<const N: usize> {
    tree: RTree<Entry<N>>,
}

impl<const N: usize> PointIndex<N> {
    pub fn new(points: &[SVector<f64, N>]) -> Self {
        let entries = points
            .iter()
            .enumerate()
            .map(|(i, p)| GeomWithData::new(array(p), i))
            .collect();
        Self {
            tree: RTree::bulk_load(entries),
        }
    }

    pub fn len(&self) -> usize {
        self.tree.size()
    }

    pub fn is_empty(&self) -> bool {
        self.tree.size() == 0
    }

    /// Index of the nearest point, `None` when the index is empty.
    pub fn nearest(&self, p: &SVector<f64, N>) -> Option<usize> {
        self.tree.nearest_neighbor(array(p)).map(|e| e.data)
    }

    /// Indices of the points by increasing distance from `p`.
    pub fn nearest_iter(&self, p: &SVector<f64, N>) -> impl Iterator<Item = usize> + '_ {
        self.tree.nearest_neighbor_iter(array(p)).map(|e| e.data)
    }
}

fn array<const N: usize>(p: &SVector<f64, N>) -> [f64; N] {
    std::array::from_fn(|k| p[k])
}
