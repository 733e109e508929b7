//! A scanned profile seen flat: its points and normals projected into the profile's own plane, and a coordinate
//! along the section that means the same place on every instance, so that the instances' deviation lines line up.

use nalgebra::{Matrix3, SymmetricEigen, Vector2, Vector3};

use crate::report::PointRecord;

/// Below this ratio of the middle to the largest principal variance the points lie on a line and span no plane.
const COLLINEAR_RATIO: f64 = 1e-12;
/// Below this length a direction is taken as zero (unit vectors, so a pure ratio).
const NEGLIGIBLE: f64 = 1e-9;

/// One point of a section, in the profile plane (mm): `u` horizontal, `v` up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionPoint {
    pub u: f64,
    pub v: f64,
    /// The point's outward normal projected into the plane, unit length, or zero when the normal is
    /// perpendicular to the plane (no in-plane direction to draw its deviation along).
    pub normal: Vector2<f64>,
    pub deviation_mm: f64,
    /// The deviation after the section's least-squares best fit, where the report has it.
    pub after_fit_mm: Option<f64>,
    /// Angle about the section's centroid, from its chord, counter-clockwise in (u, v), in (-180, 180] degrees.
    pub angle_deg: f64,
}

/// Projects a profile's surface points into its plane, in scan order; `None` when fewer than three points or
/// the points lie on a line (no plane to see them in).
///
/// The plane is the least-squares plane (PCA: its normal is the smallest principal axis). The normal is turned
/// away from the machine origin, and `u` is the horizontal in-plane direction `z x normal`: for a part centred
/// on the origin, like a propeller on its axis, every instance is then seen from outside and the instances' `u`
/// axes correspond. `v = normal x u` is up (z itself when the plane is vertical). The angle is measured from
/// the chord (the longest principal axis, pointing to +u), so 0 and 180 degrees are the section's two ends and
/// its two faces take the two signs of the angle.
pub fn project_section(points: &[PointRecord]) -> Option<Vec<SectionPoint>> {
    if points.len() < 3 {
        return None;
    }
    let positions: Vec<Vector3<f64>> = points.iter().map(|p| Vector3::from(p.surface)).collect();
    let centroid = positions.iter().sum::<Vector3<f64>>() / positions.len() as f64;
    let axes = principal_axes(&positions, centroid)?;
    let frame = PlaneFrame::new(axes, centroid);
    let chord = frame.in_plane(&axes.largest);
    let chord = if chord.x > 0.0 || (chord.x == 0.0 && chord.y > 0.0) {
        chord
    } else {
        -chord
    };
    let centre = frame.in_plane(&centroid);
    let projected = points
        .iter()
        .zip(&positions)
        .map(|(point, position)| {
            let at = frame.in_plane(position);
            let from_centre = at - centre;
            let angle = chord.perp(&from_centre).atan2(chord.dot(&from_centre));
            let normal = frame.in_plane(&Vector3::from(point.normal));
            SectionPoint {
                u: at.x,
                v: at.y,
                normal: normal
                    .try_normalize(NEGLIGIBLE)
                    .unwrap_or_else(Vector2::zeros),
                deviation_mm: point.deviation_mm,
                after_fit_mm: point.after_fit_mm,
                angle_deg: angle.to_degrees(),
            }
        })
        .collect();
    Some(projected)
}

/// The smallest and largest principal axes of points about their centroid.
#[derive(Debug, Clone, Copy)]
struct PrincipalAxes {
    smallest: Vector3<f64>,
    largest: Vector3<f64>,
}

fn principal_axes(positions: &[Vector3<f64>], centroid: Vector3<f64>) -> Option<PrincipalAxes> {
    let scatter: Matrix3<f64> = positions
        .iter()
        .map(|p| (p - centroid) * (p - centroid).transpose())
        .sum();
    let eigen = SymmetricEigen::new(scatter);
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| eigen.eigenvalues[a].total_cmp(&eigen.eigenvalues[b]));
    let [smallest, middle, largest] = order;
    if eigen.eigenvalues[middle] <= COLLINEAR_RATIO * eigen.eigenvalues[largest] {
        return None;
    }
    Some(PrincipalAxes {
        smallest: eigen.eigenvectors.column(smallest).into_owned(),
        largest: eigen.eigenvectors.column(largest).into_owned(),
    })
}

/// The in-plane unit directions `u` (horizontal) and `v` (up).
struct PlaneFrame {
    u: Vector3<f64>,
    v: Vector3<f64>,
}

impl PlaneFrame {
    fn new(axes: PrincipalAxes, centroid: Vector3<f64>) -> Self {
        let normal = if axes.smallest.dot(&centroid) < 0.0 {
            -axes.smallest
        } else {
            axes.smallest
        };
        // A horizontal plane has no horizontal direction of its own: its chord stands in.
        let u = Vector3::z()
            .cross(&normal)
            .try_normalize(NEGLIGIBLE)
            .unwrap_or(axes.largest);
        Self {
            u,
            v: normal.cross(&u),
        }
    }

