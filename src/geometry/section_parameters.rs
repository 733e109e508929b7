//! A blade section's parameters from its closed outline (points in the section plane, in order round it), as
//! blade software names them: the chord (nose to tail), the maximum thickness as the diameter of the largest
//! inscribed circle and where along the chord it lies, the thickness near each edge, and the mean line with its
//! camber and chord angle.
//!
//! The chord's length is well conditioned (it is the largest distance, stationary at its ends), but where its
//! ends lie across a round nose is not: sliding both ends sideways by d shortens it by only about d^2 / (2 r) for
//! ends of radius r, so a sparse scan of a thick section (seed 003's profile 3, 400 points) puts the line between
//! the two farthest points 0.67 mm off its dense nominal's. The camber and the chord's angle are therefore taken
//! from the mean line, whose ends are fixed by the faces: see [`MeanLine`].
//!
//! Definitions (each measured the same way on the scanned section and on the nominal, so that their differences
//! are the errors):
//! - Between its points the outline is the centripetal Catmull-Rom curve through them.
//! - The nose and tail are the two outline points farthest apart, each moved, where the edge is round (see the
//!   edge radius below), to the peak of a quartic fitted across the points within 50 deg of its tip (a scan's
//!   points step round a nose, each with the probe's noise; where they are too few, to the farthest reach of the
//!   smooth outline beside the farthest point), or where it is sharp and the scan's compensation names the
//!   contacts of its ball rolling round it, to their mean; the chord joins them. The
//!   leading edge is the blunter end: the one whose section is thicker at `EDGE_PROBE` of the chord in from it (an
//!   airfoil's round nose against its thin tail).
//! - Stations run along the chord from the leading edge: at station `s` the line across the section perpendicular
//!   to the chord meets the outline on both faces; the section's thickness there is the length between them.
//! - The maximum thickness: the diameter of the largest circle inside the outline, found among the circles
//!   centred on each station's line (every inside point lies on one station's line): the peak of a quartic fitted
//!   to their diameters about the best station, where it follows them (see [`PEAK_SPAN`]), else the best station
//!   refined.
//! - An edge's radius: the circle fitted (orthogonal distances) to the outline's points within the edge's own
//!   radius' [`EDGE_ZONE_DEPTH`] of its tip along the chord (at most half the edge distance; the zone is settled
//!   by refitting), so that on a round end it is the round's circle; none where the points there are too few, span
//!   less than [`EDGE_MIN_SPAN_DEG`] of it or stray from it by more than [`EDGE_ROUNDNESS`] of its radius (a
//!   sharp edge, a square-cut one).
//! - The mean line: the centres of those circles where they touch both faces; its ends, where it meets the outline;
//!   the chord line joining them; the maximum camber, the mean line's largest distance from that chord line; the
//!   chord angle, the chord line's direction in the outline's plane (for a propeller's section in the plane of
//!   the station's y and z, its angle to the plane of rotation).
//!
//! Why written here: the one crate that finds a polygon's largest inscribed circle (polylabel) brings the geo
//! stack for one function, and the stations' lines give the edge thicknesses besides.

use nalgebra::Vector2;

use super::circle::{fit_circle, Circle};
use super::trace::inside_closed;

/// Where the ends are told apart: thickness this fraction of the chord in from each end.
const EDGE_PROBE: f64 = 0.05;
/// Stations along the chord at which the inscribed circles are sampled before the largest is refined.
const STATIONS: usize = 200;
/// The maximum thickness is the peak of a polynomial of this degree fitted to the inscribed circles' diameters
/// within this fraction of the chord either side of the largest: the largest of the noisy diameters themselves
/// picks the station where the faces' noise happens to widen the section (2 um noise on points 1 mm apart read
/// NACA sections up to 8 um thick over 40 draws; the fitted peak, 3 um). Not the camber's: a NACA mean line's
/// curvature jumps at its maximum, which a quartic rounds off, reading the camber 1-2 um low.
const PEAK_SPAN: f64 = 0.1;
const PEAK_DEGREE: usize = 4;
/// The fitted peak is taken only where the polynomial follows the samples this closely (RMS, mm): over a smooth peak
/// its misfit is well under a micron and the residual is the scan's noise, microns. Where the largest circle
/// touches a third point (seed 003's thick profiles, their noses) the diameters peak in a corner, which the
/// quartic misses by 0.6 mm RMS and overshoots; there the largest station, refined, is the maximum.
const PEAK_MAX_RESIDUAL_MM: f64 = 0.005;
/// Samples at least within the span, for a fitted peak.
const PEAK_MIN_SAMPLES: usize = 12;
/// The golden-section searches stop below this, mm.
const SEARCH_TOLERANCE_MM: f64 = 1e-7;
/// An edge is round where its points lie this close to their circle (RMS, as a fraction of its radius): a NACA
/// nose within its own radius of the tip, scanned with 2 um noise, stays under 0.5 %.
const EDGE_ROUNDNESS: f64 = 0.02;
/// An edge's circle is taken from points spanning at least this much of it.
const EDGE_MIN_SPAN_DEG: f64 = 60.0;
/// An edge's circle is fitted to the points within this fraction of its radius of the tip (along the chord): a
/// span of 83 deg. A NACA nose bends away from its osculating circle at first order: over its whole radius the
/// fitted circle is 18 % wider than the osculating one, over a quarter 6 % (the unit tests).
const EDGE_ZONE_DEPTH: f64 = 0.25;
/// A sharp edge's contacts lie within about 12 um of its apex (2 um noise; the compensation's tests): those this
/// close to the end's farthest point are its tip's estimates.
const SHARP_TIP_REACH_MM: f64 = 0.03;
/// A round end's tip is fitted to the points within this angle of it (on the edge's circle), by a polynomial of
/// this degree, from at least this many points; its peak is looked for among this many places across them first.
/// Over 50 deg the quartic is off a NACA nose's tip by 0.4 um at most; over 35 deg it averages less of the noise
/// (0.7 against 0.6 um at 2.5 deg steps), a quadratic is off by 1-6 um (BENCHMARKS.md, issue 16).
const NOSE_SPAN_DEG: f64 = 50.0;
const NOSE_DEGREE: usize = 4;
const NOSE_MIN_POINTS: usize = 9;
const NOSE_LOOKS: usize = 64;
/// A face crossed by a station's line is fitted to its points within this distance of the crossing (mm) ...
const FACE_FIT_REACH_MM: f64 = 5.0;
/// ... or within half as far, and so on down to this, until it turns by at most ...
const FACE_FIT_MIN_REACH_MM: f64 = 0.5;
/// ... this from the crossed segment's direction (deg) ...
const FACE_FIT_MAX_TURN_DEG: f64 = 3.0;
/// ... from at least this many points (else the smooth outline through the points is crossed).
const FACE_FIT_MIN_POINTS: usize = 5;
/// The spacing of the smooth outline an edge's circle is fitted to, mm: fine enough that the zone's cut moves a NACA
/// nose's circle by under 0.3 um (5 um spacing: 0.7 um).
const SMOOTH_SPACING_MM: f64 = 0.002;
/// Steps along each segment per spacing, between which its points are placed.
const SMOOTH_STEPS_PER_SPACING: usize = 4;
/// Fits by which the zone is settled.
const EDGE_ZONE_ROUNDS: usize = 3;
/// Points at least, for an edge's circle.
const EDGE_MIN_POINTS: usize = 5;
/// Stations along the chord at which the mean line is sampled.
const MEAN_LINE_STATIONS: usize = 400;
/// A station's inscribed circle is a point of the mean line when it keeps this fraction of the chord clear of
/// both ends along the chord: inside an end's own round (a nose of radius r, up to r from its tip) the largest
/// circle on a station's line touches the round alone, and its centre follows the station's line, not the faces.
const END_CLEARANCE: f64 = 0.02;
/// The stretch of the mean line, as a fraction of the chord from its first (last) point, through which a parabola
/// is fitted and followed out to the edge: long enough that the faces' noise averages out. A NACA 4-digit mean
/// line is a parabola from the nose to its maximum camber (at 20-70 % of the chord) and from there to the tail,
/// so the fit holds it exactly there.
const END_STRETCH: f64 = 0.25;

