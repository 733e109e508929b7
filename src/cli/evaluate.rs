//! `zeroset evaluate`: where one measured section lies against its nominal profile model and its form error
//! once that is removed, by a least-squares or minimum-zone best fit in the section's plane; and the section's
//! parameters (chord, maximum and edge thicknesses) measured and nominal.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail};
use clap::{Args, ValueEnum};
use nalgebra::{Point3, Vector2};

use crate::analysis::deviation::ProfileGauge;
use crate::analysis::reference::Reference;
use crate::analysis::section::{
    chord_of, faces_outline, measure_in_plane, nominal_outline, BestFitLimits, BestFitMode,
    BestFitSettings, EDGE_DISTANCE_MM,
};
use crate::fsutil::write_atomically;
use crate::geometry::distance::ExactDistance;
use crate::geometry::faces::FacedProfile;
use crate::geometry::implicit::Implicit;
use crate::geometry::sampling::ZeroSetSamples;
use crate::geometry::section_fit::{fit_section, FitMethod, Form, Measured, SectionFit};
use crate::geometry::section_parameters::{section_parameters, SectionParameters};
use crate::model_file::{FittedIp, ModelFile, ReferenceModel};
use crate::points::{read_section, SectionPoints};

/// Zero-set sampling for the exact distance's seeds, as `zeroset deviate` does.
const CELLS: usize = 512;
#[derive(Args)]
pub struct EvaluateArgs {
    /// The nominal: a profile model file written by `zeroset fit ip` from y,z points (one polynomial, or faces
    /// joined at sharp edges).
    #[arg(
        long,
        required_unless_present = "reference",
        conflicts_with = "reference"
    )]
    model: Option<PathBuf>,
    /// The nominal as the station took it: a taught reference (a report folder's reference.json, or
    /// references/PART.json in the station's data folder), with --profile naming the section's profile. The
    /// section is then measured as the station measured it live: against the profile's faces, with the master's
    /// sharp edges at the apexes of its rolls, and each point in the profile's plane.
    #[arg(long, requires = "profile")]
    reference: Option<PathBuf>,
    /// The reference's profile the section belongs to (e.g. r100).
    #[arg(long, requires = "reference")]
    profile: Option<String>,
    /// The measured section: CSV with header y,z, or y,z,roll, in mm, in order round the section (a report
    /// folder's sections/INSTANCE-PROFILE.csv holds each section the station evaluated, as it took it). roll is 1
    /// for a contact of the ball rolling round a sharp edge: a sharp end's tip is their mean, as the station takes
    /// it; without them, its farthest point, which may lie a contact's noise (microns) off.
    #[arg(long)]
    points: PathBuf,
    /// What the best fit may move before the form is judged.
    #[arg(long, value_enum, default_value = "full")]
    fit: FitArg,
    /// What the best fit minimises.
    #[arg(long, value_enum, default_value = "l2")]
    method: MethodArg,
    /// How far (+-) the best fit may move the section along its chord, mm (none: as far as fits best); a section
    /// lying farther off is fitted to the limit and the rest shows in its form.
    #[arg(long, value_name = "MM")]
    max_dchord_mm: Option<f64>,
    /// How far (+-) the best fit may move the section along its thickness direction, mm.
    #[arg(long, value_name = "MM")]
    max_dn_mm: Option<f64>,
    /// How far (+-) the best fit may turn the section about its chord's middle, deg (with --fit full).
    #[arg(long, value_name = "DEG")]
    max_rotation_deg: Option<f64>,
    /// Each point's deviation as measured and after the fit (CSV), if given.
    #[arg(long)]
    out: Option<PathBuf>,
    /// How far in from each edge, along the chord, the edge thicknesses are taken (mm); a reference's are the
    /// station's, 2 mm.
    #[arg(long, default_value_t = EDGE_DISTANCE_MM, conflicts_with = "reference")]
    edge_distance: f64,
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
    let (nominal, nominal_name) = match (&args.model, &args.reference, &args.profile) {
        (Some(model), _, _) => {
            let file = ModelFile::load(model)?;
            let nominal =
                Nominal::of(file.model).map_err(|e| anyhow!("{}: {e}", model.display()))?;
            (nominal, model.display().to_string())
        }
        (None, Some(reference), Some(profile)) => (
            Nominal::station(reference, profile)?,
            format!("profile {profile} of {}", reference.display()),
        ),
        _ => bail!("evaluate needs --model, or --reference with --profile"),
    };
    let SectionPoints {
        points,
        roll_contacts,
    } = read_section(&args.points)?;
    let (pivot, chord) = chord_of(&points);
    let (mode, mode_name) = match args.fit {
        FitArg::None => (BestFitMode::None, "no fit"),
        FitArg::Translation => (BestFitMode::Translation, "translations"),
        FitArg::Full => (BestFitMode::Full, "translations and rotation"),
    };
    let (method, method_name) = match args.method {
        MethodArg::L2 => (FitMethod::L2, "least squares"),
        MethodArg::Minzone => (FitMethod::MinZone, "minimum zone"),
    };
    let settings = BestFitSettings {
        mode,
        max_dchord_mm: args.max_dchord_mm,
        max_dn_mm: args.max_dn_mm,
        max_rotation_deg: args.max_rotation_deg,
    };
    settings.check().map_err(|problem| {
        anyhow!("{problem} (the limits are --max-dchord-mm, --max-dn-mm and --max-rotation-deg)")
    })?;
    let limits = settings.limits().fit_limits();
    let fitted = fit_section(
        &points,
        pivot,
        chord,
        mode.fit_mode(),
        method,
        &limits,
        |moved| nominal.measure(moved),
    )
    .map_err(|e| anyhow!("{}: {e}", args.points.display()))?;
    reportln!(
        "section {} ({} points) against {}; best fit: {mode_name} by {method_name}, about the chord's middle \
         ({:.3}, {:.3}) mm",
        args.points.display(),
        points.len(),
        nominal_name,
        pivot.x,
        pivot.y
    )?;
    print_fit(&fitted, &chord, &settings.limits())?;
    let measured = section_parameters(&points, &roll_contacts, args.edge_distance)
        .map_err(|e| anyhow!("{}: {e}", args.points.display()))?;
    let nominal = nominal
        .parameters(&points, args.edge_distance)
        .map_err(|e| anyhow!("{nominal_name}: {e}"));
    print_parameters(&measured, nominal, args.edge_distance)?;
    if let Some(out) = &args.out {
        write_deviations(out, &points, &fitted)?;
        reportln!("wrote {}", out.display())?;
    }
    Ok(())
}

