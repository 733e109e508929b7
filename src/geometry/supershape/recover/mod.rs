//! Supershape recovery from measured points (seed 001 sections 3-6): one supershape fitted by Levenberg-Marquardt
//! to the radial cost a1 a2 a3 sum F2^2 (eq. 4), exponents and sizes through their logarithms, symmetry numbers
//! read from sections along the inertia axes, the rational supershape (eqs. 8-9) for the first iterations, several
//! starts; then holes found from points well inside the envelope and fitted as negative primitives, the envelope
//! truncated by the oriented bounding box of its points, all combined by R_p (p = 2) into one solid; and the global
//! error of fit (eq. 15) as the similarity of points to a model, with a pose fit against a fixed reference.
//!
//! The fit runs on points centred on their centroid and scaled to unit RMS radius, so that every parameter is of
//! order one whatever the part's size; the model is returned in the points' own frame and units (mm).

mod holes;
mod model;
mod problem;
mod segments;
mod similarity;
mod starts;
mod superquadric;
mod symmetry;

#[cfg(test)]
mod tests;

use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use rayon::prelude::*;

use self::model::{Candidate, Radius};
use self::problem::minimise;
use super::csg::{Node, Solid};
use super::deform::{Deformation, Deformations};
use super::rfunc::{Boolean, RFunction};
use super::shape::Supershape;

pub use self::segments::{
    recover_segments, RecoveredObject, RecoveredSegment, SegmentError, SegmentPoints,
};
pub use self::similarity::{
    fit_pose, global_error, surface_distance_bound, surface_gap_rms, Pose, PoseFit,
};

/// Fewer points than this cannot fix fifteen parameters against noise.
const MIN_POINTS: usize = 60;
/// The rational first iterations run on at most this many of the points (evenly taken): a start only has to reach
/// the right basin there, and every start costs the same whatever the scan's size.
const EARLY_POINTS: usize = 400;
/// The evaluation budgets of the two stages, in the crate's units (x 16 evaluations).
const RATIONAL_PATIENCE: usize = 4;
const STANDARD_PATIENCE: usize = 100;
/// The best starts after the rational stage that the standard stage refines.
const REFINED_STARTS: usize = 4;
/// The latitude symmetry numbers m2 tried from the refined fit when they are not given (`starts::other_latitudes`).
const LATITUDES: [u32; 4] = [2, 4, 6, 8];
/// The section symmetry numbers m1 tried from the refined fit when they are not given (`starts::other_sections`).
const SECTION_COUNTS: [u32; 6] = [3, 4, 5, 6, 7, 8];
/// The brief minimisation of each other-symmetry candidate (x 16 evaluations), and how many are refined.
const SWITCH_PATIENCE: usize = 4;
/// The brief minimisations run on this many of the subsample's points.
const SWITCH_POINTS: usize = 200;
const SWITCH_REFINED: usize = 2;
/// The fraction by which another symmetry's fit must come nearer the points than the fit read.
const SWITCH_GAIN: f64 = 0.1;
/// The truncating box lies this many RMS radial distances outside the points (at least this fraction of the
/// points' RMS radius), so that it cuts away only what lies beyond the data, never the data's own surface.
const BOX_MARGIN_RMS: f64 = 4.0;
const BOX_MARGIN_MIN: f64 = 0.005;

/// The shapes the envelope is recovered among.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Family {
    /// Supershapes (15 parameters), their symmetry numbers given or read from the points.
    #[default]
    Supershape,
    /// Superquadrics (11 parameters): supershapes with m1 = m2 = 4 and each superformula's exponents equal,
    /// n = 2 / epsilon; the family of superquadric fitters such as EMS.
    Superquadric,
}

impl Family {
    /// What one of the family is called.
    pub fn name(self) -> &'static str {
        match self {
            Family::Supershape => "supershape",
            Family::Superquadric => "superquadric",
        }
    }
}

/// What the recovery may assume and do.
#[derive(Debug, Clone, PartialEq)]
pub struct RecoveryOptions {
    pub family: Family,
    /// The symmetry numbers m1, m2 when known (a superquadric is 4, 4); read from the points otherwise.
    pub symmetry: Option<[u32; 2]>,
    /// Cut the envelope by the oriented bounding box of its points (seed 001 eq. 14).
    pub truncate: bool,
    /// Look for holes (points well inside the envelope) and fit them as negative primitives (section 6.2).
    pub holes: bool,
}

