//! `zeroset fit ip`: fit an implicit polynomial to a point file and save it as a model file.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, bail};
use clap::{Args, ValueEnum};
use nalgebra::{SVector, Vector2, Vector3};

use super::{rows_of, MethodArg};
use crate::analysis::fit_sanity;
use crate::geometry::faces::{fit_faces, FacedLoft, FacesFitOptions};
use crate::geometry::fit3l::{fit_ip, FitMethod, FitOptions, Fitted};
use crate::geometry::held_out::{
    choose_degree, clean_fit_or_chosen, combined_scores, held_out_scores, CANDIDATE_DEGREES,
};
use crate::geometry::nearest::PointIndex;
use crate::geometry::normals::{ordered_profile_normals, pca_normals};
use crate::model_file::{
    faced_sections, FacedIp, FacedStackProfile, FittedIp, ModelFile, ReferenceModel, StackProfile,
};
use crate::points::{read_point_file, PointFile, PointSet};

#[derive(Args)]
pub struct FitIpArgs {
    /// Point file: CSV with header y,z (a profile) or x,y,z (3-D), in mm.
    #[arg(long)]
    points: PathBuf,
    /// Degree of the polynomial (of each profile, for a stack; of each face, for a profile with sharp edges), 1 to
    /// 16. By default a profile's, each face's or a surface's is chosen from 4, 6 and 8 by the points held out of its
    /// fit, a stack's (one for all its profiles) by the points held out of all of them; a surface through profiles
    /// (points in parallel planes of constant x) takes 4.
    #[arg(long, value_parser = degree)]
    degree: Option<usize>,
    /// Sharp edges of a planar profile, or of each profile of a stack (a blade's trailing edge): `auto` finds them
    /// in the points (which must run along the profile) and fits the faces between them one by one, joined at the
    /// edges, a stack's faces lofted from profile to profile; `none` fits one polynomial round the whole profile,
    /// which rounds or overshoots a sharp edge by tens of microns.
    #[arg(long, value_enum, default_value = "auto")]
    edges: EdgesArg,
    #[arg(long, value_enum, default_value = "odr")]
    method: MethodArg,
    /// Where the outward normals for the 3L offsets come from.
    #[arg(long, value_enum, default_value = "auto")]
    normals: NormalsArg,
    /// Treat x,y,z points as parallel planar profiles at constant x and fit a stack of profile models blended
    /// along x (seed 003 section 4), or, where every profile has sharp edges, lofted face by face.
    #[arg(long)]
    stack: bool,
    /// Points whose x differ by less than this (mm) belong to the same profile plane (with --stack).
    #[arg(long, default_value_t = 1.0)]
    plane_tolerance: f64,
    /// The part's tolerance, mm (the half width of its band): warn when a fitted point lies farther than this
    /// from the model, which could not then measure the part to it.
    #[arg(long, value_parser = tolerance)]
    tolerance: Option<f64>,
    /// The model file to write (JSON).
    #[arg(long)]
    out: PathBuf,
}

/// `--tolerance`: a positive length in mm.
fn tolerance(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(t) if t.is_finite() && t > 0.0 => Ok(t),
        Ok(t) => Err(format!(
            "{t} mm is not a tolerance; give a positive number of mm"
        )),
        Err(e) => Err(format!("{e}; give a positive number of mm")),
    }
}

