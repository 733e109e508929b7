//! The taught reference as a closed triangle mesh in the part frame, for the clearance checks of planned moves
//! (issue 6): the part model a swept stylus is measured against.
//!
//! - A supershape reference is polygonised (seed 000 section 4): vertices on the surface, faces within a chord
//!   tolerance of it.
//! - An IP stack is lofted through its profiles' nominal curves (the master's measured surface, thinned): each
//!   closed nominal curve resampled by arc length from its first nominal (every teach scan starts at the same
//!   place of its section), consecutive rings joined by triangles, the two end rings closed by fans. Near a
//!   profile's plane, where the descents and the ways out of its scans run, the mesh is the measured surface to
//!   within the nominals' chord sag; between profiles it is a ruled surface, and beyond the outermost profiles
//!   (hub, tip) the part is not modelled: moves there are not checked by this model.

use nalgebra::{Point3, Vector3};

use super::reference::Reference;
use crate::geometry::supershape::mesh::{polygonise, MeshParams};
use crate::model_file::ReferenceModel;

/// Points per lofted ring: 0.5 to 2 mm apart on the simulated propeller's sections.
const RING_POINTS: usize = 256;
/// The lofted rings' chord sag: nominals at most 2 mm apart and at most 10 degrees of normal turn
/// (`nominals`): 2^2 / (8 x 11.5 mm), the radius where the two limits meet, is 0.044 mm; above that radius the
/// spacing limits the sag, below it the turn does (R (1 - cos 5 degrees) < 0.044 mm).
const LOFT_CHORD_MM: f64 = 0.05;
/// Mesh cells of a supershape: this fraction of its bounding-box diagonal (1.2 mm on the 120 mm nut model).
const SOLID_CELLS_PER_DIAGONAL: f64 = 100.0;

/// A closed mesh, wound counter-clockwise seen from outside, and how far it may lie from the model's surface.
#[derive(Debug, Clone, PartialEq)]
pub struct PartMesh {
    pub vertices: Vec<Point3<f64>>,
    pub triangles: Vec<[usize; 3]>,
    pub chord_tolerance_mm: f64,
}

/// The reference's surface as a mesh in the part frame.
pub fn part_mesh(reference: &Reference) -> Result<PartMesh, String> {
    match &reference.model.model {
        ReferenceModel::Supershape { solid, .. } => {
            let cell = solid.bounds().diagonal() / SOLID_CELLS_PER_DIAGONAL;
            let mesh = polygonise(solid, &MeshParams::with_cell(cell))
                .map_err(|e| format!("the supershape model of part '{}': {e}", reference.part))?;
            // A face spans about a cell; its sag on a radius R is cell^2 / (8 R); bounded here for R >= cell.
            Ok(PartMesh {
                vertices: mesh.vertices,
                triangles: mesh
                    .triangles
                    .iter()
                    .map(|t| t.map(|i| i as usize))
                    .collect(),
                chord_tolerance_mm: cell / 8.0,
            })
        }
        ReferenceModel::Stack { .. } => loft(reference),
        _ => Err(format!(
            "the reference of part '{}' is not a stack of profiles or a supershape",
            reference.part
        )),
    }
}

/// The loft through the profiles' nominal curves, in the order of the reference (increasing x).
fn loft(reference: &Reference) -> Result<PartMesh, String> {
    let rings: Vec<Vec<Point3<f64>>> = reference
        .profiles
        .iter()
        .map(|profile| {
            let points: Vec<Point3<f64>> = profile
                .nominals
                .iter()
                .map(|n| Point3::from(n.point))
                .collect();
            resample_closed(&points, RING_POINTS).ok_or_else(|| {
                format!(
                    "profile {} of part '{}' has too few nominals to model its surface",
                    profile.name, reference.part
                )
            })
        })
        .collect::<Result<_, _>>()?;
    if rings.len() < 2 {
        return Err(format!(
            "part '{}' has fewer than two profiles to loft",
            reference.part
        ));
    }
    let n = RING_POINTS;
    let mut vertices: Vec<Point3<f64>> = rings.iter().flatten().copied().collect();
    let mut triangles = Vec::new();
    for k in 0..rings.len() - 1 {
        for i in 0..n {
            let (a, b) = (k * n + i, k * n + (i + 1) % n);
            let (c, d) = (a + n, b + n);
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    for (k, reversed) in [(0, true), (rings.len() - 1, false)] {
        let centre = rings[k]
            .iter()
            .fold(Vector3::zeros(), |sum, p| sum + p.coords)
            / n as f64;
        vertices.push(Point3::from(centre));
        let apex = vertices.len() - 1;
        for i in 0..n {
            let (a, b) = (k * n + i, k * n + (i + 1) % n);
            triangles.push(if reversed { [apex, b, a] } else { [apex, a, b] });
        }
    }
    if signed_volume(&vertices, &triangles) < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    Ok(PartMesh {
        vertices,
        triangles,
        chord_tolerance_mm: LOFT_CHORD_MM,
    })
}

/// `count` points evenly spaced by arc length along the closed polyline through `points`, from its first point.
fn resample_closed(points: &[Point3<f64>], count: usize) -> Option<Vec<Point3<f64>>> {
    if points.len() < 3 {
        return None;
    }
    let segments: Vec<(Point3<f64>, Point3<f64>)> = (0..points.len())
        .map(|i| (points[i], points[(i + 1) % points.len()]))
        .collect();
    let total: f64 = segments.iter().map(|(a, b)| (b - a).norm()).sum();
    let mut out = Vec::with_capacity(count);
    let (mut segment, mut start_of_segment) = (0, 0.0);
    for k in 0..count {
        let at = total * k as f64 / count as f64;
        while start_of_segment + (segments[segment].1 - segments[segment].0).norm() < at
            && segment + 1 < segments.len()
        {
            start_of_segment += (segments[segment].1 - segments[segment].0).norm();
            segment += 1;
        }
        let (a, b) = segments[segment];
        let length = (b - a).norm();
        let u = if length > 0.0 {
            ((at - start_of_segment) / length).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(a + (b - a) * u);
    }
    Some(out)
}

/// The volume enclosed by a closed mesh, positive when its triangles wind counter-clockwise seen from outside.
fn signed_volume(vertices: &[Point3<f64>], triangles: &[[usize; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i].coords);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::test_profiles::{taught_ellipses, Ellipse};

    /// The taught elliptic stack lofted: closed (every edge shared by two triangles, in opposite directions),
    /// outward, every ring vertex on its ellipse, and the volume of the elliptic frustums between the profiles.
    #[test]
    fn a_lofted_stack_is_closed_and_follows_its_profiles() {
        let reference = taught_ellipses();
        let mesh = part_mesh(reference).unwrap();
        let mut directed = std::collections::HashSet::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                assert!(directed.insert((t[k], t[(k + 1) % 3])), "edge used twice");
            }
        }
        for (a, b) in &directed {
            assert!(directed.contains(&(*b, *a)), "open edge {a}-{b}");
        }
        let stack = Ellipse::stack();
        for (k, ellipse) in stack.iter().enumerate() {
            for v in &mesh.vertices[k * RING_POINTS..(k + 1) * RING_POINTS] {
                assert!((v.x - ellipse.x).abs() < 1e-9);
                // Between measured nominals: within their chord sag of the ellipse.
                let off = ellipse.distance_in_plane(v.y, v.z).abs();
                assert!(off < LOFT_CHORD_MM, "{} mm off at {v}", off);
            }
        }
        let volume = signed_volume(&mesh.vertices, &mesh.triangles);
        assert!(volume > 0.0);
    }
}
