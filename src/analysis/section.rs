//! A scanned section's best fit to its reference profile (`geometry::section_fit`), as the report keeps it: where
//! the section lies (shift along the thickness direction and the chord, and in the plane's own axes; twist) and its
//! form error once that is removed, by least squares and by minimum zone; and its parameters (chord, thicknesses,
//! camber, chord angle, pitch) measured beside the nominal's.

use nalgebra::{Isometry3, Point3, Vector2};
use serde::{Deserialize, Serialize};

use super::deviation::ProfileGauge;
use super::edges::{sharpen, SharpEdge};
use super::tolerances::{AppliedTolerance, Parameter, ParameterVerdict};
use crate::geometry::faces::FacedProfile;
use crate::geometry::implicit::Implicit;
use crate::geometry::sampling::project_to_zero_set;
use crate::geometry::section_fit::{fit_section, FitLimits, FitMethod, FitMode, Form, Measured};
use crate::geometry::section_parameters::{farthest_pair, section_parameters, SectionParameters};
use crate::geometry::sweep::compensation::Compensated;
use crate::geometry::trace::simplify_closed;

/// The spacing of a nominal outline's points before it is thinned, mm: fine enough that its sampling moves the
/// section's parameters by under a micron.
const OUTLINE_STEP_MM: f64 = 0.01;
/// The nominal outline is kept within this of itself (mm): dense only where it bends.
const OUTLINE_TOLERANCE_MM: f64 = 1e-4;
/// The farthest a nominal outline follows the model away from the taught nominals' polyline, mm: more than the
/// sagitta between two nominals (2 mm apart on a face of radius 20 mm: 25 um) and the master's noise, far less
/// than a polynomial's stray at a sharp edge.
const MODEL_STRAY_MM: f64 = 0.05;
/// How far in from each edge, along the chord, the edge thicknesses are taken unless told (mm).
pub(crate) const EDGE_DISTANCE_MM: f64 = 2.0;

/// What each section's best fits may move, and how far: the part file's `[best_fit]`.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct BestFitSettings {
    #[serde(default)]
    pub mode: BestFitMode,
    /// How far (+-) the fit may move a section along its chord and along its thickness, mm, and turn it, deg.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_dchord_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_dn_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_rotation_deg: Option<f64>,
}

/// What a best fit moves.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
#[serde(rename_all = "lowercase")]
pub enum BestFitMode {
    /// The two translations in the section's plane and the twist about the chord's middle.
    #[default]
    Full,
    /// The two translations only: a twist stays in the form.
    Translation,
    /// Nothing: the section as measured, its form its deviations.
    None,
}

impl BestFitMode {
    pub fn name(self) -> &'static str {
        match self {
            Self::Full => "full",
            Self::Translation => "translation",
            Self::None => "none",
        }
    }

    pub(crate) fn fit_mode(self) -> FitMode {
        match self {
            Self::Full => FitMode::Full,
            Self::Translation => FitMode::Translation,
            Self::None => FitMode::None,
        }
    }
}

/// How far a best fit may move a section: +- each, mm and deg (none: as far as fits best). A section lying farther
/// off is fitted to the limit, and the rest of its displacement shows in its form.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
pub struct BestFitLimits {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dchord_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dn_mm: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation_deg: Option<f64>,
}

impl BestFitLimits {
    fn is_empty(&self) -> bool {
        *self == Self::default()
    }

    pub(crate) fn fit_limits(&self) -> FitLimits {
        FitLimits {
            dchord_mm: self.dchord_mm,
            dn_mm: self.dn_mm,
            rotation_deg: self.rotation_deg,
        }
    }
}

impl BestFitSettings {
    pub fn limits(&self) -> BestFitLimits {
        BestFitLimits {
            dchord_mm: self.max_dchord_mm,
            dn_mm: self.max_dn_mm,
            rotation_deg: self.max_rotation_deg,
        }
    }

