//! `zeroset sweep PART`: the clearance of every move of the part's inspection plan (issue 6) as a table, and the
//! perspective silhouette of the ball swept along the plan's free moves (seed 002) as SVG.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use nalgebra::{Point3, Vector3};

use crate::config::StationConfig;
use crate::fsutil::write_atomically;
use crate::geometry::sweep::silhouette::{ball_silhouette, silhouette_svg, View};
use crate::station::clearance::{sweep_plan, CheckedMove, MoveKind};

/// Silhouettes are traced with steps of this, mm: a tenth of a typical ball radius.
const SILHOUETTE_STEP_MM: f64 = 0.1;
const SVG_SIZE_PX: f64 = 800.0;

#[derive(Debug, Args)]
pub struct SweepArgs {
    /// The part, as its config/parts/PART.toml names it; it must have been taught.
    pub part: String,
    /// The station's configuration (probe, safety margin, folders).
    #[arg(long, default_value = "config/station.toml")]
    pub config: PathBuf,
    /// Where the silhouette is seen from, machine coordinates in mm: "x,y,z". By default above and in front of
    /// the part, two of its sizes away.
    #[arg(long, value_parser = parse_point)]
    pub eye: Option<Point3<f64>>,
    /// The folder for clearance.csv and silhouette.svg.
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
}

fn parse_point(text: &str) -> Result<Point3<f64>, String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|v| v.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{text:?}: {e}; give x,y,z in mm"))?;
    match values[..] {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok(Point3::new(x, y, z)),
        _ => Err(format!("{text:?}: give three numbers x,y,z in mm")),
    }
}

pub fn run(args: &SweepArgs) -> anyhow::Result<()> {
    let config = StationConfig::load(&args.config)?;
    let sweep = sweep_plan(&config, &args.part).map_err(anyhow::Error::msg)?;
    let margin = config.safety.move_margin_mm;
    // The chord tolerance to the micrometre: the mesh's error is no finer than that.
    reportln!(
        "part {}: {} moves of its inspection checked against the taught model ({} triangles, chord tolerance \
         {:.3} mm); the stylus as the largest the station accepts: ball radius {} mm ([safety] max_ball_radius_mm), \
         shank radius {} mm, length {} mm; margin {margin} mm; distances in mm",
        args.part,
        sweep.moves.len(),
        sweep.part.triangle_count(),
        sweep.part.chord_tolerance_mm(),
        sweep.stylus.ball_radius_mm,
        sweep.stylus.shank.radius_mm,
        sweep.stylus.shank.length_mm,
    )?;
    reportln!(
        "{:>5}  {:<10} {:<8} {:<24} {:>10}  {:<6}  closest part point",
        "move",
        "instance",
        "profile",
        "kind",
        "min mm",
        "by"
    )?;
    let mut rows = vec![
        "move,instance,profile,kind,min_distance_mm,stylus_part,x_mm,y_mm,z_mm,verdict".to_string(),
    ];
    for (index, checked) in sweep.moves.iter().enumerate() {
        let (instance, profile) = names(&sweep.plan, checked);
        let c = &checked.clearance;
        let verdict = verdict(checked, margin);
        reportln!(
            "{index:>5}  {instance:<10} {profile:<8} {:<24} {:>10.3}  {:<6}  ({:.3}, {:.3}, {:.3}) {verdict}",
            checked.planned.kind.describe(),
            c.min_distance_mm,
            c.stylus_part,
            c.at_point.x,
            c.at_point.y,
            c.at_point.z
        )?;
        rows.push(format!(
            "{index},{instance},{profile},{},{:.6},{},{:.6},{:.6},{:.6},{verdict}",
            checked.planned.kind.describe(),
            c.min_distance_mm,
            c.stylus_part,
            c.at_point.x,
            c.at_point.y,
            c.at_point.z
        ));
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let table = args.out.join("clearance.csv");
    write_atomically(&table, (rows.join("\n") + "\n").as_bytes())
        .with_context(|| format!("cannot write {}", table.display()))?;
    let svg = args.out.join("silhouette.svg");
    let pieces = write_silhouette(&sweep, args.eye, &svg)?;
    reportln!(
        "wrote {} and {} ({pieces} silhouette components)",
        table.display(),
        svg.display()
    )?;
    let refused = sweep
        .moves
        .iter()
        .filter(|c| verdict(c, margin) == "REFUSED")
        .count();
    if refused > 0 {
        anyhow::bail!("{refused} moves come closer than the {margin} mm margin: the daemon refuses this inspection");
    }
    Ok(())
}

fn names<'p>(plan: &'p crate::plan::Plan, checked: &CheckedMove) -> (&'p str, &'p str) {
    (
        &plan.instance_names()[checked.planned.key.instance],
        plan.profile_names()[checked.planned.key.profile],
    )
}

/// A free move closer than the margin refuses the inspection; a contact scan's shank is only shown.
fn verdict(checked: &CheckedMove, margin: f64) -> &'static str {
    match (
        checked.planned.kind,
        checked.clearance.min_distance_mm < margin,
    ) {
        (_, false) => "ok",
        (MoveKind::Scan, true) => "shank near the part",
        (_, true) => "REFUSED",
    }
}

/// The silhouettes of the ball swept along every straight move, in one drawing; the number of components.
fn write_silhouette(
    sweep: &crate::station::clearance::PlanSweep,
    eye: Option<Point3<f64>>,
    path: &std::path::Path,
) -> anyhow::Result<usize> {
    let vertices = sweep.part.vertices();
    let (lo, hi) = vertices.iter().fold(
        (
            Point3::from(Vector3::repeat(f64::INFINITY)),
            Point3::from(Vector3::repeat(f64::NEG_INFINITY)),
        ),
        |(lo, hi), v| (lo.inf(v), hi.sup(v)),
    );
    let target = nalgebra::center(&lo, &hi);
    let size = (hi - lo).norm();
    let eye = eye.unwrap_or(target + Vector3::new(0.0, -2.0 * size, 1.5 * size));
    let view = View {
        eye,
        target,
        up: Vector3::z(),
    };
    let mut components = Vec::new();
    for checked in &sweep.moves {
        if checked.planned.motion.is_smooth() {
            components.extend(
                ball_silhouette(
                    &checked.planned.motion,
                    sweep.stylus.ball_radius_mm,
                    eye,
                    SILHOUETTE_STEP_MM,
                )
                .map_err(|e| anyhow::anyhow!("the silhouette of a move: {e}"))?,
            );
        }
    }
    write_atomically(
        path,
        silhouette_svg(&components, &view, SVG_SIZE_PX).as_bytes(),
    )
    .with_context(|| format!("cannot write {}", path.display()))?;
    Ok(components.len())
}