impl Default for RecoveryOptions {
    fn default() -> Self {
        Self {
            family: Family::Supershape,
            symmetry: None,
            truncate: true,
            holes: true,
        }
    }
}

/// Why no supershape was recovered.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RecoveryError {
    #[error("{got} points cannot fix a supershape; give at least {MIN_POINTS} points spread over the part's surface")]
    TooFewPoints { got: usize },
    #[error("a point has a coordinate that is not a finite number (point {index})")]
    NotFinite { index: usize },
    #[error(
        "no start converged ({starts} tried); check that the points are of one part's surface"
    )]
    NoConvergence { starts: usize },
    #[error("the points all lie at one place ({centre:?} mm): they do not show a surface")]
    Coincident { centre: [f64; 3] },
    #[error("a superquadric has the symmetry numbers 4,4, not {}; give no symmetry numbers with it", .given.map(|m| m.to_string()).join(","))]
    SuperquadricSymmetry { given: [u32; 2] },
}

/// A recovered solid and how it was found.
#[derive(Debug, Clone, PartialEq)]
pub struct Recovered {
    /// The model, in the points' frame, mm: the envelope (truncated if asked) minus its holes.
    pub solid: Solid,
    /// The envelope supershape and its placement, before truncation and holes.
    pub envelope: (Supershape, Deformations),
    /// The negative primitives, each with its placement and whether it passes through the envelope.
    pub holes: Vec<RecoveredHole>,
    /// The envelope's symmetry numbers m1, m2.
    pub symmetry: [u32; 2],
    /// Where each came from.
    pub symmetry_source: [SymmetrySource; 2],
    /// The starts tried for the envelope.
    pub starts: usize,
    /// Seed 001 eq. 15 at the points, mm^3.
    pub global_error: f64,
    /// The RMS of the envelope's radial distances |P| |F2| / (1 - F2) at its points, mm: an upper bound of
    /// their Euclidean distances (the radial foot is a point of the surface).
    pub rms_radial_mm: f64,
}

/// Where a recovered symmetry number came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SymmetrySource {
    /// Given in the options (or fixed by the family: a superquadric's are 4, 4).
    Given,
    /// Read from the lobes of the points' sections.
    Read,
    /// Another number than the one read (or than 4) fitted the points better, and the fit switched to it.
    Switched,
    /// Nothing stood out, so 4, which eq. 1 makes transparent.
    Transparent,
}

impl SymmetrySource {
    /// How the number was found, in words.
    pub fn describe(self) -> &'static str {
        match self {
            SymmetrySource::Given => "given",
            SymmetrySource::Read => "read from the points",
            SymmetrySource::Switched => "fitted better than the one read",
            SymmetrySource::Transparent => "4: nothing stood out",
        }
    }
}

/// A hole of the recovered solid.
#[derive(Debug, Clone, PartialEq)]
pub struct RecoveredHole {
    pub shape: Supershape,
    pub place: Deformations,
    /// The points it was fitted to.
    pub points: usize,
    /// Whether its points run through the envelope, so that it was made a prism longer than the part.
    pub through: bool,
}

/// The points' centroid and RMS radius, to fit in a frame where both are 0 and 1.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Normalisation {
    centre: Vector3<f64>,
    scale: f64,
}

impl Normalisation {
    fn of(points: &[Point3<f64>]) -> Self {
        let count = points.len() as f64;
        let centre = points.iter().map(|p| p.coords).sum::<Vector3<f64>>() / count;
        let scale = (points
            .iter()
            .map(|p| (p.coords - centre).norm_squared())
            .sum::<f64>()
            / count)
            .sqrt();
        Self { centre, scale }
    }

    fn apply(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::from((p.coords - self.centre) / self.scale)
    }

    /// A supershape fitted in the normalised frame, placed in the points' frame.
    fn placed(&self, candidate: &Candidate) -> (Supershape, Deformations) {
        let (mut shape, _) = candidate.supershape();
        shape.scale = shape.scale.map(|a| a * self.scale);
        let p = &candidate.params;
        let place = Isometry3::from_parts(
            Translation3::from(self.centre + Vector3::new(p[0], p[1], p[2]) * self.scale),
            UnitQuaternion::from_rotation_matrix(&candidate.rotation()),
        );
        (shape, Deformations(vec![Deformation::Rigid(place)]))
    }
}