    /// What serde cannot check: each limit a size, and no limit on what the mode does not move.
    pub(crate) fn check(&self) -> Result<(), String> {
        for (key, limit) in [
            ("max_dchord_mm", self.max_dchord_mm),
            ("max_dn_mm", self.max_dn_mm),
            ("max_rotation_deg", self.max_rotation_deg),
        ] {
            if let Some(limit) = limit {
                if !(limit.is_finite() && limit >= 0.0) {
                    return Err(format!(
                        "{key} = {limit}: a limit is how far (+-) the fit may move a section, a finite \
                         size of 0 or more; leave it out for no limit"
                    ));
                }
            }
        }
        let limited = self.limits() != BestFitLimits::default();
        if self.mode == BestFitMode::None && limited {
            return Err(
                "limits are given but mode = \"none\" moves no section; leave them out, or set mode = \
                 \"full\" or \"translation\""
                    .into(),
            );
        }
        if self.mode == BestFitMode::Translation && self.max_rotation_deg.is_some() {
            return Err(
                "max_rotation_deg is given but mode = \"translation\" never turns a section; leave it out, \
                 or set mode = \"full\""
                    .into(),
            );
        }
        Ok(())
    }
}

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
    /// What the fit moved: "full" (the two translations and the twist) or "translation".
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
    /// The limits the fit was held within (+-, mm and deg), where the part file sets any.
    #[serde(default, skip_serializing_if = "BestFitLimits::is_empty")]
    pub limits: BestFitLimits,
    /// The displacements the fit left at their limit ("dchord_mm", "dn_mm", "rotation_deg"): the section lies
    /// farther off than it may be moved, and the rest shows in its form.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub at_limit: Vec<String>,
}

impl SectionBestFit {
    /// The limits the fit was held at, for an operator: "dn +-0.25 mm, twist +-0.01 deg"; `None` when it reached
    /// none.
    pub fn held_at(&self) -> Option<String> {
        let held: Vec<String> = self
            .at_limit
            .iter()
            .filter_map(|name| match name.as_str() {
                "dchord_mm" => Some(format!("dchord +-{} mm", self.limits.dchord_mm?)),
                "dn_mm" => Some(format!("dn +-{} mm", self.limits.dn_mm?)),
                "rotation_deg" => Some(format!("twist +-{} deg", self.limits.rotation_deg?)),
                _ => None,
            })
            .collect();
        (!held.is_empty()).then(|| held.join(", "))
    }
}

/// A section's best fits, and each of its points' deviation after the least-squares one.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionFits {
    pub fits: Vec<SectionBestFit>,
    /// In the order of the points fitted, mm.
    pub after_l2_mm: Vec<f64>,
}

/// The signed distance and outward normal at the foot of each of `moved` (the section's points `points`, moved
/// within its plane by a best fit's trial motion) on `gauge`'s profile, in the plane of each point's own x.
pub(crate) fn measure_in_plane(
    gauge: &ProfileGauge,
    points: &[Point3<f64>],
    moved: &[Vector2<f64>],
) -> Vec<Option<Measured>> {
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
}

