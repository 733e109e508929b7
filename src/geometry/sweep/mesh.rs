//! A triangle mesh as a part model: exact point-triangle and segment-triangle distances over an R*-tree of the
//! triangles' bounding boxes (nearest-neighbour and best-first searches), signed by angle-weighted pseudo-normals (Baerentsen and Aanaes, "Signed distance
//! computation using the angle weighted pseudonormal", 2005) when the mesh is closed.
//!
//! The mesh approximates the true part: the chord tolerance (the largest distance between the tessellation and the
//! surface it stands for, as the CAD exporter was asked for) is subtracted from every distance, so that what this
//! model reports is a lower bound of the distance to the true surface too.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

use nalgebra::{Point3, Vector3};
use rstar::{PointDistance, RTree, RTreeNode, RTreeObject, AABB};

use super::closest::{closest_on_triangle, closest_segment_triangle, TriangleFeature};
use super::part::{PartDistance, Proximity};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("the mesh has no triangles")]
    Empty,
    #[error("triangle {0} refers to vertex {1}, but the mesh has {2} vertices")]
    BadIndex(usize, usize, usize),
    #[error("the closed mesh encloses a negative volume ({0} mm^3): its triangles face inwards; reverse them")]
    InsideOut(f64),
    #[error("the chord tolerance must be finite and non-negative, got {0} mm")]
    BadChordTolerance(f64),
}

/// One triangle in the index, with its corners copied for cache-friendly distance evaluations.
struct IndexedTriangle {
    index: usize,
    corners: [Point3<f64>; 3],
}

impl RTreeObject for IndexedTriangle {
    type Envelope = AABB<[f64; 3]>;

    fn envelope(&self) -> Self::Envelope {
        let [a, b, c] = &self.corners;
        let lo = a.inf(b).inf(c);
        let hi = a.sup(b).sup(c);
        AABB::from_corners(lo.coords.into(), hi.coords.into())
    }
}

impl PointDistance for IndexedTriangle {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        let p = Point3::from(*point);
        let [a, b, c] = &self.corners;
        (closest_on_triangle(&p, a, b, c).0 - p).norm_squared()
    }
}

/// Lower bounds of the distance from a segment to a box: the gap between the box and the segment's own box, and
/// the distance from the box to the segment's midpoint less half its length; the larger of the two.
struct SegmentBounds {
    lo: Point3<f64>,
    hi: Point3<f64>,
    mid: [f64; 3],
    half_length: f64,
}

impl SegmentBounds {
    fn new(a: &Point3<f64>, b: &Point3<f64>) -> Self {
        Self {
            lo: a.inf(b),
            hi: a.sup(b),
            mid: nalgebra::center(a, b).coords.into(),
            half_length: 0.5 * (b - a).norm(),
        }
    }

    fn lower_bound(&self, envelope: &AABB<[f64; 3]>) -> f64 {
        let (lo, hi) = (envelope.lower(), envelope.upper());
        let gap: f64 = (0..3)
            .map(|k| {
                (lo[k] - self.hi[k])
                    .max(self.lo[k] - hi[k])
                    .max(0.0)
                    .powi(2)
            })
            .sum();
        let from_mid = envelope.distance_2(&self.mid).sqrt() - self.half_length;
        gap.sqrt().max(from_mid)
    }
}

/// A node of the search queue, ordered so that the smallest bound comes out first.
struct Candidate<'a> {
    bound: f64,
    node: &'a RTreeNode<IndexedTriangle>,
}

impl PartialEq for Candidate<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.bound.total_cmp(&other.bound) == Ordering::Equal
    }
}

impl Eq for Candidate<'_> {}

impl PartialOrd for Candidate<'_> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Candidate<'_> {
    fn cmp(&self, other: &Self) -> Ordering {
        other.bound.total_cmp(&self.bound)
    }
}

/// A triangle mesh part (coordinates in mm, in the frame the motions are planned in).
pub struct MeshPart {
    vertices: Vec<Point3<f64>>,
    triangles: Vec<[usize; 3]>,
    tree: RTree<IndexedTriangle>,
    /// Pseudo-normals for the sign; `None` when the mesh is not closed (then distances are unsigned).
    pseudo_normals: Option<PseudoNormals>,
    chord_tolerance_mm: f64,
}

struct PseudoNormals {
    face: Vec<Vector3<f64>>,
    edge: HashMap<(usize, usize), Vector3<f64>>,
    vertex: Vec<Vector3<f64>>,
}

fn edge_key(i: usize, j: usize) -> (usize, usize) {
    (i.min(j), i.max(j))
}

impl PseudoNormals {
    /// Pseudo-normals of a closed, consistently oriented mesh (every edge shared by exactly two triangles);
    /// `None` otherwise. Triangles with zero area contribute nothing.
    fn of_closed(vertices: &[Point3<f64>], triangles: &[[usize; 3]]) -> Option<Self> {
        let mut edge: HashMap<(usize, usize), (Vector3<f64>, usize)> = HashMap::new();
        let mut vertex = vec![Vector3::zeros(); vertices.len()];
        let mut face = Vec::with_capacity(triangles.len());
        for tri in triangles {
            let p = tri.map(|i| vertices[i]);
            let n = (p[1] - p[0])
                .cross(&(p[2] - p[0]))
                .try_normalize(0.0)
                .unwrap_or_default();
            face.push(n);
            for k in 0..3 {
                let e = edge.entry(edge_key(tri[k], tri[(k + 1) % 3])).or_default();
                e.0 += n;
                e.1 += 1;
                let u = p[(k + 1) % 3] - p[k];
                let v = p[(k + 2) % 3] - p[k];
                vertex[tri[k]] += n * u.angle(&v);
            }
        }
        if edge.values().any(|(_, count)| *count != 2) {
            return None;
        }
        Some(Self {
            face,
            edge: edge.into_iter().map(|(k, (n, _))| (k, n)).collect(),
            vertex,
        })
    }