/// A section's parameters, mm and degrees.
#[derive(Debug, Clone, PartialEq)]
pub struct SectionParameters {
    pub leading_edge: Vector2<f64>,
    pub trailing_edge: Vector2<f64>,
    pub chord_mm: f64,
    /// The diameter of the largest inscribed circle.
    pub max_thickness_mm: f64,
    /// Its centre's station, as a fraction of the chord from the leading edge.
    pub max_thickness_at: f64,
    /// The thickness across the chord at the given distance in from the leading edge ...
    pub le_thickness_mm: f64,
    /// ... and in from the trailing edge.
    pub te_thickness_mm: f64,
    /// The leading edge's radius, if it is round ...
    pub le_radius_mm: Option<f64>,
    /// ... and the trailing edge's.
    pub te_radius_mm: Option<f64>,
    pub mean_line: MeanLine,
}

/// The mean (camber) line: the centres of the circles inscribed in the section, each touching both faces, from
/// the leading to the trailing edge (stations whose circles keep [`END_CLEARANCE`] clear of both ends); its ends
/// are a sharp edge's tip, or where it meets a round edge's outline, followed out as a parabola through its first
/// or last [`END_STRETCH`]. The line joining those ends is the chord line of blade software, from which
/// camber and chord angle are measured.
#[derive(Debug, Clone, PartialEq)]
pub struct MeanLine {
    /// Inscribed circles' centres at stations along the chord, leading edge first.
    pub points: Vec<Vector2<f64>>,
    /// ... and their diameters, the section's thickness there (mm).
    pub thicknesses_mm: Vec<f64>,
    pub leading_end: Vector2<f64>,
    pub trailing_end: Vector2<f64>,
    /// The largest distance of the mean line from its chord line, + on the side the chord turned +90 deg points
    /// to (mm) ...
    pub max_camber_mm: f64,
    /// ... and where along the chord line, as a fraction of it from the leading end.
    pub max_camber_at: f64,
    /// The chord line's direction, leading to trailing end, from the outline's first axis towards its second
    /// (deg, in (-180, 180]).
    pub chord_angle_deg: f64,
}

/// The smooth outline through `outline`'s points (its Catmull-Rom segments, chords where points coincide) sampled
/// every [`SMOOTH_SPACING_MM`] or so along it, on each segment that has a point within `zone` of `depth`.
fn smooth_outline_within(
    outline: &[Vector2<f64>],
    zone: f64,
    depth: impl Fn(&Vector2<f64>) -> f64,
) -> Vec<Vector2<f64>> {
    let n = outline.len();
    let mut smooth: Vec<Vector2<f64>> = Vec::new();
    // Points every spacing of the way along the outline, each stretch then weighing by its length however the
    // outline's own points crowd (a dense outline's round a nose, a scan's 2.5-deg steps): placed between fine
    // steps along each segment, `to_next` ahead of the last.
    let mut to_next = 0.0;
    for i in 0..n {
        let (a, b) = (outline[i], outline[(i + 1) % n]);
        if depth(&a) > zone && depth(&b) > zone {
            to_next = 0.0;
            continue;
        }
        let steps = ((b - a).norm() * SMOOTH_STEPS_PER_SPACING as f64 / SMOOTH_SPACING_MM)
            .ceil()
            .max(1.0) as usize;
        let segment = CatmullRom::through(outline, i);
        let at = |t: f64| segment.as_ref().map_or(a + (b - a) * t, |s| s.at(t));
        let mut from = a;
        for k in 1..=steps {
            let to = at(k as f64 / steps as f64);
            let length = (to - from).norm();
            let mut along = 0.0;
            while to_next <= length - along {
                along += to_next;
                smooth.push(from + (to - from) * (along / length));
                to_next = SMOOTH_SPACING_MM;
            }
            to_next -= length - along;
            from = to;
        }
    }
    smooth
}