/// The nominal a section is evaluated against: one polynomial round the profile (with its zero set sampled for the
/// exact distance's seeds), its faces, or a profile of the station's taught reference.
enum Nominal {
    Profile {
        model: Box<FittedIp<2>>,
        samples: ZeroSetSamples<2>,
    },
    Faces(FacedProfile),
    Station(Box<ProfileGauge>),
}

impl Nominal {
    fn of(model: ReferenceModel) -> Result<Self, String> {
        match model {
            ReferenceModel::Profile(model) => Ok(Self::Profile {
                samples: ZeroSetSamples::new(&model.ip, &model.domain.scaled(2.0), CELLS),
                model: Box::new(model),
            }),
            ReferenceModel::Faces(faced) => {
                faced.profile().map(Self::Faces).map_err(|e| e.to_string())
            }
            _ => Err(
                "evaluate needs a profile model (fitted from y,z points); this one is 3-D"
                    .to_string(),
            ),
        }
    }

    /// The gauge the station measures the reference's `profile` with.
    fn station(reference: &Path, profile: &str) -> anyhow::Result<Self> {
        let taught = Reference::load(reference)?;
        let names: Vec<String> = taught.profiles.iter().map(|p| p.name.clone()).collect();
        let gauge = ProfileGauge::named(&taught, profile).ok_or_else(|| {
            anyhow!(
                "{}: no profile '{profile}' (the reference of part '{}' has {})",
                reference.display(),
                taught.part,
                names.join(", ")
            )
        })?;
        Ok(Self::Station(Box::new(gauge)))
    }

    /// The signed distance and outward normal of each point at its foot.
    fn measure(&self, points: &[Vector2<f64>]) -> Vec<Option<Measured>> {
        match self {
            Self::Profile { model, samples } => ExactDistance::new(&model.ip, samples)
                .feet_along_scan(points)
                .into_iter()
                .map(|foot| {
                    let foot = foot.ok()?;
                    let (_, gradient) = model.ip.value_gradient(&foot.point);
                    Some(Measured {
                        distance_mm: foot.distance,
                        normal: gradient.try_normalize(0.0)?,
                    })
                })
                .collect(),
            Self::Faces(faces) => points
                .iter()
                .map(|p| {
                    let foot = faces.foot(p)?;
                    Some(Measured {
                        distance_mm: foot.distance,
                        normal: faces.outward_normal(p, &foot)?,
                    })
                })
                .collect(),
            Self::Station(gauge) => {
                let in_plane: Vec<Point3<f64>> = points
                    .iter()
                    .map(|p| Point3::new(gauge.x_mm(), p.x, p.y))
                    .collect();
                measure_in_plane(gauge, &in_plane, points)
            }
        }
    }