/// The section's fits by least squares and by minimum zone, from its points (part frame, in scan order, flagged
/// contacts left out), moving what `settings` lets them; `Err` says why the section could not be fitted.
pub fn best_fits(
    gauge: &ProfileGauge,
    points: &[Point3<f64>],
    settings: &BestFitSettings,
) -> Result<SectionFits, String> {
    if points.len() < 4 {
        return Err(format!(
            "{} points are too few for a best fit",
            points.len()
        ));
    }
    let in_plane: Vec<Vector2<f64>> = points.iter().map(|p| Vector2::new(p.y, p.z)).collect();
    let (pivot, chord) = chord_of(&in_plane);
    let measure = |moved: &[Vector2<f64>]| measure_in_plane(gauge, points, moved);
    let mut after_l2_mm = Vec::new();
    let fits = [(FitMethod::L2, "l2"), (FitMethod::MinZone, "minzone")]
        .into_iter()
        .map(|(method, name)| {
            let mode = settings.mode.fit_mode();
            let limits = settings.limits().fit_limits();
            let fitted = fit_section(&in_plane, pivot, chord, mode, method, &limits, measure)
                .map_err(|e| e.to_string())?;
            let across = Vector2::new(-chord.y, chord.x);
            let shift = chord * fitted.dchord_mm + across * fitted.dn_mm;
            if method == FitMethod::L2 {
                after_l2_mm = fitted.after_mm;
            }
            Ok(SectionBestFit {
                mode: settings.mode.name().into(),
                method: name.into(),
                dn_mm: fitted.dn_mm,
                dchord_mm: fitted.dchord_mm,
                shift_mm: [shift.x, shift.y],
                rotation_deg: fitted.rotation_deg,
                chord_direction: [chord.x, chord.y],
                form: form(&fitted.form),
                limits: settings.limits(),
                at_limit: ["dchord_mm", "dn_mm", "rotation_deg"]
                    .iter()
                    .zip(fitted.at_limit)
                    .filter(|(_, at)| *at)
                    .map(|(name, _)| name.to_string())
                    .collect(),
            })
        })
        .collect::<Result<_, String>>()?;
    Ok(SectionFits { fits, after_l2_mm })
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

/// The nominal outline through `nominals` (the taught nominal points, in order round the section): each moved onto
/// the model's zero set, and the stretch between neighbours filled in with points of it [`OUTLINE_STEP_MM`] apart
/// (the chord's points projected onto it), then thinned where it is straight. Where the model strays from the
/// nominals, farther than [`MODEL_STRAY_MM`], the nominals' own polyline is kept: at a sharp edge the polynomial
/// rounds the apex the master was measured with, and beside it its zero set passes close to a spurious branch
/// (the propeller's sharp trailing edges: a nominal there projects 0.6 mm away, and a trace of the zero set from
/// one point steps onto the branch and never closes).
pub(crate) fn nominal_outline(
    model: &impl Implicit<2>,
    nominals: &[Vector2<f64>],
) -> Vec<Vector2<f64>> {
    let onto_model = |p: &Vector2<f64>| {
        project_to_zero_set(model, p, MODEL_STRAY_MM).filter(|q| (q - p).norm() <= MODEL_STRAY_MM)
    };
    let on_model: Vec<Vector2<f64>> = nominals
        .iter()
        .map(|p| onto_model(p).unwrap_or(*p))
        .collect();
    let n = on_model.len();
    let mut outline = Vec::new();
    for i in 0..n {
        let (a, b) = (on_model[i], on_model[(i + 1) % n]);
        outline.push(a);
        let pieces = ((b - a).norm() / OUTLINE_STEP_MM).ceil() as usize;
        for k in 1..pieces {
            let on_chord = a + (b - a) * (k as f64 / pieces as f64);
            outline.push(onto_model(&on_chord).unwrap_or(on_chord));
        }
    }
    simplify_closed(&outline, OUTLINE_TOLERANCE_MM)
}

/// The nominal parameters of a profile model: those of its outline through its taught nominal points `nominals`
/// (in the profile's plane, in order round it), made sharp at the master's sharp `edges` (a polynomial rounds
/// them, or overshoots their apex by microns, where the contacts of a ball rolling round the edge lie on it);
/// `Err` says why there are none.
pub(crate) fn nominal_parameters(
    model: &impl Implicit<2>,
    nominals: &[Vector2<f64>],
    edges: &[SharpEdge],
) -> Result<SectionParameters, String> {
    section_parameters(
        &sharpen(&nominal_outline(model, nominals), edges),
        &[],
        EDGE_DISTANCE_MM,
    )
    .map_err(|e| format!("its nominal: {e}"))
}

/// The outline of a profile of faces for its parameters: the traced faces, thinned where they are straight (the
/// chord's farthest pair looks at every pair of the outline's points).
pub(crate) fn faces_outline(faces: &FacedProfile) -> Vec<Vector2<f64>> {
    simplify_closed(&faces.outline(), OUTLINE_TOLERANCE_MM)
}

/// One parameter of a section, nominal and measured (in the unit its name gives).
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct ParameterValue {
    pub nominal: f64,
    pub measured: f64,
    /// Measured minus nominal.
    pub deviation: f64,
    /// The limits the deviation is held to, where the part gives the parameter a tolerance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<AppliedTolerance>,
    /// Whether the deviation is within them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict: Option<ParameterVerdict>,
}

impl ParameterValue {
    /// Not yet judged against a tolerance.
    pub(crate) fn of(nominal: f64, measured: f64) -> Self {
        ParameterValue {
            nominal,
            measured,
            deviation: measured - nominal,
            tolerance: None,
            verdict: None,
        }
    }

    /// The mean of each of `values`' nominal and measured; `None` without one.
    pub(crate) fn mean<'a>(values: impl IntoIterator<Item = &'a ParameterValue>) -> Option<Self> {
        let (n, nominal, measured) = values
            .into_iter()
            .fold((0usize, 0.0, 0.0), |(n, nominal, measured), v| {
                (n + 1, nominal + v.nominal, measured + v.measured)
            });
        (n > 0).then(|| ParameterValue::of(nominal / n as f64, measured / n as f64))
    }
}