impl MeanLine {
    /// Each point's (place along the chord line as a fraction of it from the leading end, thickness mm, camber mm:
    /// its distance from the chord line, signed as [`MeanLine::max_camber_mm`]).
    pub fn distribution(&self) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
        let chord = self.trailing_end - self.leading_end;
        let along = chord.normalize();
        let normal = Vector2::new(-along.y, along.x);
        self.points
            .iter()
            .zip(&self.thicknesses_mm)
            .map(move |(c, &thickness)| {
                let d = c - self.leading_end;
                (d.dot(&along) / chord.norm(), thickness, d.dot(&normal))
            })
    }
}

/// Why a section has no parameters.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(crate) enum ParameterError {
    #[error("{0} points are too few to outline a section")]
    TooFewPoints(usize),
    #[error("the line across the section {0:.3} mm from its leading edge does not cross both faces: is the outline closed, in order round the section?")]
    OpenAt(f64),
    #[error("no circle inside the section touches both faces away from its ends (chord {0:.3} mm): it has no mean line")]
    NoMeanLine(f64),
}

/// The parameters of the closed outline `outline` (in order round it; the last point joins the first), with the
/// edge thicknesses taken `edge_distance_mm` in from each edge. `sharp_edge_contacts` are the indices of the
/// points that are contacts of a ball rolling round a sharp edge (the compensation's), none for a nominal outline.
pub(crate) fn section_parameters(
    outline: &[Vector2<f64>],
    sharp_edge_contacts: &[usize],
    edge_distance_mm: f64,
) -> Result<SectionParameters, ParameterError> {
    if outline.len() < 4 {
        return Err(ParameterError::TooFewPoints(outline.len()));
    }
    let (a, b) = farthest_pair(outline);
    let chord_mm = (b - a).norm();
    let thickness_in_from = |from: Vector2<f64>, to: Vector2<f64>| {
        Across::new(outline, sharp_edge_contacts, from, to).thickness_at(EDGE_PROBE * chord_mm)
    };
    let (leading_edge, trailing_edge) = if thickness_in_from(a, b)? >= thickness_in_from(b, a)? {
        (a, b)
    } else {
        (b, a)
    };
    // A round end's tip is the peak of the nose fitted to the points round it (see `round_tip`), or where they
    // are too few, the smooth outline's farthest reach beside the farthest point. The edge thicknesses are taken
    // from the moved ends.
    let inward = (trailing_edge - leading_edge).normalize();
    let zone_mm = edge_distance_mm / 2.0;
    let le_circle = edge_circle(outline, leading_edge, inward, zone_mm);
    let te_circle = edge_circle(outline, trailing_edge, -inward, zone_mm);
    // A sharp end scanned by a rolling ball has many contacts, all noisy estimates of its apex: the farthest of
    // them stands a few microns proud (the trailing edges of the simulated blades read 1-5 um long, +2.7 um on
    // average), their mean does not.
    // Each end's tip, and whether it is known sharp: the apex of a roll's contacts, or a corner of the outline. An
    // end with no circle found that is neither (a round nose scanned too sparsely for its circle) is not.
    let to_tip = |end: Vector2<f64>, circle: Option<&Circle>, outward: Vector2<f64>| match circle {
        Some(circle) => (
            round_tip(outline, end, outward, circle.radius)
                .unwrap_or_else(|| end + outward * smooth_reach_beyond(outline, end, outward)),
            false,
        ),
        None => match roll_apex(outline, sharp_edge_contacts, end) {
            Some(apex) => (apex, true),
            None => (end, is_corner(outline, end, -outward)),
        },
    };
    let (leading_edge, le_sharp) = to_tip(leading_edge, le_circle.as_ref(), -inward);
    let (trailing_edge, te_sharp) = to_tip(trailing_edge, te_circle.as_ref(), inward);
    let chord_mm = (trailing_edge - leading_edge).norm();
    let across = Across::new(outline, sharp_edge_contacts, leading_edge, trailing_edge);
    let le_thickness_mm = across.thickness_at(edge_distance_mm)?;
    let te_thickness_mm = across.thickness_at(chord_mm - edge_distance_mm)?;
    // The inscribed circles at stations along the chord (the ends themselves have no width); the largest is the
    // peak of the polynomial fitted to their diameters about the best station (see `PEAK_SPAN`), or where that has
    // none, the best station's refined.
    let diameters = (1..STATIONS)
        .map(|k| {
            let s = chord_mm * k as f64 / STATIONS as f64;
            across.inscribed_at(s).map(|radius| (s, 2.0 * radius))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let best =
        diameters.iter().copied().fold(
            (0.0, f64::NEG_INFINITY),
            |a, b| if b.1 > a.1 { b } else { a },
        );
    let (station, max_thickness_mm) = match fitted_peak(&diameters, best.0, PEAK_SPAN * chord_mm) {
        Some(peak) => peak,
        None => {
            let step = chord_mm / STATIONS as f64;
            let (low, high) = (best.0 - step, best.0 + step);
            let mut failure = None;
            let station = golden_max(low.max(0.0), high.min(chord_mm), |s| {
                across.inscribed_at(s).unwrap_or_else(|e| {
                    failure = Some(e);
                    f64::NEG_INFINITY
                })
            });
            if let Some(error) = failure {
                return Err(error);
            }
            (station, 2.0 * across.inscribed_at(station)?)
        }
    };
    // A sharp end is the mean line's end itself (a NACA section's closed trailing edge is where its mean line
    // ends); a round one's end is found by following the mean line out.
    let sharp_ends = [
        le_sharp.then_some(leading_edge),
        te_sharp.then_some(trailing_edge),
    ];
    let mean_line = MeanLine::of(&across, chord_mm, sharp_ends)?;
    Ok(SectionParameters {
        leading_edge,
        trailing_edge,
        chord_mm,
        max_thickness_mm,
        max_thickness_at: station / chord_mm,
        le_thickness_mm,
        te_thickness_mm,
        le_radius_mm: le_circle.map(|c| c.radius),
        te_radius_mm: te_circle.map(|c| c.radius),
        mean_line,
    })
}

/// The circle of the edge at `tip` whose section lies towards `inward` (unit), if the edge is round: see the
/// module's definition of an edge's radius.
fn edge_circle(
    outline: &[Vector2<f64>],
    tip: Vector2<f64>,
    inward: Vector2<f64>,
    zone_mm: f64,
) -> Option<Circle> {
    let depth = |p: &Vector2<f64>| (p - tip).dot(&inward);
    // The circle is fitted to the smooth outline through the points, sampled evenly along it and cut at the zone's
    // depth, not to the points themselves: on a nose that is not a circle (a NACA nose's curvature falls away from
    // the tip), the points a scan happens to put in the zone, and how they crowd, moved the circle. Noise-free NACA
    // 4412 noses of 150 mm stepped 2.5 deg from random phases read their radius 17 um apart (sd), and 15 um
    // narrower than their dense outline, through their points; along the smooth outline, 0.6 um apart.
    let smooth = smooth_outline_within(outline, zone_mm, depth);
    let within = |zone: f64| -> Vec<Vector2<f64>> {
        smooth
            .iter()
            .copied()
            .filter(|p| depth(p) <= zone)
            .collect()
    };
    // The zone shrinks to its share of the radius found in it; a few rounds settle it.
    let mut circle = fit_circle(&within(zone_mm))?;
    let mut points = Vec::new();
    for _ in 0..EDGE_ZONE_ROUNDS {
        let zone = zone_mm.min(EDGE_ZONE_DEPTH * circle.radius);
        if outline.iter().filter(|p| depth(p) <= zone).count() < EDGE_MIN_POINTS {
            return None;
        }
        points = within(zone);
        circle = fit_circle(&points)?;
    }
    // The span: the points' angles about the centre, from the direction out through the tip.
    let out = -inward;
    let angle = |p: &Vector2<f64>| {
        let d = p - circle.centre;
        (out.x * d.y - out.y * d.x).atan2(out.dot(&d))
    };
    let (low, high) = points
        .iter()
        .map(angle)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), a| {
            (l.min(a), h.max(a))
        });
    let round = circle.rms_mm <= EDGE_ROUNDNESS * circle.radius;
    (round && (high - low).to_degrees() >= EDGE_MIN_SPAN_DEG).then_some(circle)
}