    /// The nominal's parameters: those of a polynomial's zero set along the points' feet, of the faces traced from
    /// edge to edge, or the station's own.
    fn parameters(
        &self,
        points: &[Vector2<f64>],
        edge_distance_mm: f64,
    ) -> Result<SectionParameters, String> {
        let outline = match self {
            Self::Profile { model, samples } => {
                let exact = ExactDistance::new(&model.ip, samples);
                points
                    .iter()
                    .map(|p| exact.foot(p, None).map(|foot| foot.point))
                    .collect::<Result<Vec<_>, _>>()
                    .map(|feet| nominal_outline(&model.ip, &feet))
                    .map_err(|e| format!("a point has no foot on the model: {e}"))?
            }
            Self::Faces(faces) => faces_outline(faces),
            Self::Station(gauge) => {
                return gauge.nominal_parameters().cloned().map_err(String::from)
            }
        };
        section_parameters(&outline, &[], edge_distance_mm).map_err(|e| e.to_string())
    }
}

fn print_fit(
    fitted: &SectionFit,
    chord: &Vector2<f64>,
    limits: &BestFitLimits,
) -> anyhow::Result<()> {
    let across = Vector2::new(-chord.y, chord.x);
    reportln!(
        "  chord direction (y, z) ({:.5}, {:.5}); thickness direction, the chord turned +90 deg, ({:.5}, {:.5})",
        chord.x, chord.y, across.x, across.y
    )?;
    reportln!(
        "  the section lies {:+.4} mm along the thickness direction and {:+.4} mm along the chord from the \
         nominal, turned {:+.4} deg (counter-clockwise +)",
        fitted.dn_mm, fitted.dchord_mm, fitted.rotation_deg
    )?;
    let held = [
        ("along the chord", limits.dchord_mm, "mm"),
        ("along the thickness", limits.dn_mm, "mm"),
        ("turned", limits.rotation_deg, "deg"),
    ];
    for ((what, limit, unit), at) in held.iter().zip(fitted.at_limit) {
        if let Some(limit) = limit {
            let state = if at {
                "reached: the section lies farther off, and the rest shows in the form"
            } else {
                "not reached"
            };
            reportln!("  limit {what} +-{limit} {unit}: {state}")?;
        }
    }
    print_form("as measured:  ", &fitted.form_before)?;
    print_form("after the fit:", &fitted.form)?;
    Ok(())
}

/// One of a section's parameters, read from them.
type Parameter = fn(&SectionParameters) -> f64;

/// The section's parameters, measured and nominal, with their differences; the nominal's absence said why.
fn print_parameters(
    measured: &SectionParameters,
    nominal: anyhow::Result<SectionParameters>,
    edge_distance_mm: f64,
) -> anyhow::Result<()> {
    reportln!(
        "  parameters (leading edge the blunter end, at ({:.3}, {:.3}) mm; edge thicknesses {edge_distance_mm} mm \
         in from each edge; camber and chord angle from the mean line, its chord from ({:.3}, {:.3}) to ({:.3}, \
         {:.3}) mm):",
        measured.leading_edge.x,
        measured.leading_edge.y,
        measured.mean_line.leading_end.x,
        measured.mean_line.leading_end.y,
        measured.mean_line.trailing_end.x,
        measured.mean_line.trailing_end.y
    )?;
    let nominal = match nominal {
        Ok(nominal) => {
            reportln!(
                "    {:<34} {:>12} {:>12} {:>12}",
                "",
                "measured",
                "nominal",
                "deviation"
            )?;
            Some(nominal)
        }
        Err(error) => {
            reportln!("    no nominal parameters: {error:#}")?;
            None
        }
    };
    let rows: [(&str, Parameter); 8] = [
        ("chord (mm)", |p| p.chord_mm),
        ("max thickness, inscribed (mm)", |p| p.max_thickness_mm),
        ("  at (fraction of the chord)", |p| p.max_thickness_at),
        ("leading-edge thickness (mm)", |p| p.le_thickness_mm),
        ("trailing-edge thickness (mm)", |p| p.te_thickness_mm),
        ("max camber, mean line (mm)", |p| p.mean_line.max_camber_mm),
        ("  at (fraction of its chord)", |p| {
            p.mean_line.max_camber_at
        }),
        ("chord angle to +y (deg)", |p| p.mean_line.chord_angle_deg),
    ];
    for (name, value) in rows {
        let m = value(measured);
        match &nominal {
            Some(n) => reportln!(
                "    {name:<34} {m:>12.4} {:>12.4} {:>+12.4}",
                value(n),
                m - value(n)
            ),
            None => reportln!("    {name:<34} {m:>12.4}"),
        }?;
    }
    Ok(())
}

fn print_form(what: &str, form: &Form) -> anyhow::Result<()> {
    reportln!(
        "  {what} normal deviations min {:+.4} mm, max {:+.4} mm, RMS {:.4} mm, zone {:.4} mm (twice the largest)",
        form.min_mm, form.max_mm, form.rms_mm, form.zone_mm
    )?;
    Ok(())
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