/// `--degree`: checked as an option, so that a degree out of range is a usage error, not a fault of the file.
fn degree(text: &str) -> Result<usize, String> {
    use crate::geometry::poly::MAX_DEGREE;
    match text.parse::<usize>() {
        Ok(d) if (1..=MAX_DEGREE).contains(&d) => Ok(d),
        Ok(d) => Err(format!(
            "degree {d} is not supported; give 1 to {MAX_DEGREE}"
        )),
        Err(e) => Err(format!("{e}; give a whole number from 1 to {MAX_DEGREE}")),
    }
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum EdgesArg {
    Auto,
    None,
}

#[derive(Clone, Copy, PartialEq, ValueEnum)]
enum NormalsArg {
    /// From the order of the points when they run along the profile, else by local PCA.
    Auto,
    /// From the order of the points along a closed profile.
    Ordered,
    /// By local principal component analysis (any order).
    Pca,
}

pub fn run(args: &FitIpArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let file = read_point_file(&args.points)?;
    warn_of_isolated_points(&file)?;
    let method: FitMethod = args.method.into();
    let lines = &file.lines;
    let (model, method) = match (file.points, args.stack) {
        (PointSet::Profile(points), false) if with_faces(args, &points) => {
            match fit_faces_of(args, &args.points.display().to_string(), &points, true)? {
                Some(faced) => (ReferenceModel::Faces(faced), method),
                None => one_polynomial(args, &points, lines)?,
            }
        }
        (PointSet::Profile(points), false) => one_polynomial(args, &points, lines)?,
        (PointSet::Spatial(points), false) => {
            if args.normals == NormalsArg::Ordered {
                bail!(
                    "{}: ordered normals need a planar profile (y,z); 3-D points use --normals pca",
                    args.points.display()
                );
            }
            let normals = pca_normals(&points);
            let rows = || rows_of(&args.points, lines, 0..points.len());
            // Profiles' points held out judge a surface only in their own planes, which a higher degree passes
            // through exactly whatever it does between them: their surface keeps the lowest degree.
            let planes = profile_planes(&points, args.plane_tolerance);
            let degree = args
                .degree
                .or(planes.as_ref().map(|_| CANDIDATE_DEGREES[0]));
            let fitted = held_out_or_given(degree, &points, &normals, method, &rows)?;
            print_fit(
                &args.points,
                "surface",
                &fitted.fitted,
                &points,
                args.tolerance,
            )?;
            fitted.print_degree()?;
            if let Some(xs) = planes {
                let xs: Vec<String> = xs.iter().map(|x| format!("{x:.3}")).collect();
                reportln!(
                    "  warning: the points lie in {} parallel planes of constant x (x = {} mm): they are \
                     profiles, which one surface does not model; fit them with --stack{}",
                    xs.len(),
                    xs.join(", "),
                    if args.degree.is_none() {
                        format!(
                            " (the surface took degree {}: points held out of profiles cannot judge it \
                             between their planes)",
                            CANDIDATE_DEGREES[0]
                        )
                    } else {
                        String::new()
                    }
                )?;
            }
            (
                ReferenceModel::Surface(FittedIp::from(fitted.fitted.clone())),
                fitted.fitted.method,
            )
        }
        (PointSet::Spatial(points), true) => {
            match fit_faces_stack(&args.points, &points, lines, args)? {
                Some(profiles) => (ReferenceModel::FacesStack { profiles }, method),
                None => {
                    let profiles = fit_stack(&args.points, &points, lines, method, args)?;
                    (ReferenceModel::Stack { profiles }, method)
                }
            }
        }
        (PointSet::Profile(_), true) => {
            bail!(
                "{}: --stack needs x,y,z points (parallel profiles at constant x)",
                args.points.display()
            )
        }
    };
    let file = ModelFile::new(method.describe(), model);
    if let ReferenceModel::Stack { profiles } = &file.model {
        crate::model_file::stack_of(profiles)
            .map_err(|e| anyhow!("{}: {e}", args.points.display()))?;
    }
    file.save(&args.out)?;
    reportln!(
        "wrote {} ({:.2} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    )?;
    Ok(())
}

/// Whether to look for sharp edges: asked for, and the points run along the profile (the edges are found in
/// their order).
fn with_faces(args: &FitIpArgs, points: &[Vector2<f64>]) -> bool {
    args.edges == EdgesArg::Auto
        && args.normals != NormalsArg::Pca
        && points.len() >= 3
        && runs_along_the_profile(points)
}

/// The profile fitted face by face between its sharp edges, with what was found and fitted said after `label`
/// (the file, or a stack's profile); `None` when it has no sharp edge. A fit that misses `--tolerance` fails
/// rather than being saved.
fn fit_faces_of(
    args: &FitIpArgs,
    label: &str,
    points: &[Vector2<f64>],
    split_unfollowed: bool,
) -> anyhow::Result<Option<FacedIp>> {
    let options = FacesFitOptions {
        degree: args.degree,
        method: args.method.into(),
        split_unfollowed,
    };
    let Some(fitted) = fit_faces(points, &options).map_err(|e| {
        anyhow!(
            "{}: {e}; check the points there, or fit one polynomial round the whole profile with --edges none",
            label
        )
    })?
    else {
        return Ok(None);
    };
    let edges: Vec<String> = fitted
        .model
        .joins()
        .iter()
        .filter(|j| j.sharp)
        .map(|j| format!("({:.3}, {:.3})", j.point[0], j.point[1]))
        .collect();
    reportln!(
        "{}: {} sharp edge(s) at {} mm: fitted face by face, {} faces joined at the edges (--edges none for one \
         polynomial)",
        label,
        edges.len(),
        edges.join(", "),
        fitted.faces.len()
    )?;
    let faces = fitted
        .faces
        .iter()
        .zip(&fitted.held_out)
        .zip(&fitted.face_points);
    for (j, ((face, held_out), points)) in faces.enumerate() {
        let chosen = if held_out.is_empty() {
            "given".to_string()
        } else {
            let scores: Vec<String> = held_out
                .iter()
                .map(|(d, rms)| format!("{d}: {:.2} um", rms * 1000.0))
                .collect();
            format!("chosen by held-out RMS, {}", scores.join(", "))
        };
        reportln!(
            "  face {j}: degree {} ({chosen}), {} points, RMS {:.4} mm, max {:.4} mm",
            face.model.degree(),
            points,
            face.stats.rms_distance_mm,
            face.stats.max_distance_mm
        )?;
    }
    if !fitted.joint_gaps_mm.is_empty() {
        let gaps: Vec<String> = fitted
            .joint_gaps_mm
            .iter()
            .map(|g| format!("{:.2} um", g * 1000.0))
            .collect();
        reportln!(
            "  at the smooth joints the faces' curves pass {} apart (the model's step there)",
            gaps.join(", ")
        )?;
    }
    let faced = FacedIp::of(fitted, points);
    let stats = faced.fit.expect("a profile of faces' statistics");
    reportln!(
        "  distance of the fitted points to the joined faces: RMS {:.4} mm, max {:.4} mm",
        stats.rms_distance_mm,
        stats.max_distance_mm
    )?;
    if let Some(tolerance) = args.tolerance {
        if stats.max_distance_mm > tolerance {
            bail!(
                "{}: the faces' fit reaches {:.4} mm at worst, beyond the part's tolerance of {tolerance} mm: no \
                 model saved; check the points for strays, or give --degree",
                label,
                stats.max_distance_mm
            );
        }
    }
    Ok(Some(faced))
}

/// A profile fitted as one polynomial, printed, at the degree [`held_out_or_given`] takes.
fn one_polynomial(
    args: &FitIpArgs,
    points: &[Vector2<f64>],
    lines: &[u64],
) -> anyhow::Result<(ReferenceModel, FitMethod)> {
    let path = &args.points;
    let rows = || rows_of(path, lines, 0..points.len());
    let normals = profile_normals(points, args.normals).map_err(|e| anyhow!("{}: {e}", rows()))?;
    let fitted = held_out_or_given(args.degree, points, &normals, args.method.into(), &rows)?;
    print_fit(path, "profile", &fitted.fitted, points, args.tolerance)?;
    fitted.print_degree()?;
    Ok((
        ReferenceModel::Profile(FittedIp::from(fitted.fitted.clone())),
        fitted.fitted.method,
    ))
}

/// One polynomial's fit, and how its degree was chosen when none was given.
struct DegreeChosen<const N: usize> {
    fitted: Fitted<N>,
    /// The held-out RMS of each degree tried; empty when the degree was given.
    scores: Vec<(usize, f64)>,
    /// The degree the held-out points chose, and why its fit was passed over where another was taken.
    chosen: usize,
    passed_over: Option<String>,
}

impl<const N: usize> DegreeChosen<N> {
    /// The line saying how the degree was chosen (nothing when it was given).
    fn print_degree(&self) -> anyhow::Result<()> {
        if self.scores.is_empty() {
            return Ok(());
        }
        let degree = self.fitted.model.degree();
        let why = match &self.passed_over {
            None => "chosen by".to_string(),
            Some(problem) => format!(
                "taken because degree {}, chosen by the points held out, {problem}; see",
                self.chosen
            ),
        };
        reportln!(
            "  degree {degree} {why} the RMS distance of the points held out of the fit ({}); --degree gives one",
            held_out_list(&self.scores)
        )?;
        Ok(())
    }
}

/// One polynomial fitted to points (a profile's or a surface's) at `degree`, or where none is given at the one of
/// 4, 6 and 8 that the points held out of its fit choose; where that degree's fit has a defect the statistics show
/// (a spurious branch or sliver beside the data, points with no foot), the next best by held-out RMS whose fit has
/// none. `rows` names the points in an error.
fn held_out_or_given<const N: usize>(
    degree: Option<usize>,
    points: &[SVector<f64, N>],
    normals: &[SVector<f64, N>],
    method: FitMethod,
    rows: &dyn Fn() -> String,
) -> anyhow::Result<DegreeChosen<N>> {
    let fit = |degree: usize| {
        fit_ip(points, normals, &FitOptions::new(degree, method))
            .map_err(|e| anyhow!("{}: {e}", rows()))
    };
    if let Some(degree) = degree {
        return Ok(DegreeChosen {
            fitted: fit(degree)?,
            scores: Vec::new(),
            chosen: degree,
            passed_over: None,
        });
    }
    let scores = held_out_scores(points, normals, method);
    let chosen = choose_degree(&scores);
    let (fitted, passed_over) = clean_fit_or_chosen(chosen, &scores, fit, |fitted| {
        defects(fitted).map(|d| format!("fits with {d}"))
    });
    let fitted = fitted?;
    Ok(DegreeChosen {
        fitted,
        scores,
        chosen,
        passed_over,
    })
}

/// Whether the points are in scan order: nearly every step to the next point is about as short as the step to
/// the nearest point. Shuffled points jump across the part instead.
fn runs_along_the_profile<const N: usize>(points: &[SVector<f64, N>]) -> bool {
    let index = PointIndex::new(points);
    let n = points.len();
    let in_order = (0..n)
        .filter(|&i| {
            let next = (points[(i + 1) % n] - points[i]).norm();
            let nearest = index
                .nearest_iter(&points[i])
                .nth(1)
                .map_or(0.0, |j| (points[j] - points[i]).norm());
            next <= 4.0 * nearest
        })
        .count();
    in_order as f64 >= 0.95 * n as f64
}

/// The outward normals of a profile's points, for its 3L offsets. The caller names the points' rows in an error.
fn profile_normals(
    points: &[Vector2<f64>],
    normals: NormalsArg,
) -> anyhow::Result<Vec<Vector2<f64>>> {
    if points.len() < 3 {
        bail!("{} points are too few for a profile", points.len());
    }
    let ordered = match normals {
        NormalsArg::Ordered => true,
        NormalsArg::Pca => false,
        NormalsArg::Auto => runs_along_the_profile(points),
    };
    Ok(if ordered {
        ordered_profile_normals(points)
    } else {
        pca_normals(points)
    })
}

/// A stack whose profiles have sharp edges: each profile fitted face by face (each face's degree its own, as for
/// one profile), the faces lofted from profile to profile. `None` where edges are not looked for (`--edges none`,
/// `--normals pca`, points that do not run along their profiles) or no profile has one: one polynomial per profile
/// then serves. Profiles some with sharp edges and some without cannot be lofted face to face, and fail.
fn fit_faces_stack(
    path: &Path,
    points: &[Vector3<f64>],
    lines: &[u64],
    args: &FitIpArgs,
) -> anyhow::Result<Option<Vec<FacedStackProfile>>> {
    let planes = group_into_planes(points, args.plane_tolerance);
    let profiles: Vec<(f64, Vec<Vector2<f64>>, String)> = planes
        .iter()
        .map(|(x, indices)| {
            let yz = indices
                .iter()
                .map(|&i| Vector2::new(points[i].y, points[i].z))
                .collect();
            let rows = rows_of(path, lines, indices.iter().copied());
            (*x, yz, format!("{rows}: the profile at x = {x:.3} mm"))
        })
        .collect();
    let looked_for = profiles.len() >= 2 && profiles.iter().all(|(_, yz, _)| with_faces(args, yz));
    if !looked_for {
        return Ok(None);
    }
    let mut fitted = Vec::with_capacity(profiles.len());
    for (x, yz, label) in &profiles {
        fitted.push((*x, fit_faces_of(args, label, yz, false)?));
    }
    let without: Vec<String> = fitted
        .iter()
        .filter(|(_, faced)| faced.is_none())
        .map(|(x, _)| format!("{x:.3}"))
        .collect();
    if without.len() == fitted.len() {
        return Ok(None);
    }
    if !without.is_empty() {
        bail!(
            "{}: the profiles at x = {} mm have no sharp edge while the others have: a stack is lofted face to face \
             between like profiles; check those profiles' points, or fit one polynomial per profile with --edges \
             none",
            path.display(),
            without.join(", ")
        );
    }
    let profiles: Vec<FacedStackProfile> = fitted
        .into_iter()
        .filter_map(|(x, faced)| Some(FacedStackProfile { x, profile: faced? }))
        .collect();
    let loft = FacedLoft::new(faced_sections(&profiles)).map_err(|e| {
        anyhow!(
            "{}: {e}; check the profiles' points, or fit one polynomial per profile with --edges none",
            path.display()
        )
    })?;
    reportln!(
        "stack of faces: {} profiles, each face lofted through the same face of every profile ({} triangles, within \
         {:.2} um of the faces' curves and {:.2} um of the smooth loft between them)",
        profiles.len(),
        loft.triangle_count(),
        loft.sag_mm * 1000.0,
        loft.surface_mm * 1000.0
    )?;
    Ok(Some(profiles))
}

/// A stack: one polynomial per plane of constant x, every one at the same degree (profiles blend only at equal
/// degrees). The degree is `--degree`'s, or else the one of 4, 6 and 8 that the points held out of the profiles'
/// fits choose together; where a profile's fit at it fails or has a defect the statistics show, the next best by
/// held-out RMS at which every profile fits cleanly. Errors name the profile and its own lines in the file.
fn fit_stack(
    path: &Path,
    points: &[Vector3<f64>],
    lines: &[u64],
    method: FitMethod,
    args: &FitIpArgs,
) -> anyhow::Result<Vec<StackProfile>> {
    let planes = group_into_planes(points, args.plane_tolerance);
    if planes.len() < 2 {
        bail!(
            "{}: the points lie in {} plane(s) of constant x (tolerance {} mm); a stack needs at least two",
            rows_of(path, lines, 0..points.len()),
            planes.len(),
            args.plane_tolerance
        );
    }
    let mut profiles = Vec::with_capacity(planes.len());
    for (x, indices) in planes {
        let yz: Vec<Vector2<f64>> = indices
            .iter()
            .map(|&i| Vector2::new(points[i].y, points[i].z))
            .collect();
        let rows = rows_of(path, lines, indices.iter().copied());
        let normals = profile_normals(&yz, args.normals)
            .map_err(|e| anyhow!("{rows}: the profile at x = {x:.3} mm: {e}"))?;
        profiles.push((x, yz, normals, rows));
    }
    let fit_at = |degree: usize| -> anyhow::Result<Vec<Fitted<2>>> {
        let options = FitOptions::new(degree, method);
        profiles
            .iter()
            .map(|(x, yz, normals, rows)| {
                fit_ip(yz, normals, &options)
                    .map_err(|e| anyhow!("{rows}: the profile at x = {x:.3} mm: {e}"))
            })
            .collect()
    };
    let (fits, scores, chosen, passed_over) = match args.degree {
        Some(degree) => (fit_at(degree)?, Vec::new(), degree, None),
        None => {
            let each: Vec<(usize, Vec<(usize, f64)>)> = profiles
                .iter()
                .map(|(_, yz, normals, _)| (yz.len() / 2, held_out_scores(yz, normals, method)))
                .collect();
            let scores = combined_scores(&each);
            let chosen = choose_degree(&scores);
            let (fits, passed_over) =
                clean_fit_or_chosen(chosen, &scores, fit_at, |fits: &Vec<Fitted<2>>| {
                    let defects: Vec<String> = profiles
                        .iter()
                        .zip(fits)
                        .filter_map(|((x, ..), fitted)| {
                            let defects = defects(fitted)?;
                            Some(format!("fits the profile at x = {x:.3} mm with {defects}"))
                        })
                        .collect();
                    (!defects.is_empty()).then(|| defects.join("; "))
                });
            let fits = fits?;
            (fits, scores, chosen, passed_over)
        }
    };
    if !scores.is_empty() {
        let degree = fits[0].model.degree();
        let why = match passed_over {
            None => "chosen by".to_string(),
            Some(problem) => format!(
                "taken because degree {chosen}, chosen by the points held out, {problem}; see"
            ),
        };
        reportln!(
            "stack degree {degree} {why} the RMS distance of the points held out of its profiles' fits ({}); \
             --degree gives one",
            held_out_list(&scores)
        )?;
    }
    profiles
        .iter()
        .zip(fits)
        .map(|((x, yz, ..), fitted)| {
            print_fit(
                path,
                &format!("profile at x = {x:.3} mm"),
                &fitted,
                yz,
                args.tolerance,
            )?;
            Ok(StackProfile {
                x: *x,
                fitted: FittedIp::from(fitted),
            })
        })
        .collect()
}

/// The defects a fit's statistics show, as a phrase ("2 spurious branches beside the data and 3 points with no
/// foot"), or `None` for a clean fit: a spurious branch or sliver beside the data, or a point with no foot.
fn defects<const N: usize>(fitted: &Fitted<N>) -> Option<String> {
    let s = &fitted.stats;
    let count = |n: usize, one: &str, many: &str| match n {
        0 => None,
        1 => Some(format!("1 {one}")),
        n => Some(format!("{n} {many}")),
    };
    let found: Vec<String> = [
        count(
            s.branches_beside_data,
            "spurious branch beside the data",
            "spurious branches beside the data",
        ),
        count(
            s.side_segments_crossed_again,
            "segment across the data crossed twice (a sliver)",
            "segments across the data crossed twice (a sliver)",
        ),
        count(
            s.points_without_foot,
            "point with no foot",
            "points with no foot",
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    (!found.is_empty()).then(|| found.join(" and "))
}

/// Held-out scores as printed: "4: 2.10 um, 6: ...".
fn held_out_list(scores: &[(usize, f64)]) -> String {
    scores
        .iter()
        .map(|(d, rms)| format!("{d}: {:.2} um", rms * 1000.0))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Splits points into planes of (nearly) constant x: each plane's mean x and its points' indices, in file order.
fn group_into_planes(points: &[Vector3<f64>], tolerance: f64) -> Vec<(f64, Vec<usize>)> {
    let mut xs: Vec<f64> = points.iter().map(|p| p.x).collect();
    xs.sort_by(f64::total_cmp);
    let mut centres: Vec<Vec<f64>> = Vec::new();
    for x in xs {
        match centres.last_mut() {
            Some(group) if x - group[group.len() - 1] <= tolerance => group.push(x),
            _ => centres.push(vec![x]),
        }
    }
    let bounds: Vec<(f64, f64)> = centres.iter().map(|g| (g[0], g[g.len() - 1])).collect();
    bounds
        .iter()
        .map(|&(lo, hi)| {
            let plane: Vec<usize> = (0..points.len())
                .filter(|&i| points[i].x >= lo && points[i].x <= hi)
                .collect();
            let x = plane.iter().map(|&i| points[i].x).sum::<f64>() / plane.len() as f64;
            (x, plane)
        })
        .collect()
}

/// The fit's statistics, and each doubt they raise about it (see [`fit_sanity::doubts`]).
fn print_fit<const N: usize>(
    path: &Path,
    what: &str,
    fitted: &Fitted<N>,
    points: &[SVector<f64, N>],
    tolerance_mm: Option<f64>,
) -> anyhow::Result<()> {
    let s = &fitted.stats;
    let at: Vec<String> = s
        .max_distance_at
        .iter()
        .map(|c| format!("{c:.3}"))
        .collect();
    reportln!(
        "fitted a degree-{} implicit polynomial ({what}) to {} points of {} by {}",
        fitted.model.degree(),
        s.points,
        path.display(),
        fitted.method.describe()
    )?;
    reportln!(
        "  distance of the fitted points to the model: RMS {:.4} mm, max {:.4} mm at ({}) mm",
        s.rms_distance_mm,
        s.max_distance_mm,
        at.join(", ")
    )?;
    reportln!(
        "  condition number {:.1e}; 3L offsets {:.3} to {:.3} mm; {} refinement iterations",
        s.condition_number,
        s.offset_min_mm,
        s.offset_max_mm,
        s.refinement_iterations
    )?;
    reportln!(
        "  zero set: {} component(s) within twice the data's box, {} spurious branch(es) beside the data",
        s.zero_set_components, s.branches_beside_data
    )?;
    let scatter = fit_sanity::scatter_mm(points);
    for doubt in fit_sanity::doubts(s, scatter, &fitted.domain, tolerance_mm) {
        reportln!("  warning: {doubt}")?;
    }
    Ok(())
}

/// Points that stand far from all others are named by their lines before the fit: an export error, or a touch of
/// something else, pulls the whole model.
fn warn_of_isolated_points(file: &PointFile) -> anyhow::Result<()> {
    let isolated = match &file.points {
        PointSet::Profile(points) => fit_sanity::isolated_points(points),
        PointSet::Spatial(points) => fit_sanity::isolated_points(points),
    };
    if isolated.is_empty() {
        return Ok(());
    }
    let lines: Vec<String> = isolated
        .iter()
        .take(10)
        .map(|&i| file.lines[i].to_string())
        .collect();
    let more = if isolated.len() > 10 { ", ..." } else { "" };
    reportln!(
        "warning: {} point(s) stand far from all the others (line {}{more}): an export error or a touch of \
         something else? remove them and fit again",
        isolated.len(),
        lines.join(", ")
    )?;
    Ok(())
}

/// The planes of constant x (their mean x) that 3-D points lie in when they are profiles: two or more planes each
/// holding a scanned profile's points, together nearly all the points (a stray point off every plane does not make
/// them a surface's). `None` for points spread over a surface.
fn profile_planes(points: &[Vector3<f64>], plane_tolerance: f64) -> Option<Vec<f64>> {
    let profiles: Vec<(f64, Vec<usize>)> = group_into_planes(points, plane_tolerance)
        .into_iter()
        .filter(|(_, plane)| plane.len() >= MIN_PROFILE_POINTS)
        .collect();
    let in_profiles: usize = profiles.iter().map(|(_, plane)| plane.len()).sum();
    (profiles.len() >= 2 && in_profiles as f64 >= IN_PROFILES * points.len() as f64)
        .then(|| profiles.iter().map(|(x, _)| *x).collect())
}

/// The share of 3-D points that planes of profiles hold when the points are profiles.
const IN_PROFILES: f64 = 0.95;

/// A plane of constant x holding at least this many points is a scanned profile, not a scatter of surface points.
const MIN_PROFILE_POINTS: usize = 10;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_are_told_from_a_surface_s_points_even_with_a_stray_point_off_their_planes() {
        let circle = |x: f64| {
            (0..20).map(move |i| {
                let t = i as f64 / 20.0 * std::f64::consts::TAU;
                Vector3::new(x, 10.0 * t.cos(), 5.0 * t.sin())
            })
        };
        let mut profiles: Vec<Vector3<f64>> =
            [100.0, 200.0, 300.0].into_iter().flat_map(circle).collect();
        assert_eq!(
            profile_planes(&profiles, 1.0),
            Some(vec![100.0, 200.0, 300.0])
        );
        // One point between the planes is a plane of its own, too small for a profile.
        profiles.push(Vector3::new(150.0, 0.0, 0.0));
        assert_eq!(
            profile_planes(&profiles, 1.0),
            Some(vec![100.0, 200.0, 300.0])
        );
        // Points spread along x are a surface's.
        let spread: Vec<Vector3<f64>> = (0..60)
            .map(|i| Vector3::new(i as f64 * 5.0, (i as f64).cos(), (i as f64).sin()))
            .collect();
        assert_eq!(profile_planes(&spread, 1.0), None);
    }

    #[test]
    fn a_fit_s_defects_are_named_with_their_counts() {
        let points: Vec<Vector2<f64>> = (0..40)
            .map(|i| {
                let t = i as f64 / 40.0 * std::f64::consts::TAU;
                Vector2::new(10.0 * t.cos(), 5.0 * t.sin())
            })
            .collect();
        let normals = ordered_profile_normals(&points);
        let mut fitted = fit_ip(&points, &normals, &FitOptions::new(2, FitMethod::ThreeL)).unwrap();
        assert_eq!(defects(&fitted), None, "an ellipse's conic is clean");
        fitted.stats.branches_beside_data = 1;
        fitted.stats.points_without_foot = 3;
        assert_eq!(
            defects(&fitted).as_deref(),
            Some("1 spurious branch beside the data and 3 points with no foot")
        );
        fitted.stats.branches_beside_data = 0;
        fitted.stats.points_without_foot = 0;
        fitted.stats.side_segments_crossed_again = 2;
        assert_eq!(
            defects(&fitted).as_deref(),
            Some("2 segments across the data crossed twice (a sliver)")
        );
    }
}