impl MeanLine {
    /// `sharp_ends`: the leading and trailing edges' tips where they are sharp, which are the line's ends.
    fn of(
        across: &Across,
        chord_mm: f64,
        sharp_ends: [Option<Vector2<f64>>; 2],
    ) -> Result<MeanLine, ParameterError> {
        let clear = END_CLEARANCE * chord_mm;
        let mut centres = Vec::new();
        let mut thicknesses_mm = Vec::new();
        // In the chord's frame: x along the chord from the leading edge, y across it.
        let mut local = Vec::new();
        for k in 1..MEAN_LINE_STATIONS {
            let s = chord_mm * k as f64 / MEAN_LINE_STATIONS as f64;
            let (centre, radius) = across.inscribed_circle_at(s)?;
            if s - radius > clear && chord_mm - s - radius > clear {
                let d = centre - across.origin;
                centres.push(centre);
                thicknesses_mm.push(2.0 * radius);
                local.push((d.dot(&across.along), d.dot(&across.normal)));
            }
        }
        let too_few = || ParameterError::NoMeanLine(chord_mm);
        let (first, last) = match (local.first(), local.last()) {
            (Some(first), Some(last)) => (first.0, last.0),
            _ => return Err(too_few()),
        };
        let stretch = END_STRETCH * chord_mm;
        // The mean line's end beyond `from` (its first or last point), the parabola through the points within
        // the stretch of it followed outward to where it leaves the section.
        let end = |from: f64, outward: f64| -> Result<Vector2<f64>, ParameterError> {
            let near: Vec<(f64, f64)> = local
                .iter()
                .copied()
                .filter(|(x, _)| (x - from).abs() <= stretch)
                .collect();
            let parabola = fit_polynomial(&near, 2).ok_or_else(too_few)?;
            let at = |x: f64| across.origin + across.along * x + across.normal * parabola(x);
            let step = 2e-3 * chord_mm * outward;
            let mut inside = from;
            let mut outside = None;
            for k in 1..=500 {
                let x = from + step * k as f64;
                if !inside_closed(across.outline, &at(x)) {
                    outside = Some(x);
                    break;
                }
                inside = x;
            }
            let mut outside = outside.ok_or(ParameterError::OpenAt(from))?;
            while (outside - inside).abs() > SEARCH_TOLERANCE_MM {
                let middle = (inside + outside) / 2.0;
                if inside_closed(across.outline, &at(middle)) {
                    inside = middle;
                } else {
                    outside = middle;
                }
            }
            Ok(at((inside + outside) / 2.0))
        };
        let leading_end = sharp_ends[0].map_or_else(|| end(first, -1.0), Ok)?;
        let trailing_end = sharp_ends[1].map_or_else(|| end(last, 1.0), Ok)?;
        let chord = trailing_end - leading_end;
        let (along, normal) = (
            chord.normalize(),
            Vector2::new(-chord.y, chord.x).normalize(),
        );
        let (mut max_camber_mm, mut max_camber_at) = (0.0f64, 0.0);
        for c in &centres {
            let camber = (c - leading_end).dot(&normal);
            if camber.abs() > max_camber_mm.abs() {
                max_camber_mm = camber;
                max_camber_at = (c - leading_end).dot(&along) / chord.norm();
            }
        }
        Ok(MeanLine {
            points: centres,
            thicknesses_mm,
            leading_end,
            trailing_end,
            max_camber_mm,
            max_camber_at,
            chord_angle_deg: chord.y.atan2(chord.x).to_degrees(),
        })
    }
}

