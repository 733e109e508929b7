//! A scanned section's best fit to its reference profile (`geometry::section_fit`), as the report keeps it: where
//! the section lies (shift along the thickness direction and the chord, and in the plane's own axes; twist) and its
//! form error once that is removed, by least squares and by minimum zone.

use nalgebra::{Point3, Vector2};
use serde::{Deserialize, Serialize};

use super::deviation::ProfileGauge;
use crate::geometry::section_fit::{fit_section, FitMethod, FitMode, Form, Measured};
use crate::geometry::section_parameters::farthest_pair;

/// The form error after a fit, mm.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct SectionForm {
    pub min_mm: f64,
    pub max_mm: f64,
    pub rms_mm: f64,
    /// Twice the largest absolute deviation: the narrowest band centred on the reference holding every point.
    pub zone_mm: f64,
}

/// One best fit of a section: translations and twist about the chord's middle.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct SectionBestFit {
    /// What the fit moved: "full" (the two translations and the twist).
    pub mode: String,
    /// "l2" (least squares) or "minzone" (minimum zone).
    pub method: String,
    /// The section's displacement from the reference along its thickness direction (the chord turned +90 deg in
    /// the plane, the chord pointing to +y), mm.
    pub dn_mm: f64,
    /// ... along the chord, mm.
    pub dchord_mm: f64,
    /// ... in the profile plane's axes (y, z of the part frame), mm.
    pub shift_mm: [f64; 2],
    /// The section's turn about the chord's middle, deg, counter-clockwise in (y, z) positive.
    pub rotation_deg: f64,
    /// The chord's unit direction in (y, z), the thickness direction being it turned by +90 deg.
    pub chord_direction: [f64; 2],
    pub form: SectionForm,
}

/// The section's fits by least squares and by minimum zone, from its points (part frame, in scan order, flagged
/// contacts left out); `Err` says why the section could not be fitted.
pub fn best_fits(
    gauge: &ProfileGauge,
    points: &[Point3<f64>],
) -> Result<Vec<SectionBestFit>, String> {
    if points.len() < 4 {
        return Err(format!(
            "{} points are too few for a best fit",
            points.len()
        ));
    }
    let in_plane: Vec<Vector2<f64>> = points.iter().map(|p| Vector2::new(p.y, p.z)).collect();
    let (pivot, chord) = chord_of(&in_plane);
    let measure = |moved: &[Vector2<f64>]| -> Vec<Option<Measured>> {
        let mut scan = gauge.scan();
        let mut last_normal = None;
        moved
            .iter()
            .zip(points)
            .map(|(q, p)| {
                let measured = scan.measure(&Point3::new(p.x, q.x, q.y)).ok()?;
                let to_point = Vector2::new(q.x - measured.foot[1], q.y - measured.foot[2]);
                // The distance grows along the line from the foot to the point; at the reference itself (no
                // line), the neighbour's direction stands in.
                let normal = match to_point.try_normalize(1e-12) {
                    Some(unit) => unit * measured.deviation_mm.signum(),
                    None => last_normal?,
                };
                last_normal = Some(normal);
                Some(Measured {
                    distance_mm: measured.deviation_mm,
                    normal,
                })
            })
            .collect()
    };
    [(FitMethod::L2, "l2"), (FitMethod::MinZone, "minzone")]
        .into_iter()
        .map(|(method, name)| {
            let fitted = fit_section(&in_plane, pivot, chord, FitMode::Full, method, measure)
                .map_err(|e| e.to_string())?;
            let across = Vector2::new(-chord.y, chord.x);
            let shift = chord * fitted.dchord_mm + across * fitted.dn_mm;
            Ok(SectionBestFit {
                mode: "full".into(),
                method: name.into(),
                dn_mm: fitted.dn_mm,
                dchord_mm: fitted.dchord_mm,
                shift_mm: [shift.x, shift.y],
                rotation_deg: fitted.rotation_deg,
                chord_direction: [chord.x, chord.y],
                form: form(&fitted.form),
            })
        })
        .collect()
}

fn form(form: &Form) -> SectionForm {
    SectionForm {
        min_mm: form.min_mm,
        max_mm: form.max_mm,
        rms_mm: form.rms_mm,
        zone_mm: form.zone_mm,
    }
}

/// The section's chord: the middle and unit direction of its two points farthest apart (nose and tail), the
/// direction pointing to +y (to +z for a chord along z). Taken from the measured points: they lie within the
/// section's displacement of the reference, which turns the chord by the twist only.
pub(crate) fn chord_of(points: &[Vector2<f64>]) -> (Vector2<f64>, Vector2<f64>) {
    let (a, b) = farthest_pair(points);
    let mut direction = (b - a).try_normalize(0.0).unwrap_or_else(Vector2::x);
    if direction.x < 0.0 || (direction.x == 0.0 && direction.y < 0.0) {
        direction = -direction;
    }
    ((a + b) / 2.0, direction)
}