/// One supershape fitted to points of the normalised frame, with the number of starts tried and where its
/// symmetry numbers came from.
struct Fitted {
    candidate: Candidate,
    starts: usize,
    source: [SymmetrySource; 2],
}

/// Recovers a solid from points on a part's surface (mm).
pub fn recover(
    points: &[Point3<f64>],
    options: &RecoveryOptions,
) -> Result<Recovered, RecoveryError> {
    if points.len() < MIN_POINTS {
        return Err(RecoveryError::TooFewPoints { got: points.len() });
    }
    if let Some(index) = points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(RecoveryError::NotFinite { index });
    }
    let normalisation = Normalisation::of(points);
    if normalisation.scale <= 1e-9 * (1.0 + normalisation.centre.norm()) {
        return Err(RecoveryError::Coincident {
            centre: normalisation.centre.into(),
        });
    }
    let model = match (options.family, options.symmetry) {
        (Family::Supershape, given) => Envelope::Supershape(given),
        (Family::Superquadric, None) => Envelope::Superquadric,
        (Family::Superquadric, Some(given)) if given == superquadric::SYMMETRY => {
            Envelope::Superquadric
        }
        (Family::Superquadric, Some(given)) => {
            return Err(RecoveryError::SuperquadricSymmetry { given })
        }
    };
    let unit: Vec<Point3<f64>> = points.iter().map(|p| normalisation.apply(p)).collect();
    let (envelope, outer, hole_fits) = if options.holes {
        holes::separate(&unit, model)?
    } else {
        let outer: Vec<usize> = (0..unit.len()).collect();
        (model.fit(&unit)?, outer, Vec::new())
    };
    let outer_points: Vec<Point3<f64>> = outer.iter().map(|&i| unit[i]).collect();
    let rms_radial = rms_radial(&envelope.candidate, &outer_points);
    let (shape, place) = normalisation.placed(&envelope.candidate);
    let mut root = Node::supershape(shape, place.clone());
    if options.truncate {
        let margin = (BOX_MARGIN_RMS * rms_radial).max(BOX_MARGIN_MIN);
        root = Node::boolean(
            Boolean::Intersection,
            RFunction::P(2),
            root,
            bounding_box(&envelope.candidate, &outer_points, margin, &normalisation),
        );
    }
    let mut holes = Vec::new();
    for hole in hole_fits {
        let (shape, place) = normalisation.placed(&hole.fitted.candidate);
        let (shape, place) = if hole.through {
            holes::through_prism(shape, place, hole.length * normalisation.scale)
        } else {
            (shape, place)
        };
        root = Node::boolean(
            Boolean::Difference,
            RFunction::P(2),
            root,
            Node::supershape(shape, place.clone()),
        );
        holes.push(RecoveredHole {
            shape,
            place,
            points: hole.points,
            through: hole.through,
        });
    }
    let solid = Solid::new(root);
    Ok(Recovered {
        global_error: global_error(&solid, points),
        envelope: (shape, place),
        holes,
        symmetry: envelope.candidate.frame.symmetry,
        symmetry_source: envelope.source,
        starts: envelope.starts,
        rms_radial_mm: rms_radial * normalisation.scale,
        solid,
    })
}

/// The model of an envelope.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Envelope {
    /// A supershape, with its symmetry numbers when given.
    Supershape(Option<[u32; 2]>),
    Superquadric,
}

impl Envelope {
    /// The envelope fitted to normalised points.
    fn fit(self, points: &[Point3<f64>]) -> Result<Fitted, RecoveryError> {
        match self {
            Envelope::Supershape(given) => fit_one(points, given),
            Envelope::Superquadric => superquadric::fit(points),
        }
    }

    /// A fitted envelope minimised on other points from where it stands, in its family.
    fn refine(self, points: &[Point3<f64>], from: &Candidate) -> Option<Candidate> {
        match self {
            Envelope::Supershape(_) => {
                minimise(points, *from, Radius::Standard, STANDARD_PATIENCE).map(|(c, _)| c)
            }
            Envelope::Superquadric => superquadric::refine(points, from),
        }
    }
}