/// The least-squares polynomial of `degree` through `points`, as a function; `None` for fewer points than
/// coefficients.
fn fit_polynomial(points: &[(f64, f64)], degree: usize) -> Option<impl Fn(f64) -> f64> {
    let terms = degree + 1;
    if points.len() < terms {
        return None;
    }
    // Centred and scaled in x so the system stays well conditioned at any chord.
    let n = points.len() as f64;
    let mid = points.iter().map(|p| p.0).sum::<f64>() / n;
    let scale = points
        .iter()
        .map(|p| (p.0 - mid).abs())
        .fold(0.0, f64::max)
        .max(1e-300);
    let rows = nalgebra::DMatrix::from_fn(points.len(), terms, |i, j| {
        ((points[i].0 - mid) / scale).powi(j as i32)
    });
    let values = nalgebra::DVector::from_iterator(points.len(), points.iter().map(|p| p.1));
    let coefficients = rows.svd(true, true).solve(&values, 1e-12).ok()?;
    Some(move |x: f64| {
        let t = (x - mid) / scale;
        coefficients.iter().rev().fold(0.0, |sum, c| sum * t + c)
    })
}

/// Where the polynomial of [`PEAK_DEGREE`] fitted to `samples` (place, value) within `half_span` of `around`
/// peaks, and its value there: `None` if the samples there are too few, its largest value lies at the window's
/// edge (no peak inside it) or it does not follow them (see [`PEAK_MAX_RESIDUAL_MM`]).
fn fitted_peak(samples: &[(f64, f64)], around: f64, half_span: f64) -> Option<(f64, f64)> {
    let near: Vec<(f64, f64)> = samples
        .iter()
        .copied()
        .filter(|(x, _)| (x - around).abs() <= half_span)
        .collect();
    if near.len() < PEAK_MIN_SAMPLES {
        return None;
    }
    let (low, high) = (near[0].0, near[near.len() - 1].0);
    let curve = fit_polynomial(&near, PEAK_DEGREE)?;
    let at = golden_max(low, high, &curve);
    let inside = at - low > SEARCH_TOLERANCE_MM * 10.0 && high - at > SEARCH_TOLERANCE_MM * 10.0;
    let residual_mm = (near
        .iter()
        .map(|(x, y)| (y - curve(*x)).powi(2))
        .sum::<f64>()
        / near.len() as f64)
        .sqrt();
    let follows = residual_mm <= PEAK_MAX_RESIDUAL_MM;
    (inside && follows).then(|| (at, curve(at)))
}

/// The two points farthest apart (all pairs: a section of a few thousand points takes milliseconds).
pub(crate) fn farthest_pair(points: &[Vector2<f64>]) -> (Vector2<f64>, Vector2<f64>) {
    let mut best = (0.0, points[0], points[0]);
    for (i, a) in points.iter().enumerate() {
        for b in &points[i + 1..] {
            let d = (a - b).norm_squared();
            if d > best.0 {
                best = (d, *a, *b);
            }
        }
    }
    (best.1, best.2)
}

/// Where a station's line crosses the outline: the index of the point starting the outline's segment it crosses,
/// and its offset from the chord there (mm).
#[derive(Clone, Copy)]
struct Crossing {
    segment: usize,
    offset: f64,
}

/// Lines across the section, perpendicular to its chord, at stations measured from the leading edge.
struct Across<'a> {
    outline: &'a [Vector2<f64>],
    /// The outline's points that are contacts of a ball rolling round a sharp edge: a face's fit stops at them.
    contacts: &'a [usize],
    origin: Vector2<f64>,
    /// Unit, along the chord.
    along: Vector2<f64>,
    /// Unit, the chord turned +90 deg.
    normal: Vector2<f64>,
}

impl<'a> Across<'a> {
    fn new(
        outline: &'a [Vector2<f64>],
        contacts: &'a [usize],
        from: Vector2<f64>,
        to: Vector2<f64>,
    ) -> Self {
        let along = (to - from).normalize();
        Across {
            outline,
            contacts,
            origin: from,
            along,
            normal: Vector2::new(-along.y, along.x),
        }
    }

    /// The outermost offsets (from the chord) at which the station's line meets the outline.
    fn faces_at(&self, s: f64) -> Result<(f64, f64), ParameterError> {
        self.crossings_at(s)
            .map(|(low, high)| (low.offset, high.offset))
    }

    /// The outermost crossings of the station's line with the outline, lower first.
    fn crossings_at(&self, s: f64) -> Result<(Crossing, Crossing), ParameterError> {
        let (mut low, mut high) = (
            Crossing {
                segment: 0,
                offset: f64::INFINITY,
            },
            Crossing {
                segment: 0,
                offset: f64::NEG_INFINITY,
            },
        );
        let n = self.outline.len();
        for i in 0..n {
            let p = self.outline[i] - self.origin;
            let q = self.outline[(i + 1) % n] - self.origin;
            let (sp, sq) = (p.dot(&self.along) - s, q.dot(&self.along) - s);
            if sp == sq || (sp > 0.0) == (sq > 0.0) && sp != 0.0 && sq != 0.0 {
                continue;
            }
            // Where the smooth outline through the points crosses the line, between these two of them: the
            // chord between points a scan takes 10 deg apart round a 2.5 mm nose cuts 9.5 um inside it, which put
            // the leading-edge thickness 2 mm in 14-24 um thin on every blade (the dense nominal has no such cut).
            let crossing = match CatmullRom::through(self.outline, i) {
                Some(segment) => {
                    let along = |t: f64| (segment.at(t) - self.origin).dot(&self.along) - s;
                    segment.at(bisect(along, sp, sq)) - self.origin
                }
                None => p + (q - p) * (sp / (sp - sq)),
            };
            let here = Crossing {
                segment: i,
                offset: crossing.dot(&self.normal),
            };
            if here.offset < low.offset {
                low = here;
            }
            if here.offset > high.offset {
                high = here;
            }
        }
        if low.offset < high.offset {
            Ok((low, high))
        } else {
            Err(ParameterError::OpenAt(s))
        }
    }

