//! Fitting a profile with sharp edges face by face, each face's degree chosen by points it was not fitted to.

use nalgebra::Vector2;

use super::refine::joint_for_unfollowed;
use super::split::{
    edge_angle, face_normals, find_corners, orientation, perimeter, split_at_corners, split_face,
    FacePoints,
};
use super::{meeting_point, trace_face, FacedProfile, FacesError, Join};
use crate::geometry::fit3l::{fit_ip, FitMethod, FitOptions, Fitted};
use crate::geometry::held_out::{choose_degree, degrees_to_try, rms_distance, CANDIDATE_DEGREES};
use crate::geometry::implicit::IpModel;
use crate::geometry::sampling::{project_to_zero_set, Aabb};

/// How many times a sharp edge's own point counts, at most, in the fits of the faces that meet there (see
/// [`edge_weight`]).
const MAX_EDGE_WEIGHT: f64 = 200.0;

/// How many times a sharp edge's own point counts in the fits of the two faces that meet there at `angle_rad`:
/// 1 / (2 sin^2(angle / 2)), at least once and at most [`MAX_EDGE_WEIGHT`].
///
/// The edge is where the faces cross, and where they cross at a small angle an error of the faces across their
/// length moves it along the edge's bisector 1 / sin(angle / 2) times as far (14 times on NACA 0006's 8 deg);
/// the edge's own point is the one measure of where along the bisector the edge lies. Its noise along the
/// bisector moves it across each face by only sin(angle / 2) of it, so in a face's fit it deserves 1 / sin^2 the
/// weight of a point whose noise lies across the face, and half that in each of the two faces it serves. Measured
/// over 45 draws of 2 um (BENCHMARKS.md, issue 15, stop 51): a fixed weight of 20 put NACA 0006's edge 2.7 um RMS
/// off the truth (the faces crossing up to 3 um farther in than its point), 60 put it 2.2 um off and the cambered
/// sections' 2.0 (1.9 at 20), 200 2.1 on every section.
fn edge_weight(angle_rad: f64) -> usize {
    let weight = 0.5 / (0.5 * angle_rad).sin().powi(2);
    weight.clamp(1.0, MAX_EDGE_WEIGHT).round() as usize
}

/// A profile is split into at most this many faces (sharp edges' faces and the splits of those its polynomials do
/// not follow).
const MAX_FACES: usize = 12;
/// Each degree tried for a face, with its held-out RMS distance (mm).
type HeldOut = Vec<(usize, f64)>;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FacesFitOptions {
    /// Every face's degree; `None` to choose each face's from [`CANDIDATE_DEGREES`] by a held-out check.
    pub degree: Option<usize>,
    pub method: FitMethod,
    /// Whether a face its polynomial does not follow is split in two at a smooth joint (see
    /// [`joint_for_unfollowed`](super::refine::joint_for_unfollowed)). A stack's profiles are not: its loft pairs
    /// faces profile to profile, so every profile must have its joints at the same places.
    pub split_unfollowed: bool,
}

/// A profile fitted face by face.
pub struct FittedFaces {
    /// Each face's fit, counter-clockwise round the part.
    pub faces: Vec<Fitted<2>>,
    /// For each face, the held-out RMS distance (mm) of each candidate degree tried, when the degree was chosen.
    pub held_out: Vec<HeldOut>,
    /// How many of the profile's points each face was fitted to (its fit's statistics count a sharp edge's point
    /// as often as it weighs).
    pub face_points: Vec<usize>,
    /// At each smooth joint, how far apart the two faces' curves pass the joint, mm: the step the model has there.
    pub joint_gaps_mm: Vec<f64>,
    pub model: FacedProfile,
}