/// A section's parameters as the report keeps them (`geometry::section_parameters` defines each). Fractions are
/// of the chord from the leading edge; the chord angle is the mean line's chord to +y in the (y, z) plane.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct SectionParametersReport {
    /// How far in from each edge the edge thicknesses are taken, mm.
    pub edge_distance_mm: f64,
    pub chord_mm: ParameterValue,
    pub max_thickness_mm: ParameterValue,
    pub max_thickness_at: ParameterValue,
    pub le_thickness_mm: ParameterValue,
    pub te_thickness_mm: ParameterValue,
    /// The radius of each edge's round (a circle fitted at its tip), where both the nominal's and the scan's are
    /// round; absent at a sharp edge and in older reports.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub le_radius_mm: Option<ParameterValue>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub te_radius_mm: Option<ParameterValue>,
    pub max_camber_mm: ParameterValue,
    pub max_camber_at: ParameterValue,
    pub chord_angle_deg: ParameterValue,
    /// The middle of the mean line's chord (the section's pitch reference point) in the profile plane's axes (y,
    /// z of the part frame), mm: where the section lies, whatever its thickness, camber, chord length or twist
    /// (each leaves the ends of a NACA mean line symmetric about it). Absent in older reports.
    #[serde(default)]
    pub chord_middle_mm: Option<[ParameterValue; 2]>,
    /// The local pitch 2 pi r tan(chord angle), mm: for a propeller's sections (planes at radius r about the hub
    /// axis z); absent for other parts.
    pub pitch_mm: Option<ParameterValue>,
    /// Pass if every parameter with a tolerance is within it; absent where none has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verdict: Option<ParameterVerdict>,
}

impl SectionParametersReport {
    /// The parameters a tolerance can be given on.
    pub(crate) fn judged(&self) -> impl Iterator<Item = (Parameter, &ParameterValue)> {
        [
            (Parameter::Chord, &self.chord_mm),
            (Parameter::MaxThickness, &self.max_thickness_mm),
            (Parameter::LeThickness, &self.le_thickness_mm),
            (Parameter::TeThickness, &self.te_thickness_mm),
            (Parameter::MaxCamber, &self.max_camber_mm),
            (Parameter::ChordAngle, &self.chord_angle_deg),
        ]
        .into_iter()
        .chain(self.le_radius_mm.as_ref().map(|r| (Parameter::LeRadius, r)))
        .chain(self.te_radius_mm.as_ref().map(|r| (Parameter::TeRadius, r)))
        .chain(self.pitch_mm.as_ref().map(|p| (Parameter::Pitch, p)))
    }

    /// The values of those out of tolerance, each with its name (the report's key).
    pub(crate) fn out_of_tolerance(&self) -> Vec<(&'static str, &ParameterValue)> {
        self.judged()
            .filter(|(_, v)| v.verdict == Some(ParameterVerdict::Fail))
            .map(|(parameter, v)| (parameter.key(), v))
            .collect()
    }

    pub(crate) fn judged_mut(&mut self) -> impl Iterator<Item = (Parameter, &mut ParameterValue)> {
        [
            (Parameter::Chord, &mut self.chord_mm),
            (Parameter::MaxThickness, &mut self.max_thickness_mm),
            (Parameter::LeThickness, &mut self.le_thickness_mm),
            (Parameter::TeThickness, &mut self.te_thickness_mm),
            (Parameter::MaxCamber, &mut self.max_camber_mm),
            (Parameter::ChordAngle, &mut self.chord_angle_deg),
        ]
        .into_iter()
        .chain(self.le_radius_mm.as_mut().map(|r| (Parameter::LeRadius, r)))
        .chain(self.te_radius_mm.as_mut().map(|r| (Parameter::TeRadius, r)))
        .chain(self.pitch_mm.as_mut().map(|p| (Parameter::Pitch, p)))
    }
}