    /// The thickness at station `s`: between the two faces, each crossed where the curve fitted to its points
    /// about the line crosses it (see [`Across::face_offset`]).
    fn thickness_at(&self, s: f64) -> Result<f64, ParameterError> {
        let (low, high) = self.crossings_at(s)?;
        let face = |crossing: Crossing| {
            self.face_offset(crossing.segment, s)
                .unwrap_or(crossing.offset)
        };
        Ok(face(high) - face(low))
    }

    /// The offset from the chord at which the face through the outline's segment from point `i` crosses the line
    /// of station `s`, read from the quadratic fitted to the face's points about it (in the segment's own frame):
    /// those within a reach of the segment's middle over which the face turns by at most
    /// [`FACE_FIT_MAX_TURN_DEG`], the reach halved from [`FACE_FIT_REACH_MM`] until it does. `None` where no reach
    /// holds [`FACE_FIT_MIN_POINTS`] such points.
    ///
    /// Why a fit: the smooth outline through the points passes through each point's noise, so a face's crossing
    /// carried a point's 2 um of noise and a thickness both faces': 2.6 um RMS 2 mm in from the trailing edge over
    /// 300 draws of NACA sections scanned with 2 um of noise, where the fitted faces read 1.5 um. Why so nearly
    /// straight a stretch: a scan and its dense nominal are read alike only where the quadratic follows the face on
    /// both, whatever their points' spacing. Over 30 deg of a round nose's turn (its curvature growing tenfold
    /// towards the tip) the scan's sparse points read the leading-edge thickness 33-39 um thin, over 10-15 deg
    /// still 0.6-3.2 um thick on average, and over 5 deg a noise-free ellipse's 0.07 um thin a face; a cubic
    /// narrowed the leading edge's spread only from 3.1 to 2.6-2.8 um and widened the trailing edge's to 2.0. So 2
    /// mm in from a nose the face is crossed through its points, as before.
    fn face_offset(&self, i: usize, s: f64) -> Option<f64> {
        let n = self.outline.len();
        let next = (i + 1) % n;
        let tangent = (self.outline[next] - self.outline[i]).try_normalize(0.0)?;
        let centre = (self.outline[i] + self.outline[next]) / 2.0;
        let across = Vector2::new(-tangent.y, tangent.x);
        // The face's points each way from the segment, in order, up to the farthest reach: not past a sharp edge's
        // roll contacts, nor round a corner of the outline.
        let corner = CORNER_MAX_DEG.to_radians().cos();
        let mut sides: [Vec<Vector2<f64>>; 2] = [Vec::new(), Vec::new()];
        for (side, (start, step)) in sides.iter_mut().zip([(i, n - 1), (next, 1)]) {
            let mut at = start;
            for _ in 0..n {
                let p = self.outline[at];
                if self.contacts.contains(&at) || (p - centre).norm() > FACE_FIT_REACH_MM {
                    break;
                }
                if let [.., before, last] = side.as_slice() {
                    let (d0, d1) = (last - before, p - last);
                    if d1.dot(&d0) < corner * d0.norm() * d1.norm() {
                        break;
                    }
                }
                if side.last() != Some(&p) {
                    side.push(p);
                }
                at = (at + step) % n;
            }
        }
        let cos_max = FACE_FIT_MAX_TURN_DEG.to_radians().cos();
        let mut reach = FACE_FIT_REACH_MM;
        let face: Vec<Vector2<f64>> = loop {
            if reach < FACE_FIT_MIN_REACH_MM {
                return None;
            }
            let within = |side: &Vec<Vector2<f64>>| -> Vec<Vector2<f64>> {
                side.iter()
                    .copied()
                    .take_while(|p| (p - centre).norm() <= reach)
                    .collect()
            };
            let (before, after) = (within(&sides[0]), within(&sides[1]));
            let face: Vec<Vector2<f64>> = before.into_iter().rev().chain(after).collect();
            let straight = face.windows(2).all(|w| {
                let d = w[1] - w[0];
                d.dot(&tangent) >= cos_max * d.norm()
            });
            if straight {
                break face;
            }
            reach /= 2.0;
        };
        if face.len() < FACE_FIT_MIN_POINTS {
            return None;
        }
        let local: Vec<(f64, f64)> = face
            .iter()
            .map(|p| (p - centre).dot(&tangent))
            .zip(face.iter().map(|p| (p - centre).dot(&across)))
            .collect();
        let curve = fit_polynomial(&local, 2)?;
        let (low, high) = (local[0].0, local[local.len() - 1].0);
        let point = |u: f64| centre + tangent * u + across * curve(u) - self.origin;
        let station = |u: f64| point(u).dot(&self.along) - s;
        let (f0, f1) = (station(low), station(high));
        if f0 == f1 || (f0 > 0.0) == (f1 > 0.0) && f0 != 0.0 && f1 != 0.0 {
            return None;
        }
        let t = bisect(|t| station(low + (high - low) * t), f0, f1);
        Some(point(low + (high - low) * t).dot(&self.normal))
    }