/// Fits a closed profile whose points run along it face by face, split at its sharp edges. `Ok(None)` when it
/// has no sharp edge (one polynomial then serves).
pub fn fit_faces(
    points: &[Vector2<f64>],
    options: &FacesFitOptions,
) -> Result<Option<FittedFaces>, FacesError> {
    // Counter-clockwise, so that faces and joins follow the model's own direction round the part.
    let counter_clockwise: Vec<Vector2<f64>> = if orientation(points) > 0.0 {
        points.to_vec()
    } else {
        points.iter().rev().copied().collect()
    };
    let points = &counter_clockwise[..];
    let corners = find_corners(points);
    if corners.is_empty() {
        return Ok(None);
    }
    let perimeter = perimeter(points);
    let mut faces = Vec::new();
    let mut fitted = Vec::new();
    let mut held_out = Vec::new();
    let mut face_points_count = Vec::new();
    let edge_faces = split_at_corners(points, &corners);
    // Each split adds one face; those left to split once the edges' own faces are fitted.
    let mut splits_left = MAX_FACES.saturating_sub(edge_faces.len());
    for face in edge_faces {
        let first = faces.len();
        let refined = fit_refined(points, face, first, perimeter, options, &mut splits_left)?;
        for (face, face_fit, scores) in refined {
            face_points_count.push(face.indices.len());
            faces.push(face);
            fitted.push(face_fit);
            held_out.push(scores);
        }
    }
    let n = faces.len();
    let mut joins = Vec::with_capacity(n);
    let mut joint_gaps_mm = Vec::new();
    for j in 0..n {
        let next = (j + 1) % n;
        let (before, after) = (&fitted[j].model, &fitted[next].model);
        let end = faces[j].end;
        let join = if end.sharp {
            let apex = points[end.at];
            let point = meeting_point(before, after, &apex).ok_or(FacesError::NoMeeting {
                before: j,
                after: next,
                at: apex.into(),
            })?;
            Join {
                point: point.into(),
                sharp: true,
            }
        } else {
            let joint = points[end.at];
            let on = |f: &IpModel<2>| {
                project_to_zero_set(f, &joint, super::JOIN_SEARCH_MM).unwrap_or(joint)
            };
            joint_gaps_mm.push((on(before) - on(after)).norm());
            Join {
                point: ((on(before) + on(after)) / 2.0).into(),
                sharp: false,
            }
        };
        joins.push(join);
    }
    let domain = Aabb::of_points(points).expect("a profile with an edge has points");
    let model = FacedProfile::new(
        fitted.iter().map(|f| f.model.clone()).collect(),
        joins,
        &domain,
    )?;
    Ok(Some(FittedFaces {
        faces: fitted,
        held_out,
        face_points: face_points_count,
        joint_gaps_mm,
        model,
    }))
}

/// A face fitted (as face `j` and on), split in two where its polynomial does not follow its points and the halves
/// fitted in its place, in turn, while `splits_left` allows; a split whose halves cannot both be fitted is not
/// made.
fn fit_refined(
    points: &[Vector2<f64>],
    face: FacePoints,
    j: usize,
    perimeter: f64,
    options: &FacesFitOptions,
    splits_left: &mut usize,
) -> Result<Vec<(FacePoints, Fitted<2>, HeldOut)>, FacesError> {
    let (face_fit, scores) = fit_face(points, &face, j, perimeter, options)?;
    if options.split_unfollowed && *splits_left > 0 {
        if let Some(k) = joint_for_unfollowed(points, &face, &face_fit.model) {
            *splits_left -= 1;
            let [before, after] = split_face(points, &face, k, perimeter);
            let halves = fit_refined(points, before, j, perimeter, options, splits_left).and_then(
                |mut first| {
                    let next = j + first.len();
                    first.extend(fit_refined(
                        points,
                        after,
                        next,
                        perimeter,
                        options,
                        splits_left,
                    )?);
                    Ok(first)
                },
            );
            if let Ok(halves) = halves {
                return Ok(halves);
            }
        }
    }
    Ok(vec![(face, face_fit, scores)])
}

