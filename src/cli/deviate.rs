//! `zeroset deviate`: signed deviations of measured points from a reference model, written to a CSV file with a
//! summary on the terminal.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::anyhow;
use clap::Args;
use nalgebra::{SVector, Vector3};
use rayon::prelude::*;

use super::DistanceArg;
use crate::fsutil::write_atomically;
use crate::geometry::distance::{
    signed_distances, DistanceError, DistanceMethod, ExactDistance, StackDistance,
    CERTIFICATE_TOLERANCE_MM,
};
use crate::geometry::faces::FacedLoft;
use crate::geometry::implicit::Implicit;
use crate::geometry::sampling::{Aabb, ZeroSetSamples};
use crate::geometry::supershape::distance::SolidDistance;
use crate::model_file::{faced_sections, stack_of, ModelFile, ReferenceModel};
use crate::points::{read_point_file, PointSet};

/// Zero-set sampling for exact-distance seeds: cells along the longest side of twice the model's data box.
const PROFILE_CELLS: usize = 512;
const SURFACE_CELLS: usize = 96;

#[derive(Args)]
pub struct DeviateArgs {
    /// The reference model (a model file written by `zeroset fit`).
    #[arg(long)]
    model: PathBuf,
    /// Measured points: CSV with header y,z (for a profile model) or x,y,z (for a surface or stack), in mm.
    #[arg(long)]
    points: PathBuf,
    #[arg(long, value_enum, default_value = "exact")]
    distance: DistanceArg,
    /// The CSV file to write: the points with a column deviation_mm and a status per point.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: &DeviateArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let file = ModelFile::load(&args.model)?;
    let point_file = read_point_file(&args.points)?;
    let points = &point_file.points;
    let method: DistanceMethod = args.distance.into();
    let mismatch = |model: &str, wants: &str, has: &str| {
        anyhow!(
            "{}: the model {} is {model}, which needs {wants} points; this file has {has}",
            args.points.display(),
            args.model.display()
        )
    };
    // Feet the exact distance's certificate left unproved, where the model has one (implicit polynomials).
    let mut unproved = None;
    let (rows, distances): (Vec<Vec<f64>>, Vec<Result<f64, DistanceError>>) =
        match (&file.model, points) {
            (ReferenceModel::Profile(m), PointSet::Profile(p)) => {
                let range = m.domain.scaled(RANGE);
                let distances = within(&range, p, |p| {
                    distances_to(&m.ip, &range, PROFILE_CELLS, p, method, &mut unproved)
                });
                (coordinates(p), distances)
            }
            (ReferenceModel::Surface(m), PointSet::Spatial(p)) => {
                let range = m.domain.scaled(RANGE);
                let distances = within(&range, p, |p| {
                    distances_to(&m.ip, &range, SURFACE_CELLS, p, method, &mut unproved)
                });
                (coordinates(p), distances)
            }
            (ReferenceModel::Stack { profiles }, PointSet::Spatial(p)) => {
                let stack =
                    stack_of(profiles).map_err(|e| anyhow!("{}: {e}", args.model.display()))?;
                // The stack sorts its profiles along x; pair each with its own domain in that order.
                let mut sorted = profiles.clone();
                sorted.sort_by(|a, b| a.x.total_cmp(&b.x));
                let domains: Vec<Aabb<2>> = sorted.iter().map(|p| p.fitted.domain).collect();
                let range = stack.bounds(&domains).scaled(RANGE);
                let reach = 2.0 * range.diagonal();
                let distances = within(&range, p, |p| {
                    signed_distances(&stack, p, method, reach, |points| {
                        let exact = StackDistance::new(&stack, &domains);
                        // Each point's foot is searched and proved on its own: in parallel.
                        let distances = points
                            .par_iter()
                            .map(|q| exact.foot(q).map(|f| f.distance))
                            .collect();
                        unproved = Some(exact.uncertified());
                        distances
                    })
                });
                (coordinates(p), distances)
            }
            (ReferenceModel::Supershape { solid, .. }, PointSet::Spatial(p)) => {
                exact_only(method, &args.model, "a supershape model")?;
                let exact = SolidDistance::new(solid);
                let bounds = solid.bounds();
                let range = Aabb {
                    min: bounds.min.coords,
                    max: bounds.max.coords,
                }
                .scaled(RANGE);
                let distances = within(&range, p, |p| {
                    p.iter()
                        .map(|q| {
                            exact
                                .foot(&nalgebra::Point3::from(*q))
                                .map(|f| f.distance_mm)
                                .ok_or(DistanceError::NoFootPoint)
                        })
                        .collect()
                });
                (coordinates(p), distances)
            }
            (ReferenceModel::Faces(faced), PointSet::Profile(p)) => {
                exact_only(
                    method,
                    &args.model,
                    "a profile of faces (its sharp edges have no first-order estimate)",
                )?;
                let profile = faced
                    .profile()
                    .map_err(|e| anyhow!("{}: {e}", args.model.display()))?;
                let range = faced.domain().scaled(RANGE);
                // Every foot the faces give is proved nearest by the traced faces' bound, or there is none.
                unproved = Some(0);
                let distances = within(&range, p, |p| {
                    p.iter()
                        .map(|q| {
                            profile
                                .foot(q)
                                .map(|f| f.distance)
                                .ok_or(DistanceError::NoFootPoint)
                        })
                        .collect()
                });
                (coordinates(p), distances)
            }
            (ReferenceModel::FacesStack { profiles }, PointSet::Spatial(p)) => {
                exact_only(
                    method,
                    &args.model,
                    "a stack of faces (its sharp edges have no first-order estimate)",
                )?;
                let loft = FacedLoft::new(faced_sections(profiles))
                    .map_err(|e| anyhow!("{}: {e}", args.model.display()))?;
                let (first, last) = loft.span();
                let yz = profiles
                    .iter()
                    .map(|p| p.profile.domain())
                    .reduce(|a, b| Aabb {
                        min: a.min.inf(&b.min),
                        max: a.max.sup(&b.max),
                    })
                    .expect("a stack has profiles")
                    .scaled(2.0);
                let range = Aabb {
                    min: Vector3::new(first, yz.min.x, yz.min.y),
                    max: Vector3::new(last, yz.max.x, yz.max.y),
                }
                .scaled(RANGE);
                // The nearest of the loft's triangles, found by the R*-tree's bounds: every foot is the nearest.
                unproved = Some(0);
                let distances = within(&range, p, |p| {
                    p.par_iter()
                        .map(|q| loft.foot(q).map(|f| f.distance))
                        .collect()
                });
                (coordinates(p), distances)
            }
            (ReferenceModel::Profile(_) | ReferenceModel::Faces(_), PointSet::Spatial(_)) => {
                return Err(mismatch("a profile", "y,z", "x,y,z"))
            }
            (_, PointSet::Profile(_)) => return Err(mismatch("3-D", "x,y,z", "y,z")),
        };
    let header: &[&str] = if rows[0].len() == 2 {
        &["y", "z"]
    } else {
        &["x", "y", "z"]
    };
    write_csv(&args.out, header, &rows, &distances)?;
    print_summary(&args.points, &file, method, &distances)?;
    if let Some(unproved) = unproved {
        print_certificates(&distances, unproved)?;
    }
    name_points_out_of_range(&point_file.lines, &distances)?;
    if distances.iter().all(Result::is_err) {
        anyhow::bail!(
            "{}: no point has a deviation from {} (see the status column of {})",
            args.points.display(),
            args.model.display(),
            args.out.display()
        );
    }
    reportln!(
        "wrote {} ({:.2} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    )?;
    Ok(())
}

/// Models with no first-order distance estimate (sharp edges, CSG) are measured by the exact distance only.
fn exact_only(method: DistanceMethod, model: &Path, what: &str) -> anyhow::Result<()> {
    if method != DistanceMethod::Exact {
        anyhow::bail!(
            "{}: {what} is measured by the exact Euclidean distance only; leave out --distance or give --distance \
             exact",
            model.display()
        );
    }
    Ok(())
}

/// A model answers for the region it was fitted in: its data's box (the solid's box, for a supershape) with every
/// side doubled, where the zero set is sampled. A point beyond it is not measured: a distance taken from a
/// polynomial extrapolated a kilometre out is a number, not a deviation, and would swamp the statistics.
const RANGE: f64 = 2.0;

/// Measures the points within `range` by `measure`; the others are [`DistanceError::OutsideModelRange`].
fn within<const N: usize>(
    range: &Aabb<N>,
    points: &[SVector<f64, N>],
    measure: impl FnOnce(&[SVector<f64, N>]) -> Vec<Result<f64, DistanceError>>,
) -> Vec<Result<f64, DistanceError>> {
    let inside = |p: &SVector<f64, N>| (0..N).all(|k| p[k] >= range.min[k] && p[k] <= range.max[k]);
    let measured: Vec<SVector<f64, N>> = points.iter().copied().filter(inside).collect();
    let mut distances = measure(&measured).into_iter();
    points
        .iter()
        .map(|p| {
            if inside(p) {
                distances.next().unwrap_or(Err(DistanceError::NoFootPoint))
            } else {
                Err(DistanceError::OutsideModelRange)
            }
        })
        .collect()
}

/// The lines of the points left unmeasured for being outside the model's range, so the operator can find them.
fn name_points_out_of_range(
    lines: &[u64],
    distances: &[Result<f64, DistanceError>],
) -> anyhow::Result<()> {
    let outside: Vec<String> = distances
        .iter()
        .zip(lines)
        .filter(|(d, _)| matches!(d, Err(DistanceError::OutsideModelRange)))
        .map(|(_, line)| line.to_string())
        .collect();
    if outside.is_empty() {
        return Ok(());
    }
    let shown = outside.len().min(10);
    let more = if outside.len() > shown { ", ..." } else { "" };
    reportln!(
        "  warning: {} point(s) lie far outside the model's range (its data's box, doubled) and were not measured \
         (line {}{more}): points of another part, or a unit or export error?",
        outside.len(),
        outside[..shown].join(", ")
    )?;
    Ok(())
}

fn coordinates<const N: usize>(points: &[SVector<f64, N>]) -> Vec<Vec<f64>> {
    points.iter().map(|p| p.iter().copied().collect()).collect()
}

/// Signed distances by `method`; for the exact one, `unproved` is set to how many feet its certificate left
/// unproved.
fn distances_to<const N: usize>(
    model: &impl Implicit<N>,
    bounds: &Aabb<N>,
    cells: usize,
    points: &[SVector<f64, N>],
    method: DistanceMethod,
    unproved: &mut Option<usize>,
) -> Vec<Result<f64, DistanceError>> {
    signed_distances(model, points, method, 2.0 * bounds.diagonal(), |points| {
        let samples = ZeroSetSamples::new(model, bounds, cells);
        let exact = ExactDistance::new(model, &samples);
        let distances = exact
            .feet_along_scan(points)
            .into_iter()
            .map(|foot| foot.map(|f| f.distance))
            .collect();
        *unproved = Some(exact.uncertified());
        distances
    })
}

/// Says how many exact distances are proved global minima: a Newton foot is only ever a critical point.
fn print_certificates(
    distances: &[Result<f64, DistanceError>],
    unproved: usize,
) -> anyhow::Result<()> {
    let measured = distances.iter().filter(|d| d.is_ok()).count();
    reportln!(
        "  certificate: {} of {measured} distances proved the global minimum (no zero of the model nearer, to \
         {:.0e} mm)",
        measured.saturating_sub(unproved),
        CERTIFICATE_TOLERANCE_MM
    )?;
    if unproved > 0 {
        reportln!(
            "  warning: {unproved} distance(s) left unproved: each is the nearest foot the search found, which the \
             certificate could neither prove nor beat within its budget (most often a point on a centre of \
             curvature, where two feet are about equally near)"
        )?;
    }
    Ok(())
}

fn write_csv(
    path: &std::path::Path,
    header: &[&str],
    rows: &[Vec<f64>],
    distances: &[Result<f64, DistanceError>],
) -> anyhow::Result<()> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    let mut columns: Vec<&str> = header.to_vec();
    columns.extend(["deviation_mm", "status"]);
    writer.write_record(&columns)?;
    for (row, distance) in rows.iter().zip(distances) {
        let mut record: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        match distance {
            Ok(d) => record.extend([format!("{d:.7}"), "ok".to_string()]),
            Err(e) => record.extend([String::new(), e.label().to_string()]),
        }
        writer.write_record(&record)?;
    }
    let bytes = writer.into_inner().map_err(|e| anyhow!("{e}"))?;
    write_atomically(path, &bytes)?;
    Ok(())
}

fn print_summary(
    points: &std::path::Path,
    file: &ModelFile,
    method: DistanceMethod,
    distances: &[Result<f64, DistanceError>],
) -> anyhow::Result<()> {
    let values: Vec<f64> = distances
        .iter()
        .filter_map(|d| d.as_ref().ok().copied())
        .collect();
    let failed = distances.len() - values.len();
    reportln!(
        "deviations of {} from the model ({}), by the {}:",
        points.display(),
        file.method,
        method.describe()
    )?;
    if values.is_empty() {
        reportln!("  no point has a deviation")?;
    } else {
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let rms = (values.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        reportln!(
            "  n = {}, mean {mean:+.4} mm, RMS {rms:.4} mm, min {min:+.4} mm, max {max:+.4} mm",
            values.len()
        )?;
    }
    if failed > 0 {
        let hint = match method {
            DistanceMethod::Paper => {
                "the paper's approximation fails near edges; --distance exact always answers"
            }
            _ => "outside the model's range, or where the model has no zero set nearby",
        };
        reportln!("  {failed} point(s) without a deviation, see the status column ({hint})")?;
    }
    Ok(())
}