/// Stations at most, of each side of a [`SectionDistribution`]: enough to draw the thickness and camber along the
/// chord, few enough to keep every report's file small.
const DISTRIBUTION_STATIONS: usize = 50;

/// A section's thickness and camber along its chord, as the nominal has them and as measured.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct SectionDistribution {
    /// Per station along the mean line, leading edge first: [place along the chord line as a fraction of it from
    /// the leading end, thickness mm (the inscribed circle's diameter), camber mm (the mean line's distance from
    /// its chord line, + on the side the chord turned +90 deg points to)].
    pub nominal: Vec<[f64; 3]>,
    pub measured: Vec<[f64; 3]>,
}

impl SectionDistribution {
    fn of(nominal: &SectionParameters, measured: &SectionParameters) -> Self {
        let stations = |p: &SectionParameters| -> Vec<[f64; 3]> {
            let all: Vec<[f64; 3]> = p
                .mean_line
                .distribution()
                .map(|(a, t, c)| [a, t, c])
                .collect();
            let step = all.len().div_ceil(DISTRIBUTION_STATIONS).max(1);
            all.into_iter().step_by(step).collect()
        };
        SectionDistribution {
            nominal: stations(nominal),
            measured: stations(measured),
        }
    }
}

/// A scanned section's parameters and its thickness and camber along the chord.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionShape {
    pub parameters: SectionParametersReport,
    pub distribution: SectionDistribution,
}

/// A scanned section as its evaluation takes it: the compensated points not flagged, in the part's frame and in
/// scan order round the section, and which of them are contacts of the ball rolling round a sharp edge.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ScannedSection {
    pub points: Vec<Point3<f64>>,
    /// Indices into `points` of the contacts [`Compensated::is_on_a_sharp_edge`] names.
    pub sharp_edge_contacts: Vec<usize>,
}

impl ScannedSection {
    /// Takes the next compensated point (machine frame), unless it is flagged.
    pub fn push(&mut self, point: &Compensated, machine_to_part: &Isometry3<f64>) {
        if point.is_flagged() {
            return;
        }
        if point.is_on_a_sharp_edge() {
            self.sharp_edge_contacts.push(self.points.len());
        }
        self.points.push(machine_to_part * point.surface);
    }
}

/// The parameters of the scanned `section` beside `nominal`'s; `radius_mm` is the section's radius about a
/// propeller's hub axis, if it is one.
pub fn parameters(
    nominal: &SectionParameters,
    section: &ScannedSection,
    radius_mm: Option<f64>,
) -> Result<SectionShape, String> {
    let in_plane: Vec<Vector2<f64>> = section
        .points
        .iter()
        .map(|p| Vector2::new(p.y, p.z))
        .collect();
    let measured = section_parameters(&in_plane, &section.sharp_edge_contacts, EDGE_DISTANCE_MM)
        .map_err(|e| e.to_string())?;
    let value =
        |read: fn(&SectionParameters) -> f64| ParameterValue::of(read(nominal), read(&measured));
    let radius = |read: fn(&SectionParameters) -> Option<f64>| {
        Some(ParameterValue::of(read(nominal)?, read(&measured)?))
    };
    let pitch = |p: &SectionParameters, r: f64| {
        std::f64::consts::TAU * r * p.mean_line.chord_angle_deg.to_radians().tan()
    };
    let parameters = SectionParametersReport {
        edge_distance_mm: EDGE_DISTANCE_MM,
        chord_mm: value(|p| p.chord_mm),
        max_thickness_mm: value(|p| p.max_thickness_mm),
        max_thickness_at: value(|p| p.max_thickness_at),
        le_thickness_mm: value(|p| p.le_thickness_mm),
        te_thickness_mm: value(|p| p.te_thickness_mm),
        le_radius_mm: radius(|p| p.le_radius_mm),
        te_radius_mm: radius(|p| p.te_radius_mm),
        max_camber_mm: value(|p| p.mean_line.max_camber_mm),
        max_camber_at: value(|p| p.mean_line.max_camber_at),
        chord_angle_deg: value(|p| p.mean_line.chord_angle_deg),
        chord_middle_mm: Some([
            value(|p| (p.mean_line.leading_end.x + p.mean_line.trailing_end.x) / 2.0),
            value(|p| (p.mean_line.leading_end.y + p.mean_line.trailing_end.y) / 2.0),
        ]),
        pitch_mm: radius_mm.map(|r| ParameterValue::of(pitch(nominal, r), pitch(&measured, r))),
        verdict: None,
    };
    Ok(SectionShape {
        parameters,
        distribution: SectionDistribution::of(nominal, &measured),
    })
}