/// Fits face `j` of a counter-clockwise profile: its degree chosen by held-out points unless `options` fixes it, its
/// sharp ends' points weighted (see [`edge_weight`]); with the held-out RMS (mm) of each degree tried.
fn fit_face(
    points: &[Vector2<f64>],
    face: &FacePoints,
    j: usize,
    perimeter: f64,
    options: &FacesFitOptions,
) -> Result<(Fitted<2>, HeldOut), FacesError> {
    let face_points: Vec<Vector2<f64>> = face.indices.iter().map(|&i| points[i]).collect();
    let normals = face_normals(points, &face.indices, perimeter);
    let last = face_points.len() - 1;
    // Each sharp end's point in the face, and its weight.
    let sharp_ends: Vec<(usize, usize)> = [(face.start, 0), (face.end, last)]
        .into_iter()
        .filter(|(end, _)| end.sharp)
        .map(|(end, k)| (k, edge_weight(edge_angle(points, end.at))))
        .collect();
    // Every `every`-th point, and each sharp end's point repeated so that the face passes through it (see
    // [`edge_weight`]; as much as among all the points when fitted to every other one).
    let fit = |degree: usize, every: usize| {
        let edges = sharp_ends.iter().flat_map(|&(k, weight)| {
            let repeats = (weight / every).saturating_sub(1);
            std::iter::repeat_n((face_points[k], normals[k]), repeats)
        });
        let (p, n): (Vec<_>, Vec<_>) = face_points
            .iter()
            .zip(&normals)
            .step_by(every)
            .map(|(p, n)| (*p, *n))
            .chain(edges)
            .unzip();
        fit_ip(&p, &n, &FitOptions::new(degree, options.method))
            .map_err(|source| FacesError::Fit { face: j, source })
    };
    let (degree, scores) = match options.degree {
        Some(degree) => (degree, Vec::new()),
        None => {
            let mut scores = Vec::new();
            // Fitted to every other point, judged by the others (a sharp end's point is fitted, not judged).
            let judged: Vec<Vector2<f64>> = (1..face_points.len())
                .step_by(2)
                .filter(|k| sharp_ends.iter().all(|(end, _)| end != k))
                .map(|k| face_points[k])
                .collect();
            for degree in CANDIDATE_DEGREES {
                if let Ok(trained) = fit(degree, 2) {
                    scores.push((degree, rms_distance(&trained.model, &judged)));
                }
            }
            (choose_degree(&scores), scores)
        }
    };
    // The chosen degree first, then the others by their held-out RMS: the first whose curve runs along the
    // face's points from end to end (a short, nearly straight face can leave a degree's curve crossing itself).
    let order = degrees_to_try(degree, &scores);
    let mut face_fit = Err(FacesError::Untraceable {
        face: j,
        from: face_points[0].into(),
        to: face_points[last].into(),
        problem: "no degree tried gives a curve along the face's points",
    });
    for degree in order {
        match fit(degree, 1) {
            Ok(candidate) if runs_along(&candidate.model, &face_points) => {
                face_fit = Ok(candidate);
                break;
            }
            Ok(_) => {}
            Err(problem) => face_fit = Err(problem),
        }
    }
    Ok((face_fit?, scores))
}

/// Whether a face's fitted curve can be followed from its first point to its last within the points' box (grown
/// by a tenth of its diagonal).
fn runs_along(model: &IpModel<2>, face_points: &[Vector2<f64>]) -> bool {
    let Some(bounds) = Aabb::of_points(face_points) else {
        return false;
    };
    let margin = Vector2::repeat(0.1 * bounds.diagonal());
    let limits = Aabb {
        min: bounds.min - margin,
        max: bounds.max + margin,
    };
    let length: f64 = face_points.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
    trace_face(
        model,
        &face_points[0],
        &face_points[face_points.len() - 1],
        2.0 * length,
        &limits,
    )
    .is_ok()
}
