//! The taught reference as a closed triangle mesh in the part frame, for the clearance checks of planned moves
//! (issue 6): the part model a swept stylus is measured against.
//!
//! - A supershape reference is polygonised (seed 000 section 4): vertices on the surface, faces within a chord
//!   tolerance of it.
//! - An IP stack is lofted through its profiles' nominal curves (the master's measured surface, thinned): each
//!   closed nominal curve resampled by arc length from its first nominal (every teach scan starts at the same
//!   place of its section), consecutive rings joined by triangles, the two end rings closed by fans. Near a
//!   profile's plane, where the descents and the ways out of its scans run, the mesh is the measured surface to
//!   within the rings' chord sag, measured against each profile's taught model (not assumed: the sag grows with
//!   the part's nominal spacing and shrinks with its curvature); between profiles it is a ruled surface, and
//!   beyond the outermost profiles (hub, tip) the part is not modelled: moves there are not checked by this model.

use nalgebra::{Point3, Vector3};

use super::deviation::ProfileGauge;
use super::reference::Reference;
use crate::geometry::supershape::mesh::{polygonise, MeshParams};
use crate::model_file::ReferenceModel;

/// Points per lofted ring: 0.5 to 2 mm apart on the simulated propeller's sections.
const RING_POINTS: usize = 256;
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
    let chord_tolerance_mm = ring_sag_mm(reference, &rings)?;
    Ok(PartMesh {
        vertices,
        triangles,
        chord_tolerance_mm,
    })
}

/// The farthest that a ring's vertices and the midpoints of its edges (where a chord sags most) lie from their
/// profile's taught model, mm. A clearance check subtracts it from every distance, so it is measured on this
/// part rather than bounded from a spacing that a part file may change.
fn ring_sag_mm(reference: &Reference, rings: &[Vec<Point3<f64>>]) -> Result<f64, String> {
    let gauges = ProfileGauge::all(reference);
    let mut sag: f64 = 0.0;
    for (ring, gauge) in rings.iter().zip(&gauges) {
        let mut scan = gauge.scan();
        for i in 0..ring.len() {
            let midpoint = nalgebra::center(&ring[i], &ring[(i + 1) % ring.len()]);
            for point in [ring[i], midpoint] {
                let measured = scan.measure(&point).map_err(|e| {
                    format!(
                        "profile {} of part '{}': a point of its lofted surface at {point} mm has no distance \
                         to the profile's model ({e})",
                        gauge.name(),
                        reference.part
                    )
                })?;
                sag = sag.max(measured.deviation_mm.abs());
            }
        }
    }
    Ok(sag)
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
    /// outward, every ring vertex on its ellipse within the measured chord tolerance (which must cover the sag of
    /// 5 mm nominal chords on the ellipses' flanks, 5^2 / (8 R) = 0.07 mm at R = 45 mm, and stay well below a
    /// millimetre), and the volume of the elliptic frustums between the profiles.
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
        assert!(
            (0.05..0.3).contains(&mesh.chord_tolerance_mm),
            "chord tolerance {} mm",
            mesh.chord_tolerance_mm
        );
        let stack = Ellipse::stack();
        let mut farthest: f64 = 0.0;
        for (k, ellipse) in stack.iter().enumerate() {
            for v in &mesh.vertices[k * RING_POINTS..(k + 1) * RING_POINTS] {
                assert!((v.x - ellipse.x).abs() < 1e-9);
                // Between measured nominals: within their chord sag of the ellipse (the taught model is within
                // 5 um of it).
                let off = ellipse.distance_in_plane(v.y, v.z).abs();
                farthest = farthest.max(off);
                assert!(off < mesh.chord_tolerance_mm + 0.005, "{off} mm off at {v}");
            }
        }
        // The tolerance is the sag, not a loose bound over it.
        assert!(mesh.chord_tolerance_mm < 2.0 * farthest + 0.005);
        let volume = signed_volume(&mesh.vertices, &mesh.triangles);
        assert!(volume > 0.0);
    }
}