    /// The radius of the largest circle centred on the station's line inside the outline.
    fn inscribed_at(&self, s: f64) -> Result<f64, ParameterError> {
        self.inscribed_circle_at(s).map(|(_, radius)| radius)
    }

    /// The centre and radius of that circle: away from the edges it touches both faces, a point of the mean line.
    fn inscribed_circle_at(&self, s: f64) -> Result<(Vector2<f64>, f64), ParameterError> {
        let (low, high) = self.faces_at(s)?;
        let at = |t: f64| self.origin + self.along * s + self.normal * t;
        // Found against the chords (the smooth outline moves the circle's place along the line by half the
        // difference of the two faces' sags, which changes its radius only at second order), measured against
        // the smooth outline.
        let centre = at(golden_max(low, high, |t| {
            nearest_chord(self.outline, &at(t)).1
        }));
        Ok((centre, distance_to_outline(self.outline, &centre)))
    }
}

/// The segment from point `i` of a closed outline to the next of the centripetal Catmull-Rom curve through the
/// points (Barry and Goldman's evaluation): a cubic through the two and their neighbours either side that follows
/// a circle sampled every 10 deg to 0.05 um, and does not overshoot where the spacing changes (the centripetal
/// parametrisation). Written here: the spline crates on crates.io are for animation curves, not for a closed
/// outline's segment-by-segment intersections.
struct CatmullRom {
    points: [Vector2<f64>; 4],
    knots: [f64; 4],
}

impl CatmullRom {
    /// `None` where two of the four points coincide (a sharp edge's contacts can), which leaves the chord.
    fn through(outline: &[Vector2<f64>], i: usize) -> Option<Self> {
        let n = outline.len();
        let points = [0, 1, 2, 3].map(|k| outline[(i + n + k - 1) % n]);
        let mut knots = [0.0; 4];
        for k in 1..4 {
            let step = (points[k] - points[k - 1]).norm().sqrt();
            if step < 1e-6 {
                return None;
            }
            knots[k] = knots[k - 1] + step;
        }
        Some(CatmullRom { points, knots })
    }

    /// The point at `t` in [0, 1], from point `i` (t = 0) to the next (t = 1).
    fn at(&self, t: f64) -> Vector2<f64> {
        let [p0, p1, p2, p3] = self.points;
        let [t0, t1, t2, t3] = self.knots;
        let u = t1 + (t2 - t1) * t;
        let blend = |a: Vector2<f64>, b: Vector2<f64>, from: f64, to: f64| {
            a * ((to - u) / (to - from)) + b * ((u - from) / (to - from))
        };
        let (a1, a2, a3) = (
            blend(p0, p1, t0, t1),
            blend(p1, p2, t1, t2),
            blend(p2, p3, t2, t3),
        );
        blend(blend(a1, a2, t0, t2), blend(a2, a3, t1, t3), t1, t2)
    }
}

/// A round end's tip: where the nose fitted to the outline's points round it reaches farthest along `outward`
/// (unit). The nose is a polynomial of [`NOSE_DEGREE`] giving the depth along `outward` of the points across it,
/// fitted to the points within [`NOSE_SPAN_DEG`] of the tip on a circle of the edge's `radius`. `None` where those
/// points are fewer than [`NOSE_MIN_POINTS`], or the fit peaks at their first or last (no tip between them).
///
/// Why a fit: a scan's points step round a nose by several degrees, each with the probe's noise, so the farthest
/// of them is one noisy point that falls short of the tip by r (1 - cos a), a its angle from the tip. Moved out to
/// the smooth outline's reach beside it, it still carries a point's noise: 2 um noise read the tip of NACA noses
/// stepped by 2.5-10 deg with a spread of 1.5-2.1 um and up to 6 um off, where this fit spreads 0.6 um (2.5 deg
/// steps) to 1.4 um (10 deg), and is off by at most 0.4 um without noise (BENCHMARKS.md, issue 16). Not the edge's
/// circle: a NACA nose's curvature differs on its two faces, so a circle's centre sits off to one side and its
/// reach came out 6 um long on a cambered nose; the quartic follows that asymmetry.
fn round_tip(
    outline: &[Vector2<f64>],
    end: Vector2<f64>,
    outward: Vector2<f64>,
    radius: f64,
) -> Option<Vector2<f64>> {
    let across = Vector2::new(-outward.y, outward.x);
    let depth = radius * (1.0 - NOSE_SPAN_DEG.to_radians().cos());
    let nose: Vec<(f64, f64)> = outline
        .iter()
        .map(|p| p - end)
        .filter(|d| -d.dot(&outward) <= depth)
        .map(|d| (d.dot(&across), d.dot(&outward)))
        .collect();
    if nose.len() < NOSE_MIN_POINTS {
        return None;
    }
    let (low, high) = nose
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
            (l.min(p.0), h.max(p.0))
        });
    let reach = fit_polynomial(&nose, NOSE_DEGREE)?;
    // The quartic of a nose is unimodal over its points; the best of a coarse look brackets the golden search.
    let step = (high - low) / NOSE_LOOKS as f64;
    let best = (0..=NOSE_LOOKS)
        .map(|k| low + step * k as f64)
        .fold(low, |a, t| if reach(t) > reach(a) { t } else { a });
    let at = golden_max((best - step).max(low), (best + step).min(high), &reach);
    let inside = at - low > step && high - at > step;
    inside.then(|| end + across * at + outward * reach(at))
}

/// How far beyond the outline point `end` the smooth outline through the points reaches along `outward`, on the
/// segments either side of it (mm, at least 0).
fn smooth_reach_beyond(outline: &[Vector2<f64>], end: Vector2<f64>, outward: Vector2<f64>) -> f64 {
    let Some(k) = outline.iter().position(|p| *p == end) else {
        return 0.0;
    };
    let n = outline.len();
    [(k + n - 1) % n, k]
        .into_iter()
        .filter_map(|i| CatmullRom::through(outline, i))
        .map(|segment| {
            let reach = |t: f64| (segment.at(t) - end).dot(&outward);
            reach(golden_max(0.0, 1.0, reach))
        })
        .fold(0.0, f64::max)
}