    fn of_feature(&self, tri: &[usize; 3], index: usize, feature: TriangleFeature) -> Vector3<f64> {
        match feature {
            TriangleFeature::Face => self.face[index],
            TriangleFeature::Edge(k) => self.edge[&edge_key(tri[k], tri[(k + 1) % 3])],
            TriangleFeature::Vertex(k) => self.vertex[tri[k]],
        }
    }
}

impl MeshPart {
    /// A part from vertices and counter-clockwise (outward normal) triangles. `chord_tolerance_mm` is the largest
    /// deviation of the mesh from the true surface; 0 for a part that is exactly polyhedral.
    pub fn new(
        vertices: Vec<Point3<f64>>,
        triangles: Vec<[usize; 3]>,
        chord_tolerance_mm: f64,
    ) -> Result<Self, MeshError> {
        if triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        if !(chord_tolerance_mm.is_finite() && chord_tolerance_mm >= 0.0) {
            return Err(MeshError::BadChordTolerance(chord_tolerance_mm));
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i >= vertices.len()) {
                return Err(MeshError::BadIndex(t, i, vertices.len()));
            }
        }
        let entries = triangles
            .iter()
            .enumerate()
            .map(|(index, tri)| IndexedTriangle {
                index,
                corners: tri.map(|i| vertices[i]),
            })
            .collect();
        let pseudo_normals = PseudoNormals::of_closed(&vertices, &triangles);
        if pseudo_normals.is_some() {
            // Divergence theorem: a closed mesh with outward triangles encloses a positive volume; an inverted one
            // would turn every sign (inside taken for outside) and blind the clearance check.
            let volume: f64 = triangles
                .iter()
                .map(|t| {
                    vertices[t[0]]
                        .coords
                        .dot(&vertices[t[1]].coords.cross(&vertices[t[2]].coords))
                        / 6.0
                })
                .sum();
            if volume < 0.0 {
                return Err(MeshError::InsideOut(volume));
            }
        }
        Ok(Self {
            vertices,
            triangles,
            tree: RTree::bulk_load(entries),
            pseudo_normals,
            chord_tolerance_mm,
        })
    }

    /// Whether distances are signed (the mesh is closed).
    pub fn is_signed(&self) -> bool {
        self.pseudo_normals.is_some()
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Vertex indices of triangle i.
    pub fn triangle(&self, i: usize) -> [usize; 3] {
        self.triangles[i]
    }

    pub fn chord_tolerance_mm(&self) -> f64 {
        self.chord_tolerance_mm
    }

    /// Exact distance from p to the mesh (no chord tolerance), signed when the mesh is closed, and the nearest
    /// mesh point.
    fn exact_point(&self, p: &Point3<f64>) -> (f64, Point3<f64>) {
        let nearest = self
            .tree
            .nearest_neighbor(p.coords.into())
            .expect("a mesh part has at least one triangle");
        let [a, b, c] = &nearest.corners;
        let (q, feature) = closest_on_triangle(p, a, b, c);
        let d = (p - q).norm();
        let sign = match &self.pseudo_normals {
            Some(normals) => {
                let tri = &self.triangles[nearest.index];
                let n = normals.of_feature(tri, nearest.index, feature);
                if (p - q).dot(&n) < 0.0 {
                    -1.0
                } else {
                    1.0
                }
            }
            None => 1.0,
        };
        (sign * d, q)
    }

    pub fn vertices(&self) -> &[Point3<f64>] {
        &self.vertices
    }
}

impl PartDistance for MeshPart {
    fn point_proximity(&self, p: &Point3<f64>) -> Proximity {
        let (d, q) = self.exact_point(p);
        Proximity {
            distance_mm: d - self.chord_tolerance_mm,
            query_point: *p,
            part_point: q,
        }
    }

    /// Best-first search of the R*-tree: nodes in order of a lower bound of their distance to the segment, exact
    /// segment-triangle distances at the leaves, until no node can hold anything nearer than the best found.
    fn segment_proximity(&self, a: &Point3<f64>, b: &Point3<f64>) -> Proximity {
        let (da, _) = self.exact_point(a);
        let bounds = SegmentBounds::new(a, b);
        let mut best_d = f64::INFINITY;
        let mut best = (*a, *a);
        let mut queue = BinaryHeap::new();
        for child in self.tree.root().children() {
            queue.push(Candidate {
                bound: bounds.lower_bound(&child.envelope()),
                node: child,
            });
        }
        while let Some(Candidate { bound, node }) = queue.pop() {
            if bound >= best_d {
                break;
            }
            match node {
                RTreeNode::Leaf(tri) => {
                    let [t0, t1, t2] = &tri.corners;
                    let (s, q) = closest_segment_triangle(a, b, [t0, t1, t2]);
                    let d = (s - q).norm();
                    if d < best_d {
                        best_d = d;
                        best = (s, q);
                    }
                }
                RTreeNode::Parent(parent) => {
                    for child in parent.children() {
                        let bound = bounds.lower_bound(&child.envelope());
                        if bound < best_d {
                            queue.push(Candidate { bound, node: child });
                        }
                    }
                }
            }
        }
        // A segment that does not meet the surface lies wholly on one side of it: the side of its end a.
        let signed = if best_d > 0.0 && da < 0.0 {
            -best_d
        } else {
            best_d
        };
        Proximity {
            distance_mm: signed - self.chord_tolerance_mm,
            query_point: best.0,
            part_point: best.1,
        }
    }
}
