//! An indexed triangle mesh in millimetres, with the checks and measures a closed surface allows.

use std::collections::{HashMap, HashSet};

use nalgebra::Point3;

/// Triangles over shared vertices, wound counter-clockwise seen from outside (normals outward).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    pub vertices: Vec<Point3<f64>>,
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// Watertight, edge-manifold and consistently oriented: every directed edge occurs exactly
    /// once and its reverse exactly once (each edge shared by exactly two triangles that run it in
    /// opposite directions), and no triangle repeats a vertex.
    pub fn is_closed(&self) -> bool {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
        for t in &self.triangles {
            if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                return false;
            }
            for k in 0..3 {
                *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        directed
            .iter()
            .all(|(&(a, b), &count)| count == 1 && directed.get(&(b, a)) == Some(&1))
    }

    /// The enclosed volume (mm^3) by the divergence theorem: the sum of the signed tetrahedra from
    /// the origin to each triangle. Meaningful for a closed mesh; positive when normals face out.
    pub fn volume(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v as usize].coords);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    /// The surface area (mm^2).
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// V - E + F over the vertices the triangles use: 2 - 2g for a closed surface of genus g
    /// (summed over its components).
    pub fn euler_characteristic(&self) -> i64 {
        let mut used = HashSet::new();
        let mut edges = HashSet::new();
        for t in &self.triangles {
            for k in 0..3 {
                used.insert(t[k]);
                let (a, b) = (t[k], t[(k + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        used.len() as i64 - edges.len() as i64 + self.triangles.len() as i64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube [0, 1]^3 with outward normals.
    fn cube() -> TriMesh {
        let vertices = (0..8)
            .map(|c| Point3::new((c & 1) as f64, (c >> 1 & 1) as f64, (c >> 2 & 1) as f64))
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        TriMesh {
            vertices,
            triangles,
        }
    }

    #[test]
    fn a_cube_is_closed_with_its_volume_and_area() {
        let mesh = cube();
        assert!(mesh.is_closed());
        assert!((mesh.volume() - 1.0).abs() < 1e-15);
        assert!((mesh.area() - 6.0).abs() < 1e-15);
        assert_eq!(mesh.euler_characteristic(), 2);
    }

    #[test]
    fn a_hole_or_a_flipped_triangle_is_not_closed() {
        let mut open = cube();
        open.triangles.pop();
        assert!(!open.is_closed());
        let mut flipped = cube();
        flipped.triangles[3].swap(0, 1);
        assert!(!flipped.is_closed());
        let mut inverted = cube();
        inverted.triangles.iter_mut().for_each(|t| t.swap(0, 1));
        assert!(inverted.is_closed());
        assert!((inverted.volume() + 1.0).abs() < 1e-15);
    }
}
