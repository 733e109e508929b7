//! What the operator is told when a scan along the master's curve finds no surface (I++ error 1006, "Surface not
//! found", spec 11.2.7): where along the curve the machine stopped, and whether scanning again can help.
//!
//! Why it matters: the machine's error names neither the point nor the cause, and the usual next step (`zeroset
//! clear`, which scans the profile again) fails the same way when the cause is the part itself. Round a sharp edge
//! the probing lines pass through a pivot inside the master's edge (`plan::fan`), so they find the part's edge only
//! up to about the pivot's depth plus the ball's radius inside the master's, and about the ball's radius off across
//! it. A blade whose trailing edge lies farther off (inside it along the chord, a chord short by twice that or more,
//! or off across the edge) stops there.

use nalgebra::Point3;
use zeroset_drivers::machine::{CurveScan, Density};

use crate::plan::EdgeFan;

/// I++ DME 1.4.3, error table: 1006, "Surface not found" (severity 2).
pub(super) const SURFACE_NOT_FOUND: u16 = 1006;

/// The text appended to the machine's "Surface not found" for a curve scan of `scan` (whose sharp edges are
/// `edges`) that had measured `measured` points when it stopped, with a ball of `ball_radius_mm`.
pub(super) fn where_not_found(
    scan: &CurveScan,
    edges: &[EdgeFan],
    measured: usize,
    ball_radius_mm: f64,
) -> String {
    let total = scan.nominals.len();
    // With one point per nominal, the scan stopped probing the nominal after the last one it measured.
    if scan.density != Density::AtNominals || measured >= total {
        return format!(
            "; no surface was found after {measured} points of the curve's {total} nominals, within {} mm of the \
             master's surface ([scan] max_deviation_mm) plus the probe's search: check the part's placement \
             (part_to_machine) and that this is the part the master was taught on",
            scan.max_deviation
        );
    }
    let nominal = scan.nominals[measured];
    let (p, n) = (nominal.point, nominal.normal);
    let along = format!(
        "; no surface was found after {measured} of {total} points, probing along the line of outward direction \
         ({:.3}, {:.3}, {:.3}) through the nominal point ({:.3}, {:.3}, {:.3}) mm",
        n.x, n.y, n.z, p.x, p.y, p.z
    );
    let again = "Scanning this profile again along the master's curve stops the same way: check the part against \
                 the master; `zeroset abort` ends the job with the scans so far kept";
    match near_a_sharp_edge(scan, edges, &Point3::new(p.x, p.y, p.z)) {
        // Within the fan's depth of the apex the line is one of the fan's (`plan::fan`).
        Some((off, edge)) if off < edge.depth_mm => format!(
            "{along}, {off:.2} mm from the master's sharp edge at ({:.3}, {:.3}, {:.3}) mm: the probing lines round \
             it pass through a point {:.2} mm inside the master's edge, and find the part's edge only up to about \
             that plus the ball's radius ({ball_radius_mm} mm) inside the master's, or about the ball's radius off \
             across it. This part's edge lies farther off (a blade short of chord by about twice that or more, or \
             off across the edge). {again}",
            edge.apex.x, edge.apex.y, edge.apex.z, edge.depth_mm
        ),
        Some((off, edge)) => format!(
            "{along}, {off:.2} mm from the master's sharp edge at ({:.3}, {:.3}, {:.3}) mm, on a face before the \
             lines that fan round it: a face's line finds the part only where its face passes within about the \
             ball's radius ({ball_radius_mm} mm) of it, so this part's edge lies about {:.2} mm or more inside the \
             master's along the face (a blade short of chord), or its face lies off across it by more than {} mm \
             ([scan] max_deviation_mm) plus the probe's search. {again}",
            edge.apex.x,
            edge.apex.y,
            edge.apex.z,
            (off - ball_radius_mm).max(0.0),
            scan.max_deviation
        ),
        None => format!(
            "{along}: the part lies farther from the master's surface there than {} mm ([scan] max_deviation_mm) \
             plus the probe's search. Check the part's placement (part_to_machine) and that this is the part the \
             master was taught on; scanning it again as it is stops the same way",
            scan.max_deviation
        ),
    }
}

