//! `zeroset fit supershape`: recover a supershape model from measured x,y,z points (seed 001) and save it as a
//! model file, with the exact distances of the points to it; a part scanned in segments (`x,y,z,segment`) is
//! recovered segment by segment and joined by union (seed 001 section 6.3).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use nalgebra::Point3;

use crate::geometry::supershape::csg::Solid;
use crate::geometry::supershape::distance::SolidDistance;
use crate::geometry::supershape::recover::{
    recover, recover_segments, Family, Recovered, RecoveryOptions, SegmentPoints,
};
use crate::model_file::{ModelFile, ReferenceModel, SolidFitStats};
use crate::points::read_segments;

#[derive(Args)]
pub struct FitSupershapeArgs {
    /// Point file: CSV with header x,y,z, in mm, spread over the part's surface; or x,y,z,segment for a part
    /// scanned in segments, each recovered on its own and all joined by union.
    #[arg(long)]
    points: PathBuf,
    /// The symmetry numbers of the two superformulas when known, "m1,m2" (a superquadric is 4,4; a hex prism
    /// 6,4); found from the points otherwise.
    #[arg(long, value_parser = parse_symmetry)]
    symmetry: Option<[u32; 2]>,
    /// Fit a superquadric (m1 = m2 = 4, each superformula's exponents equal: 11 parameters, epsilon1 along the
    /// axis, epsilon2 across it) instead of a general supershape.
    #[arg(long)]
    superquadric: bool,
    /// Keep the whole supershape: do not cut it by the points' oriented bounding box.
    #[arg(long)]
    no_truncation: bool,
    /// Do not look for holes (points well inside the envelope, fitted as negative primitives).
    #[arg(long)]
    no_holes: bool,
    /// The model file to write (JSON).
    #[arg(long)]
    out: PathBuf,
}