/// The smallest and largest coordinates of the points, per axis.
fn extent(points: impl Iterator<Item = Vector3<f64>>) -> (Vector3<f64>, Vector3<f64>) {
    points.fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(low, high), p| (low.inf(&p), high.sup(&p)),
    )
}

/// The extent of the points along the axes of `frame` (its columns: its axes in the points' frame).
fn extent_in(points: &[Point3<f64>], frame: &Rotation3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let inverse = frame.inverse();
    extent(points.iter().map(|p| inverse * p.coords))
}

/// At most `count` of the points, evenly taken.
fn evenly(points: &[Point3<f64>], count: usize) -> Vec<Point3<f64>> {
    if points.len() > count {
        (0..count)
            .map(|k| points[k * points.len() / count])
            .collect()
    } else {
        points.to_vec()
    }
}

/// One supershape fitted to normalised points: every start of every inertia axis's guess minimised briefly on a
/// subsample (the rational radius where it stands for the superformula), the best few refined with the
/// superformula on the subsample; then, unless the symmetry numbers are given, the best of those tried with the
/// other likely numbers (`best_switch`); and the best of all refined on every point.
///
/// Starts are compared by their RMS radial distance to the points, not by the cost they minimise: eq. 4's
/// volume term a1 a2 a3 has a degenerate minimum, a supershape shrunk to a point far from the data (there F2
/// grows like 1 / a while the weight falls like a^3), which a start in the wrong basin can slide into.
fn fit_one(points: &[Point3<f64>], given: Option<[u32; 2]>) -> Result<Fitted, RecoveryError> {
    let early = evenly(points, EARLY_POINTS);
    let starts: Vec<(Candidate, [bool; 2])> = symmetry::guesses(points, given)
        .par_iter()
        .flat_map_iter(|guess| starts::of(points, guess, given))
        .collect();
    let count = starts.len();
    // The starts are independent: they are minimised on every core (rayon keeps their order).
    let mut tried: Vec<(f64, Candidate, [bool; 2])> = starts
        .into_par_iter()
        .filter_map(|(candidate, read)| {
            // Seed 001 section 4: the rational form stands for the superformula only for exponents in [1, 4];
            // a start outside (read from the points) goes straight to the superformula.
            let radius = if candidate
                .exponents()
                .iter()
                .all(|n| (1.0..=4.0).contains(n))
            {
                Radius::Rational
            } else {
                Radius::Standard
            };
            let (reached, _) = minimise(&early, candidate, radius, RATIONAL_PATIENCE)?;
            let distance = rms_radial(&reached, &early);
            distance.is_finite().then_some((distance, reached, read))
        })
        .collect();
    tried.sort_by(|a, b| a.0.total_cmp(&b.0));
    tried.truncate(REFINED_STARTS);
    let refine = |candidate: Candidate| {
        let (reached, _) = minimise(&early, candidate, Radius::Standard, STANDARD_PATIENCE)?;
        let distance = rms_distance(&reached, &early);
        distance.is_finite().then_some((distance, reached))
    };
    let (mut distance, mut best, read) = tried
        .into_par_iter()
        .filter_map(|(_, candidate, read)| refine(candidate).map(|(d, c)| (d, c, read)))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .ok_or(RecoveryError::NoConvergence { starts: count })?;
    let mut source = match given {
        Some(_) => [SymmetrySource::Given; 2],
        None => read.map(|read| {
            if read {
                SymmetrySource::Read
            } else {
                SymmetrySource::Transparent
            }
        }),
    };
    if given.is_none() {
        // Symmetry numbers read from the points are the commonest misses: the fit switches to other ones when
        // they come nearer the points, m2 first (r1 is usually right by then), then m1.
        let latitudes = starts::other_latitudes(&early, &best, &LATITUDES);
        if let Some((d, candidate)) = best_switch(&early, latitudes, &refine, (&best, distance)) {
            (distance, best) = (d, candidate);
            source[1] = SymmetrySource::Switched;
        }
        let sections = starts::other_sections(&best, &SECTION_COUNTS);
        if let Some((_, candidate)) = best_switch(&early, sections, &refine, (&best, distance)) {
            best = candidate;
            source[0] = SymmetrySource::Switched;
        }
    }
    let (candidate, _) = minimise(points, best, Radius::Standard, STANDARD_PATIENCE)
        .ok_or(RecoveryError::NoConvergence { starts: count })?;
    Ok(Fitted {
        candidate,
        starts: count,
        source,
    })
}