/// The nearest of `edges` to a nominal `at`, and how far its apex is, mm, where that is within the scan's
/// `max_deviation`: as far as a part's edge may lie off.
fn near_a_sharp_edge<'a>(
    scan: &CurveScan,
    edges: &'a [EdgeFan],
    at: &Point3<f64>,
) -> Option<(f64, &'a EdgeFan)> {
    edges
        .iter()
        .map(|edge| ((edge.apex - at).norm(), edge))
        .filter(|(off, _)| *off <= scan.max_deviation)
        .min_by(|a, b| a.0.total_cmp(&b.0))
}

#[cfg(test)]
mod tests {
    use zeroset_drivers::machine::{Nominal, Xyz};

    use super::*;

    /// A closed curve: a face along y at z = 1 up to an apex at y = 10 with a fan of three normals, then back
    /// along z = -1.
    fn blade_end() -> CurveScan {
        let face = |y: f64, z: f64| Nominal {
            point: Xyz::new(0.0, y, z),
            normal: Xyz::new(0.0, 0.0, z.signum()),
        };
        let mut nominals: Vec<Nominal> = (0..5).map(|k| face(2.0 * k as f64, 1.0)).collect();
        let half = std::f64::consts::FRAC_1_SQRT_2;
        nominals.extend(
            [(half, half), (1.0, 0.0), (half, -half)].map(|(y, z)| Nominal {
                point: Xyz::new(0.0, 10.0, 0.0),
                normal: Xyz::new(0.0, y, z),
            }),
        );
        nominals.extend((0..5).map(|k| face(8.0 - 2.0 * k as f64, -1.0)));
        CurveScan {
            closed: true,
            nominals,
            max_deviation: 3.0,
            min_radius: 1.0,
            density: Density::AtNominals,
        }
    }

    /// The apex of [`blade_end`], its fan pivoting 1 mm inside it.
    fn apex() -> [EdgeFan; 1] {
        [EdgeFan {
            apex: Point3::new(0.0, 10.0, 0.0),
            depth_mm: 1.0,
        }]
    }

    #[test]
    fn a_stop_round_a_sharp_edge_says_the_parts_edge_lies_beyond_the_fans_reach() {
        let scan = blade_end();
        // Five face points measured: the sixth nominal, the apex's first normal, found nothing.
        let text = where_not_found(&scan, &apex(), 5, 1.0);
        assert!(
            text.contains("after 5 of 13 points")
                && text.contains("direction (0.000, 0.707, 0.707)")
                && text.contains(
                    "through the nominal point (0.000, 10.000, 0.000) mm, 0.00 mm from the master's sharp edge at \
                     (0.000, 10.000, 0.000) mm: the probing lines round it pass through a point 1.00 mm inside"
                )
                && text.contains("ball's radius (1 mm) inside the master's")
                && text.contains("stops the same way"),
            "{text}"
        );
        // Without the edges the same stop is a stop on a face.
        let text = where_not_found(&scan, &[], 5, 1.0);
        assert!(!text.contains("sharp edge"), "{text}");
    }

    #[test]
    fn a_stop_on_a_face_beside_a_sharp_edge_says_how_far_inside_the_parts_edge_lies() {
        let scan = blade_end();
        // The face points 2.24 mm before the apex, on either face: within the scan's 3 mm of it, beyond the fan's 1.
        for face_point in [4, 8] {
            let text = where_not_found(&scan, &apex(), face_point, 1.0);
            assert!(
                text.contains(", 2.24 mm from the master's sharp edge at (0.000, 10.000, 0.000) mm, on a face")
                    && text.contains("lies about 1.24 mm or more inside the master's")
                    && !text.contains("pass through a point"),
                "{text}"
            );
        }
    }

    #[test]
    fn a_stop_on_a_face_says_how_far_the_scan_searched() {
        let scan = blade_end();
        // The face point 4.12 mm from the apex.
        let text = where_not_found(&scan, &apex(), 3, 1.0);
        assert!(
            text.contains("after 3 of 13 points")
                && text.contains("through the nominal point (0.000, 6.000, 1.000) mm:")
                && text.contains("farther from the master's surface there than 3 mm")
                && !text.contains("sharp edge"),
            "{text}"
        );
        // A scan that measured every nominal and still reported the error: no nominal to name.
        let text = where_not_found(&scan, &apex(), 13, 1.0);
        assert!(text.contains("after 13 points of the curve's 13"), "{text}");
    }
}