    fn in_plane(&self, vector: &Vector3<f64>) -> Vector2<f64> {
        Vector2::new(vector.dot(&self.u), vector.dot(&self.v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An ellipse of half-axes 40 (chord) and 5 mm, its chord tilted 30 degrees from horizontal, in the vertical
    /// plane at distance `radius` from the z axis whose outward normal is at `azimuth_deg` about z; deviation k.
    fn ellipse(radius: f64, azimuth_deg: f64, count: usize) -> Vec<PointRecord> {
        let (sin_a, cos_a) = azimuth_deg.to_radians().sin_cos();
        let outward = Vector3::new(cos_a, sin_a, 0.0);
        let horizontal = Vector3::new(-sin_a, cos_a, 0.0);
        let tilt = 30f64.to_radians();
        let chord = horizontal * tilt.cos() + Vector3::z() * tilt.sin();
        let across = -horizontal * tilt.sin() + Vector3::z() * tilt.cos();
        (0..count)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / count as f64;
                let surface = outward * radius + chord * 40.0 * t.cos() + across * 5.0 * t.sin();
                let normal = (chord * 5.0 * t.cos() + across * 40.0 * t.sin()).normalize();
                PointRecord {
                    centre: (surface + normal).into(),
                    normal: normal.into(),
                    surface: surface.into(),
                    deviation_mm: k as f64,
                    off_plane_mm: 0.0,
                    quality: 1.0,
                    flagged: false,
                    after_fit_mm: None,
                }
            })
            .collect()
    }

    #[test]
    fn a_section_in_the_yz_plane_keeps_y_and_z() {
        let points = ellipse(100.0, 0.0, 36);
        let section = project_section(&points).unwrap();
        for (point, flat) in points.iter().zip(&section) {
            assert!((flat.u - point.surface[1]).abs() < 1e-9, "{flat:?}");
            assert!((flat.v - point.surface[2]).abs() < 1e-9, "{flat:?}");
            let normal = Vector2::new(point.normal[1], point.normal[2]);
            assert!((flat.normal - normal).norm() < 1e-9, "{flat:?}");
        }
        // The chord points up-right at 30 degrees, so the first point (chord end, +u) is at angle 0 and the
        // upper face's middle (t = 90 degrees) is at +90.
        assert!(section[0].angle_deg.abs() < 1e-9, "{:?}", section[0]);
        assert!(
            (section[9].angle_deg - 90.0).abs() < 1e-9,
            "{:?}",
            section[9]
        );
        assert!(
            (section[27].angle_deg + 90.0).abs() < 1e-9,
            "{:?}",
            section[27]
        );
    }

    #[test]
    fn rotated_instances_see_the_same_section() {
        let reference = project_section(&ellipse(250.0, 0.0, 24)).unwrap();
        for azimuth in [120.0, 240.0, -75.0] {
            let turned = project_section(&ellipse(250.0, azimuth, 24)).unwrap();
            for (a, b) in reference.iter().zip(&turned) {
                assert!(
                    (a.u - b.u).abs() < 1e-9,
                    "azimuth {azimuth}: {a:?} vs {b:?}"
                );
                assert!(
                    (a.v - b.v).abs() < 1e-9,
                    "azimuth {azimuth}: {a:?} vs {b:?}"
                );
                // The section's far end sits on the cut, at 180 or -180 degrees by rounding.
                let turn = (a.angle_deg - b.angle_deg).rem_euclid(360.0);
                assert!(turn.min(360.0 - turn) < 1e-9, "azimuth {azimuth}");
                assert!((a.normal - b.normal).norm() < 1e-9, "azimuth {azimuth}");
                assert_eq!(a.deviation_mm, b.deviation_mm);
            }
        }
    }

    #[test]
    fn points_on_a_line_span_no_plane() {
        let mut points = ellipse(100.0, 0.0, 3);
        for (k, point) in points.iter_mut().enumerate() {
            point.surface = [100.0, k as f64, 2.0 * k as f64];
        }
        assert_eq!(project_section(&points), None);
        assert_eq!(project_section(&ellipse(100.0, 0.0, 2)), None);
    }

    #[test]
    fn a_normal_across_the_plane_draws_no_whisker() {
        let mut points = ellipse(100.0, 0.0, 8);
        points[3].normal = [1.0, 0.0, 0.0];
        let section = project_section(&points).unwrap();
        assert_eq!(section[3].normal, Vector2::zeros());
        assert!((section[4].normal.norm() - 1.0).abs() < 1e-12);
    }
}