fn parse_symmetry(text: &str) -> Result<[u32; 2], String> {
    let numbers: Vec<u32> = text
        .split(',')
        .map(|v| v.trim().parse::<u32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{text:?}: {e}; give two whole numbers m1,m2"))?;
    match numbers[..] {
        [m1, m2] if m1 > 0 && m2 > 0 => Ok([m1, m2]),
        _ => Err(format!(
            "{text:?}: give two whole numbers above zero, m1,m2"
        )),
    }
}

pub fn run(args: &FitSupershapeArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let segments: Vec<SegmentPoints> = read_segments(&args.points)?
        .into_iter()
        .map(|s| SegmentPoints {
            label: s.label,
            points: s.points.into_iter().map(Point3::from).collect(),
        })
        .collect();
    let family = if args.superquadric {
        Family::Superquadric
    } else {
        Family::Supershape
    };
    let what = family.name();
    let options = RecoveryOptions {
        family,
        symmetry: args.symmetry,
        truncate: !args.no_truncation,
        holes: !args.no_holes,
    };
    let (solid, method) = match &segments[..] {
        [one] if one.label.is_empty() => whole(args, &one.points, &options, what)?,
        _ => segmented(args, &segments, &options, what)?,
    };
    let points: Vec<Point3<f64>> = segments.iter().flat_map(|s| s.points.clone()).collect();
    let stats = SolidFitStats::of(&SolidDistance::new(&solid), &points);
    let file = ModelFile::new(method, ReferenceModel::Supershape { solid, fit: stats });
    file.save(&args.out)?;
    match stats {
        Some(s) => reportln!(
            "  exact distances of the points: RMS {:.4} mm, max {:.4} mm",
            s.rms_distance_mm,
            s.max_distance_mm
        ),
        None => reportln!("  some points have no exact distance to the model"),
    }?;
    reportln!(
        "wrote {} ({:.2} s)",
        args.out.display(),
        started.elapsed().as_secs_f64()
    )?;
    Ok(())
}

/// One part's points recovered as one envelope (with its holes): the solid and how it was found.
fn whole(
    args: &FitSupershapeArgs,
    points: &[Point3<f64>],
    options: &RecoveryOptions,
    what: &str,
) -> anyhow::Result<(Solid, String)> {
    // A recovery tries dozens of starts and takes seconds: say so before the wait.
    eprintln!(
        "recovering a {what} from {} points of {} (a few seconds)...",
        points.len(),
        args.points.display()
    );
    let recovered =
        recover(points, options).map_err(|e| anyhow::anyhow!("{}: {e}", args.points.display()))?;
    let (primitives, booleans) = recovered.solid.root().counts();
    reportln!(
        "{what} of {}: {} points, {primitives} primitives and {booleans} Booleans, symmetry {},{}, global error \
         (eq. 15) {:.4e} mm^3",
        args.points.display(),
        points.len(),
        recovered.symmetry[0],
        recovered.symmetry[1],
        recovered.global_error
    )?;
    describe(args, &recovered)?;
    let method = format!("{what} recovery (seed 001): {}", how_found(&recovered));
    Ok((recovered.solid, method))
}

/// A segmented part's points (`x,y,z,segment`) recovered segment by segment and joined by R_p union.
fn segmented(
    args: &FitSupershapeArgs,
    segments: &[SegmentPoints],
    options: &RecoveryOptions,
    what: &str,
) -> anyhow::Result<(Solid, String)> {
    let object = recover_segments(segments, options, &mut |k, segment| {
        eprintln!(
            "recovering segment '{}' ({} of {}) as a {what} from {} points (a few seconds)...",
            segment.label,
            k + 1,
            segments.len(),
            segment.points.len()
        )
    })
    .map_err(|e| anyhow::anyhow!("{}: {e}", args.points.display()))?;
    let (primitives, booleans) = object.solid.root().counts();
    reportln!(
        "{} segments of {} joined by R_p union: {} points, {primitives} primitives and {booleans} Booleans, \
         global error (eq. 15) {:.4e} mm^3",
        object.segments.len(),
        args.points.display(),
        segments.iter().map(|s| s.points.len()).sum::<usize>(),
        object.global_error
    )?;
    let mut found = Vec::new();
    for (segment, scanned) in object.segments.iter().zip(segments) {
        reportln!(
            "  segment '{}': {} points, symmetry {},{}, global error {:.4e} mm^3",
            segment.label,
            scanned.points.len(),
            segment.recovered.symmetry[0],
            segment.recovered.symmetry[1],
            segment.recovered.global_error
        )?;
        describe(args, &segment.recovered)?;
        found.push(format!(
            "segment '{}': {}",
            segment.label,
            how_found(&segment.recovered)
        ));
    }
    let method = format!(
        "{what} recovery (seed 001) of {} segments joined by R_p union; {}",
        object.segments.len(),
        found.join("; ")
    );
    Ok((object.solid, method))
}

/// The search behind one recovery, for the model file.
fn how_found(recovered: &Recovered) -> String {
    let how = |k: usize| recovered.symmetry_source[k].describe();
    format!(
        "Levenberg-Marquardt on the radial cost, {} starts, symmetry m1 = {} ({}), m2 = {} ({})",
        recovered.starts,
        recovered.symmetry[0],
        how(0),
        recovered.symmetry[1],
        how(1)
    )
}

/// One recovery's envelope, superquadric and holes, as printed lines.
fn describe(args: &FitSupershapeArgs, recovered: &Recovered) -> anyhow::Result<()> {
    if args.superquadric {
        let (shape, _) = &recovered.envelope;
        reportln!(
            "  superquadric: sizes {:.4}, {:.4}, {:.4} mm, epsilon1 {:.4} (along its axis), epsilon2 {:.4} (across)",
            shape.scale[0],
            shape.scale[1],
            shape.scale[2],
            2.0 / shape.r2.n1,
            2.0 / shape.r1.n1
        )?;
    }
    let through = recovered.holes.iter().filter(|h| h.through).count();
    reportln!(
        "  envelope: RMS radial distance {:.4} mm; {} hole(s) ({through} through)",
        recovered.rms_radial_mm,
        recovered.holes.len()
    )?;
    Ok(())
}