/// How far a blade is turned about the hub axis from its place (deg, in the sense of the instances' step), from
/// its sections' `(radius_mm, tangential_shift_mm)` (of each chord's middle): the least-squares turn `sum(r s) / sum(r^2)` (radians) of a
/// shift that grows as r tan(turn), through the axis. `None` without a section.
pub(crate) fn index_deg(sections: &[(f64, f64)]) -> Option<f64> {
    let (rs, rr) = sections
        .iter()
        .fold((0.0, 0.0), |(rs, rr), (r, s)| (rs + r * s, rr + r * r));
    (rr > 0.0).then(|| (rs / rr).atan().to_degrees())
}

/// The angular spacing of each blade from the one before it (deg, nominal `|step_deg|`), from each blade's turn
/// off its place in the step's sense ([`index_deg`]); the first blade's is from the last, where the blades go once
/// round the axis (`step_deg` times their number a full turn), and `None` otherwise or where either turn is
/// unknown.
pub(crate) fn angular_spacings(
    index: &[Option<f64>],
    step_deg: f64,
) -> Vec<Option<ParameterValue>> {
    let n = index.len();
    let step_deg = step_deg.abs();
    let full_turn = (n as f64 * step_deg - 360.0).abs() < 1e-9;
    (0..n)
        .map(|k| {
            let before = match k {
                0 if full_turn && n > 1 => n - 1,
                0 => return None,
                _ => k - 1,
            };
            let (this, previous) = (index[k]?, index[before]?);
            Some(ParameterValue::of(step_deg, step_deg + this - previous))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_blade_turned_about_the_hub_shifts_its_sections_by_r_tan_turn() {
        let turn = 0.05f64.to_radians();
        let sections: Vec<(f64, f64)> = [100.0, 200.0, 300.0, 400.0, 500.0]
            .into_iter()
            .map(|r| (r, r * turn.tan()))
            .collect();
        let read = index_deg(&sections).unwrap();
        assert!((read - 0.05).abs() < 1e-12, "{read}");
        // A shift that does not grow with the radius (a blade moved, not turned) reads as the turn that fits it
        // best through the axis, weighted to the tip.
        let moved: Vec<(f64, f64)> = sections.iter().map(|(r, _)| (*r, 0.1)).collect();
        let expected = (0.1 * 1500.0 / 550_000.0f64).atan().to_degrees();
        assert!((index_deg(&moved).unwrap() - expected).abs() < 1e-12);
        assert_eq!(index_deg(&[]), None);
    }

    #[test]
    fn spacings_go_from_each_blade_to_the_next_and_round_from_the_last_to_the_first() {
        let spacings = angular_spacings(&[Some(0.0), Some(-0.02), Some(0.05)], 120.0);
        let measured: Vec<f64> = spacings.iter().map(|s| s.unwrap().measured).collect();
        for (m, e) in measured.iter().zip([119.95, 119.98, 120.07]) {
            assert!((m - e).abs() < 1e-9, "{measured:?}");
        }
        assert!(spacings.iter().all(|s| s.unwrap().nominal == 120.0));
        assert!((spacings[2].unwrap().deviation - 0.07).abs() < 1e-9);
        // Stepping clockwise reads the same magnitudes.
        let clockwise = angular_spacings(&[Some(0.0), Some(0.01)], -180.0);
        assert_eq!(clockwise[1].unwrap().nominal, 180.0);
        assert!((clockwise[1].unwrap().measured - 180.01).abs() < 1e-9);
        // Four nuts 90 deg apart on a tray that does not close: no spacing for the first; an unknown turn leaves
        // both of its spacings out.
        let open = angular_spacings(&[Some(0.0), None, Some(0.0)], 90.0);
        assert_eq!(open, vec![None, None, None]);
    }
}
