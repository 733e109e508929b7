//! `zeroset evaluate`: where one measured section lies against its nominal profile model and its form error
//! once that is removed, by a least-squares or minimum-zone best fit in the section's plane.

use std::path::PathBuf;

use anyhow::{anyhow, bail};
use clap::{Args, ValueEnum};
use nalgebra::Vector2;

use crate::analysis::section::chord_of;
use crate::fsutil::write_atomically;
use crate::geometry::distance::ExactDistance;
use crate::geometry::implicit::Implicit;
use crate::geometry::sampling::ZeroSetSamples;
use crate::geometry::section_fit::{fit_section, FitMethod, FitMode, Form, Measured, SectionFit};
use crate::model_file::{ModelFile, ReferenceModel};
use crate::points::{read_points, PointSet};

/// Zero-set sampling for the exact distance's seeds, as `zeroset deviate` does.
const CELLS: usize = 512;

#[derive(Args)]
pub struct EvaluateArgs {
    /// The nominal: a profile model file written by `zeroset fit ip` from y,z points.
    #[arg(long)]
    model: PathBuf,
    /// The measured section: CSV with header y,z, in mm.
    #[arg(long)]
    points: PathBuf,
    /// What the best fit may move before the form is judged.
    #[arg(long, value_enum, default_value = "full")]
    fit: FitArg,
    /// What the best fit minimises.
    #[arg(long, value_enum, default_value = "l2")]
    method: MethodArg,
    /// Each point's deviation as measured and after the fit (CSV), if given.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Clone, Copy, ValueEnum)]
enum FitArg {
    /// No fit: the deviations as measured.
    None,
    /// The two translations in the section's plane.
    Translation,
    /// The translations and the rotation about the chord's middle (twist).
    Full,
}

#[derive(Clone, Copy, ValueEnum)]
enum MethodArg {
    /// Least squares: the sum of squared normal deviations.
    L2,
    /// Minimum zone (Chebyshev): the narrowest band about the nominal holding every point.
    Minzone,
}

pub fn run(args: &EvaluateArgs) -> anyhow::Result<()> {
    let file = ModelFile::load(&args.model)?;
    let ReferenceModel::Profile(model) = &file.model else {
        bail!(
            "{}: evaluate needs a profile model (fitted from y,z points); this one is 3-D",
            args.model.display()
        );
    };
    let PointSet::Profile(points) = read_points(&args.points)? else {
        bail!(
            "{}: evaluate needs a section's y,z points; this file has x,y,z",
            args.points.display()
        );
    };
    let (pivot, chord) = chord_of(&points);
    let samples = ZeroSetSamples::new(&model.ip, &model.domain.scaled(2.0), CELLS);
    let exact = ExactDistance::new(&model.ip, &samples);
    let (mode, mode_name) = match args.fit {
        FitArg::None => (FitMode::None, "no fit"),
        FitArg::Translation => (FitMode::Translation, "translations"),
        FitArg::Full => (FitMode::Full, "translations and rotation"),
    };
    let (method, method_name) = match args.method {
        MethodArg::L2 => (FitMethod::L2, "least squares"),
        MethodArg::Minzone => (FitMethod::MinZone, "minimum zone"),
    };
    let fitted = fit_section(&points, pivot, chord, mode, method, |moved| {
        exact
            .feet_along_scan(moved)
            .into_iter()
            .map(|foot| {
                let foot = foot.ok()?;
                let (_, gradient) = model.ip.value_gradient(&foot.point);
                Some(Measured {
                    distance_mm: foot.distance,
                    normal: gradient.try_normalize(0.0)?,
                })
            })
            .collect()
    })
    .map_err(|e| anyhow!("{}: {e}", args.points.display()))?;
    println!(
        "section {} ({} points) against {}; best fit: {mode_name} by {method_name}, about the chord's middle \
         ({:.3}, {:.3}) mm",
        args.points.display(),
        points.len(),
        args.model.display(),
        pivot.x,
        pivot.y
    );
    print_fit(&fitted, &chord);
    if let Some(out) = &args.out {
        write_deviations(out, &points, &fitted)?;
        println!("wrote {}", out.display());
    }
    Ok(())
}

fn print_fit(fitted: &SectionFit, chord: &Vector2<f64>) {
    let across = Vector2::new(-chord.y, chord.x);
    println!(
        "  chord direction (y, z) ({:.5}, {:.5}); thickness direction, the chord turned +90 deg, ({:.5}, {:.5})",
        chord.x, chord.y, across.x, across.y
    );
    println!(
        "  the section lies {:+.4} mm along the thickness direction and {:+.4} mm along the chord from the \
         nominal, turned {:+.4} deg (counter-clockwise +)",
        fitted.dn_mm, fitted.dchord_mm, fitted.rotation_deg
    );
    print_form("as measured:  ", &fitted.form_before);
    print_form("after the fit:", &fitted.form);
}

fn print_form(what: &str, form: &Form) {
    println!(
        "  {what} normal deviations min {:+.4} mm, max {:+.4} mm, RMS {:.4} mm, zone {:.4} mm (twice the largest)",
        form.min_mm, form.max_mm, form.rms_mm, form.zone_mm
    );
}

fn write_deviations(
    path: &std::path::Path,
    points: &[Vector2<f64>],
    fitted: &SectionFit,
) -> anyhow::Result<()> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(["y", "z", "deviation_mm", "after_fit_mm"])?;
    for ((p, before), after) in points.iter().zip(&fitted.before_mm).zip(&fitted.after_mm) {
        writer.write_record([
            p.x.to_string(),
            p.y.to_string(),
            format!("{before:.7}"),
            format!("{after:.7}"),
        ])?;
    }
    let bytes = writer.into_inner().map_err(|e| anyhow!("{e}"))?;
    write_atomically(path, &bytes)?;
    Ok(())
}