/// A sharp end's apex: the mean of the contacts rolling round it (those of `sharp_edge_contacts` within
/// [`SHARP_TIP_REACH_MM`] of its farthest point `end`); `None` where there are fewer than two.
fn roll_apex(
    outline: &[Vector2<f64>],
    sharp_edge_contacts: &[usize],
    end: Vector2<f64>,
) -> Option<Vector2<f64>> {
    let near: Vec<Vector2<f64>> = sharp_edge_contacts
        .iter()
        .map(|&i| outline[i])
        .filter(|p| (p - end).norm() <= SHARP_TIP_REACH_MM)
        .collect();
    (near.len() >= 2).then(|| near.iter().sum::<Vector2<f64>>() / near.len() as f64)
}

/// How far along the outline from an end its direction shows whether the end is a corner (mm): past a sharp
/// edge's rounding and a roll's scatter, within a round nose's first few degrees of turn (0.5 / r rad).
const CORNER_REACH_MM: f64 = 0.5;
/// A corner's faces leave it within this angle of the way into the section (deg); a round nose's outline, as far
/// along it, leaves at 90 deg less half its turn (over 75 deg for a radius over 1 mm).
const CORNER_MAX_DEG: f64 = 45.0;

/// Whether the outline has a corner at its point `tip`, the section lying towards `inward` (unit): both ways round
/// the outline, its point [`CORNER_REACH_MM`] along it from the tip lies within [`CORNER_MAX_DEG`] of `inward`
/// (the polyline's own points, however sparse, or a point on a segment between them).
fn is_corner(outline: &[Vector2<f64>], tip: Vector2<f64>, inward: Vector2<f64>) -> bool {
    let n = outline.len();
    let Some(start) = outline.iter().position(|p| *p == tip) else {
        return false;
    };
    let cos_max = CORNER_MAX_DEG.to_radians().cos();
    let along = |step: usize| {
        let (mut at, mut travelled) = (start, 0.0);
        for _ in 0..n {
            let next = (at + step) % n;
            let segment = outline[next] - outline[at];
            let length = segment.norm();
            if length > 0.0 && travelled + length >= CORNER_REACH_MM {
                return outline[at] + segment * ((CORNER_REACH_MM - travelled) / length);
            }
            travelled += length;
            at = next;
        }
        outline[at]
    };
    [1, n - 1].into_iter().all(|step| {
        let d = along(step) - tip;
        d.dot(&inward) >= cos_max * d.norm() && d.norm() > 0.0
    })
}

/// The root in [0, 1] of `f`, which is `f0` at 0 and `f1` at 1, of opposite signs (or one of them zero), by
/// bisection.
fn bisect(f: impl Fn(f64) -> f64, f0: f64, f1: f64) -> f64 {
    if f0 == 0.0 {
        return 0.0;
    }
    if f1 == 0.0 {
        return 1.0;
    }
    let (mut low, mut high) = (0.0, 1.0);
    let rising = f1 > f0;
    for _ in 0..50 {
        let middle = (low + high) / 2.0;
        if (f(middle) < 0.0) == rising {
            low = middle;
        } else {
            high = middle;
        }
    }
    (low + high) / 2.0
}

/// The distance from `p` to the smooth outline through the points (see the module's definitions): to the
/// Catmull-Rom segments beside the nearest chord. The chords between points 1 mm apart on a face of 150 mm radius
/// cut up to 0.8 um inside it, on both faces, and an inscribed circle touching them reads the section thin.
fn distance_to_outline(outline: &[Vector2<f64>], p: &Vector2<f64>) -> f64 {
    let n = outline.len();
    let (nearest, chord_distance) = nearest_chord(outline, p);
    [nearest + n - 1, nearest, nearest + 1]
        .into_iter()
        .filter_map(|i| CatmullRom::through(outline, i % n))
        .map(|segment| {
            let away = |t: f64| -(segment.at(t) - p).norm();
            -away(golden_max(0.0, 1.0, away))
        })
        .fold(None, |nearest: Option<f64>, d| {
            Some(nearest.map_or(d, |n| n.min(d)))
        })
        // Where two points coincide (a sharp edge's contacts may) the chords stand.
        .unwrap_or(chord_distance)
}

/// The chord of the closed polyline `outline` nearest to `p` (its first point's index) and the distance to it.
fn nearest_chord(outline: &[Vector2<f64>], p: &Vector2<f64>) -> (usize, f64) {
    let n = outline.len();
    (0..n)
        .map(|i| {
            let (a, b) = (outline[i], outline[(i + 1) % n]);
            let ab = b - a;
            let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
            let distance = if t.is_finite() {
                (a + ab * t - p).norm()
            } else {
                (a - p).norm()
            };
            (i, distance)
        })
        .fold((0, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a })
}

/// The argument of the maximum of `f` on [low, high], by golden-section search (`f` unimodal there: the distance
/// to the outline along a line across the section rises from one face and falls to the other).
fn golden_max(mut low: f64, mut high: f64, mut f: impl FnMut(f64) -> f64) -> f64 {
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = high - ratio * (high - low);
    let mut x2 = low + ratio * (high - low);
    let (mut f1, mut f2) = (f(x1), f(x2));
    while high - low > SEARCH_TOLERANCE_MM {
        if f1 < f2 {
            low = x1;
            x1 = x2;
            f1 = f2;
            x2 = low + ratio * (high - low);
            f2 = f(x2);
        } else {
            high = x2;
            x2 = x1;
            f2 = f1;
            x1 = high - ratio * (high - low);
            f1 = f(x1);
        }
    }
    (low + high) / 2.0
}

#[cfg(test)]
mod tests;