/// The best of other-symmetry candidates when it comes clearly nearer the points than `distance` (by
/// `SWITCH_GAIN`): each minimised briefly, and of those already nearer by radial distance than the current fit
/// the nearest `SWITCH_REFINED` refined (`refine`, which gives the RMS distance). Where the numbers read are
/// right no other one gets that near in a brief minimisation, and the switch costs only those. A misread number leaves the fit far off (twice the noise and more in the
/// seeded cases); where the number does not matter (a round section is round for every m1) a marginal gain
/// would trade the shape read for a degenerate one of extreme exponents.
fn best_switch(
    early: &[Point3<f64>],
    candidates: Vec<Candidate>,
    refine: &(impl Fn(Candidate) -> Option<(f64, Candidate)> + Sync),
    (current, distance): (&Candidate, f64),
) -> Option<(f64, Candidate)> {
    let few = evenly(early, SWITCH_POINTS);
    let current_radial = rms_radial(current, &few);
    let mut brief: Vec<(f64, Candidate)> = candidates
        .into_par_iter()
        .filter_map(|candidate| {
            let (reached, _) = minimise(&few, candidate, Radius::Standard, SWITCH_PATIENCE)?;
            let radial = rms_radial(&reached, &few);
            (radial < current_radial).then_some((radial, reached))
        })
        .collect();
    brief.sort_by(|a, b| a.0.total_cmp(&b.0));
    brief.truncate(SWITCH_REFINED);
    brief
        .into_par_iter()
        .filter_map(|(_, candidate)| refine(candidate))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .filter(|(d, _)| *d < (1.0 - SWITCH_GAIN) * distance)
}

/// The radial distance |P - I| = |P| |F2| / (1 - F2) of a point to a placed supershape, I the surface point on
/// the ray from the supershape's centre through P: an upper bound of the Euclidean distance (I is on the
/// surface) that costs one evaluation of eq. 3, for comparing starts.
fn radial_distance(shape: &Supershape, place: &Deformations, p: &Point3<f64>) -> f64 {
    let q = place.inverse(p);
    let f = shape.radial(&q);
    q.coords.norm() * f.abs() / (1.0 - f)
}

/// The RMS of the distances of normalised points to a candidate's surface (`surface_distance_bound`): slower than
/// the radial distance and tighter, for the final choice among refined starts, whose radial distances a shape
/// seen edge-on along its rays inflates.
fn rms_distance(candidate: &Candidate, points: &[Point3<f64>]) -> f64 {
    let (shape, place) = candidate.supershape();
    let sum: f64 = points
        .iter()
        .map(|p| similarity::surface_distance_bound(&shape, &place, p).powi(2))
        .sum();
    (sum / points.len() as f64).sqrt()
}

/// The RMS of the radial distances of normalised points to a candidate.
fn rms_radial(candidate: &Candidate, points: &[Point3<f64>]) -> f64 {
    let (shape, place) = candidate.supershape();
    let sum: f64 = points
        .iter()
        .map(|p| radial_distance(&shape, &place, p).powi(2))
        .sum();
    (sum / points.len() as f64).sqrt()
}

/// The box of seed 001 eq. 14: the points' extent in the envelope's frame, `margin` larger on every side, in the
/// points' frame (mm).
fn bounding_box(
    envelope: &Candidate,
    points: &[Point3<f64>],
    margin: f64,
    normalisation: &Normalisation,
) -> Node {
    let rotation = envelope.rotation();
    let (low, high) = extent_in(points, &rotation);
    let half = ((high - low) / 2.0).add_scalar(margin) * normalisation.scale;
    let middle = normalisation.centre + rotation * ((low + high) / 2.0) * normalisation.scale;
    let place = Isometry3::from_parts(
        Translation3::from(middle),
        UnitQuaternion::from_rotation_matrix(&rotation),
    );
    Node::cuboid(
        [half.x, half.y, half.z],
        Deformations(vec![Deformation::Rigid(place)]),
    )
}
