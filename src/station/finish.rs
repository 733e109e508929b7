//! The end of a job, from its scan files on disk (the one record of what was measured, whether the job ran in
//! one go or was resumed): a teach fits and saves the reference; an inspection measures every point against the
//! reference again and writes the part's report. Both are CPU work and run off the daemon's tasks.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use nalgebra::Vector2;

use super::job::job_scans;
use super::journal::{file_stem, JobDir, JobRecord};
use super::pipeline::scan_ref;
use super::verdicts::judge_blades;
use crate::analysis::compensate_scan;
use crate::analysis::deviation::ProfileGauge;
use crate::analysis::reference::{teach, MasterProfile, Reference};
use crate::analysis::section::ScannedSection;
use crate::analysis::stats::{RunningStats, Tolerance, Verdict};
use crate::analysis::tolerances::failures;
use crate::analysis::{fit_sanity, section};
use crate::api::{InstanceSummary, JobKind, ProfileFit};
use crate::geometry::supershape::distance::SolidDistance;
use crate::model_file::{ReferenceModel, SolidFitStats};
use crate::plan::Plan;
use crate::report::{
    write_html, write_qif, write_report, write_sections, ClassUse, InstanceReport, MachineUse,
    PartReport, PointRecord, ProfileReport, ReferenceUse, Store, REFERENCE_FILE,
};

/// How a finished job ended.
#[derive(Debug)]
pub enum Outcome {
    Taught {
        path: PathBuf,
        profiles: Vec<ProfileFit>,
    },
    Inspected {
        dir: PathBuf,
        instances: Vec<InstanceSummary>,
        verdict: Verdict,
    },
}

/// Fits the reference from the master's scans and saves it at `path`.
pub fn fit_reference(plan: &Plan, dir: &JobDir, path: &Path) -> Result<Outcome, String> {
    let mut profiles = Vec::new();
    for key in job_scans(plan, JobKind::Teach) {
        let scan = dir
            .read_scan(&scan_ref(plan, key))
            .map_err(|e| e.to_string())?;
        let to_part = plan.instance_to_machine(key.instance).inverse();
        let compensated = compensate_scan(
            &scan.points,
            scan.header.ball_radius_mm,
            plan.plane_normal(key.instance),
        );
        // A flagged contact (a cusp) is not a point of the surface: the reference is fitted without it.
        let flagged = compensated.iter().filter(|c| c.is_flagged()).count();
        if flagged > 0 {
            tracing::warn!(
                scan = %plan.describe(key),
                flagged,
                points = compensated.len(),
                "teach: points left out of the reference fit, their contact not unique (a cusp)"
            );
        }
        let (points, normals) = compensated
            .iter()
            .filter(|c| !c.is_flagged())
            .map(|c| (to_part * c.surface, to_part * c.normal))
            .unzip();
        profiles.push(MasterProfile {
            name: plan.profile_names()[key.profile].to_string(),
            x_mm: plan.profile_x(key.profile),
            points,
            normals,
        });
    }
    let reference =
        teach(plan.part(), &profiles, plan.reference_settings()).map_err(|e| e.to_string())?;
    if let Some(folder) = path.parent() {
        std::fs::create_dir_all(folder)
            .map_err(|e| format!("cannot create {}: {e}", folder.display()))?;
    }
    reference.save(path).map_err(|e| e.to_string())?;
    let band = plan.tolerance();
    let fits = reference_fits(&reference, &profiles, band.upper_mm.min(-band.lower_mm));
    for fit in &fits {
        for doubt in &fit.doubts {
            tracing::warn!(part = plan.part(), profile = %fit.profile, doubt = %doubt, "teach: the reference fit is doubtful");
        }
    }
    Ok(Outcome::Taught {
        path: path.to_path_buf(),
        profiles: fits,
    })
}

/// How closely the reference follows each master profile: a stack's own fit statistics, or the exact distances
/// of each profile's points to the solid; with the doubts they raise against the part's tolerance `tolerance_mm`
/// (the half width of its band).
fn reference_fits(
    reference: &Reference,
    profiles: &[MasterProfile],
    tolerance_mm: f64,
) -> Vec<ProfileFit> {
    let fit = |master: &MasterProfile, rms_mm: Option<f64>, max_mm: Option<f64>| ProfileFit {
        profile: master.name.clone(),
        points: master.points.len(),
        rms_mm,
        max_mm,
        doubts: max_mm
            .and_then(|max| fit_sanity::beyond_tolerance(max, &[], tolerance_mm))
            .into_iter()
            .collect(),
    };
    match &reference.model.model {
        ReferenceModel::Stack { profiles: fitted } => fitted
            .iter()
            .zip(profiles)
            .map(|(stack, master)| match stack.fitted.fit.as_ref() {
                Some(stats) => {
                    let in_plane: Vec<Vector2<f64>> = master
                        .points
                        .iter()
                        .map(|p| Vector2::new(p.y, p.z))
                        .collect();
                    ProfileFit {
                        doubts: fit_sanity::doubts(
                            stats,
                            fit_sanity::scatter_mm(&in_plane),
                            &stack.fitted.domain,
                            Some(tolerance_mm),
                        ),
                        ..fit(
                            master,
                            Some(stats.rms_distance_mm),
                            Some(stats.max_distance_mm),
                        )
                    }
                }
                None => fit(master, None, None),
            })
            .collect(),
        ReferenceModel::Supershape { solid, .. } => {
            let distance = SolidDistance::new(solid);
            profiles
                .iter()
                .map(|master| {
                    let stats = SolidFitStats::of(&distance, &master.points);
                    fit(
                        master,
                        stats.map(|s| s.rms_distance_mm),
                        stats.map(|s| s.max_distance_mm),
                    )
                })
                .collect()
        }
        _ => Vec::new(),
    }
}

/// What an inspection's report needs besides its scans.
pub struct ReportInputs<'a> {
    pub plan: &'a Plan,
    pub dir: &'a JobDir,
    pub record: &'a JobRecord,
    pub reference: &'a Reference,
    pub reference_path: &'a Path,
    pub gauges: &'a [ProfileGauge],
    pub tolerance: Tolerance,
    pub reports: &'a Path,
    /// The inspection history's database file.
    pub store: &'a Path,
}

/// Measures every scanned point against the reference and writes the part's report folder.
pub fn write_inspection(inputs: &ReportInputs) -> Result<Outcome, String> {
    let ReportInputs { plan, dir, .. } = inputs;
    let serial = inputs.record.serial.clone().unwrap_or_default();
    let mut machines: BTreeMap<String, MachineUse> = BTreeMap::new();
    let mut instances: Vec<InstanceReport> = Vec::new();
    let tolerances = plan.tolerance().parameter_tolerances();
    let mut sections = Vec::new();
    for (instance, name) in plan.instance_names().iter().enumerate() {
        let mut profiles = Vec::new();
        let mut all = RunningStats::default();
        let mut outside = 0;
        for key in job_scans(plan, JobKind::Inspect)
            .into_iter()
            .filter(|k| k.instance == instance)
        {
            let scan_name = scan_ref(plan, key);
            let scan = dir.read_scan(&scan_name).map_err(|e| e.to_string())?;
            let radius = scan.header.ball_radius_mm;
            machines
                .entry(scan.header.machine.clone())
                .or_insert_with(|| MachineUse {
                    name: scan.header.machine.clone(),
                    ball_radius_mm: radius,
                    profiles_scanned: 0,
                })
                .profiles_scanned += 1;
            let to_part = plan.instance_to_machine(key.instance).inverse();
            let mut gauge = inputs.gauges[key.profile].scan();
            let mut stats = RunningStats::default();
            let mut profile_outside = 0;
            let mut points = Vec::with_capacity(scan.points.len());
            let compensated =
                compensate_scan(&scan.points, radius, plan.plane_normal(key.instance));
            let mut flagged = 0;
            let mut in_part = ScannedSection::default();
            for (raw, point) in scan.points.iter().zip(&compensated) {
                let surface = point.surface;
                in_part.push(point, &to_part);
                let measured = gauge.measure(&(to_part * surface)).map_err(|e| {
                    format!(
                        "{} ({}): a point at ({:.3}, {:.3}, {:.3}) mm has no deviation: {e}",
                        plan.describe(key),
                        file_stem(&scan_name),
                        surface.x,
                        surface.y,
                        surface.z
                    )
                })?;
                // Flagged points are reported, marked, but left out of the statistics and the verdict.
                if point.is_flagged() {
                    flagged += 1;
                } else {
                    stats.push(measured.deviation_mm, surface.coords.into());
                    if !inputs.tolerance.contains(measured.deviation_mm) {
                        profile_outside += 1;
                    }
                }
                points.push(PointRecord {
                    centre: raw.centre,
                    normal: raw.normal,
                    surface: surface.coords.into(),
                    deviation_mm: measured.deviation_mm,
                    off_plane_mm: measured.off_plane_mm,
                    quality: raw.quality,
                    flagged: point.is_flagged(),
                    after_fit_mm: None,
                });
            }
            if flagged > 0 {
                tracing::warn!(
                    scan = %plan.describe(key),
                    flagged,
                    points = points.len(),
                    "report: points left out of the statistics, their contact not unique (a cusp)"
                );
            }
            let summary = stats
                .summary()
                .ok_or_else(|| format!("{}: the scan has no points", plan.describe(key)))?;
            let best_fits = match section::best_fits(
                &inputs.gauges[key.profile],
                &in_part.points,
                plan.best_fit(),
            ) {
                Ok(fitted) => {
                    let unflagged = points.iter_mut().filter(|p| !p.flagged);
                    for (point, after) in unflagged.zip(fitted.after_l2_mm) {
                        point.after_fit_mm = Some(after);
                    }
                    fitted.fits
                }
                Err(problem) => {
                    tracing::warn!(scan = %plan.describe(key), %problem, "report: no best fit of the section");
                    Vec::new()
                }
            };
            let shape = inputs.gauges[key.profile]
                .nominal_parameters()
                .map_err(str::to_string)
                .and_then(|nominal| section::parameters(nominal, &in_part, plan.profile_radius(key.profile)))
                .map(|mut shape| {
                    tolerances.judge_section(&mut shape.parameters);
                    shape
                })
                .map_err(|problem| {
                    tracing::warn!(scan = %plan.describe(key), %problem, "report: no parameters of the section");
                })
                .ok();
            sections.push((file_stem(&scan_name), in_part));
            let (parameters, distribution) = match shape {
                Some(shape) => (Some(shape.parameters), Some(shape.distribution)),
                None => (None, None),
            };
            let section_failures = parameters
                .as_ref()
                .map_or(0, |p| failures(p.judged().map(|(_, v)| v)));
            all.merge(&stats);
            outside += profile_outside;
            profiles.push(ProfileReport {
                name: scan_name.profile.clone(),
                x_mm: plan.profile_x(key.profile),
                machine: scan.header.machine.clone(),
                scanned_at: scan.finished.clone(),
                stats: summary,
                verdict: inputs
                    .tolerance
                    .verdict(&summary, profile_outside)
                    .with_parameters_outside(section_failures, summary.worst_mm),
                best_fits,
                parameters,
                distribution,
                points,
            });
        }
        let stats = all
            .summary()
            .ok_or_else(|| format!("instance {name} has no points"))?;
        instances.push(InstanceReport {
            name: name.clone(),
            verdict: inputs.tolerance.verdict(&stats, outside),
            stats,
            index_deg: blade_index_deg(plan, &profiles),
            angular_spacing_deg: None,
            blade_pitch_mm: None,
            profiles,
        });
    }
    let index: Vec<Option<f64>> = instances.iter().map(|i| i.index_deg).collect();
    for (instance, spacing) in instances
        .iter_mut()
        .zip(section::angular_spacings(&index, plan.instance_step_deg()))
    {
        instance.angular_spacing_deg = spacing;
    }
    let propeller_pitch_mm = judge_blades(&tolerances, &mut instances);
    let worst_mm = instances
        .iter()
        .map(|i| i.stats.worst_mm)
        .fold(
            0.0,
            |worst: f64, w| if w.abs() > worst.abs() { w } else { worst },
        );
    let verdict = Verdict::combine(instances.iter().map(|i| &i.verdict))
        .with_parameters_outside(failures(propeller_pitch_mm.iter()), worst_mm);
    let settings = &inputs.reference.settings;
    let report = PartReport {
        format: crate::report::FORMAT.to_string(),
        version: crate::report::VERSION,
        units: "mm".to_string(),
        part: plan.part().to_string(),
        serial: serial.clone(),
        job: inputs.record.id.clone(),
        started: inputs.record.started.clone(),
        finished: super::clock::now_rfc3339(),
        machines: machines.into_values().collect(),
        reference: ReferenceUse {
            path: inputs.reference_path.display().to_string(),
            taught_at: inputs.reference.taught_at.clone(),
            model: settings.describe(),
        },
        distance: match inputs.reference.model.model {
            ReferenceModel::Supershape { .. } => {
                "exact Euclidean distance to the supershape solid, in the master's frame".into()
            }
            _ => "exact orthogonal distance to each profile's 2-D implicit polynomial, in the master's frame"
                .into(),
        },
        compensation: "ball centre moved back along the normal of the ball-centre path (local quartic fit over 9 \
                       points), slid into the section plane by the reported normal's tilt; the reported normal at \
                       a scan's first and last 4 points and where the path cannot be fitted; points where the \
                       surface is more concave than the ball flagged and left out of the statistics"
            .into(),
        tolerance: inputs.tolerance,
        iso484: tolerances.class().map(|(class, cites)| ClassUse {
            class,
            cites: cites.to_string(),
        }),
        instances,
        propeller_pitch_mm,
        verdict: verdict.clone(),
        rescans: inputs.record.rescans.clone(),
    };
    let folder = inputs
        .reports
        .join(plan.part())
        .join(&serial)
        .join(&inputs.record.id);
    // The HTML and QIF reports first: report.json is written last, so a folder holding it is complete.
    std::fs::create_dir_all(&folder)
        .map_err(|e| format!("cannot create {}: {e}", folder.display()))?;
    write_html(&folder, &report).map_err(|e| e.to_string())?;
    write_qif(&folder, &report).map_err(|e| e.to_string())?;
    write_sections(&folder, &sections).map_err(|e| e.to_string())?;
    copy_reference(inputs.reference_path, &folder).map_err(|e| e.to_string())?;
    write_report(&folder, &report).map_err(|e| e.to_string())?;
    copy_scans(dir, &folder).map_err(|e| e.to_string())?;
    // Last: once the history holds the inspection, it is done (the daemon then closes its journal; a daemon killed
    // in between finishes the job again, and the history replaces the entry of the same job).
    Store::open(inputs.store)
        .and_then(|mut store| store.record(&report, &folder))
        .map_err(|e| e.to_string())?;
    let summaries = report
        .instances
        .iter()
        .map(|i| InstanceSummary {
            instance: i.name.clone(),
            stats: Some(i.stats),
            verdict: Some(i.verdict.clone()),
        })
        .collect();
    Ok(Outcome::Inspected {
        dir: folder,
        instances: summaries,
        verdict,
    })
}

/// The reference goes with the report, so that its sections can be evaluated again as the station did after the
/// part is taught again.
fn copy_reference(reference: &Path, folder: &Path) -> std::io::Result<()> {
    let bytes = std::fs::read(reference).map_err(|e| {
        std::io::Error::new(
            e.kind(),
            format!("cannot read the reference {}: {e}", reference.display()),
        )
    })?;
    crate::fsutil::write_atomically(&folder.join(REFERENCE_FILE), &bytes)
}

/// The raw scans go with the report, so that it can be analysed again without the daemon's data folder.
fn copy_scans(dir: &JobDir, folder: &Path) -> std::io::Result<()> {
    let target = folder.join("scans");
    std::fs::create_dir_all(&target)?;
    for name in dir.completed()? {
        let file = format!("{name}.json");
        let bytes = std::fs::read(dir.path().join("scans").join(&file))?;
        crate::fsutil::write_atomically(&target.join(file), &bytes)?;
    }
    Ok(())
}

/// A propeller blade's turn about the hub axis off its place, deg, from how far along y the middle of each
/// section's chord lies from its nominal's (the section at radius r moves by r tan(turn)): the chord's middle,
/// not a best fit's shift, since a best fit takes part of a camber or thickness error for a shift. `None` for
/// other parts or a blade with no section parameters.
fn blade_index_deg(plan: &Plan, profiles: &[ProfileReport]) -> Option<f64> {
    let sense = plan.hub_sense()?;
    let sections: Vec<(f64, f64)> = profiles
        .iter()
        .filter_map(|profile| {
            let [y, _] = profile.parameters.as_ref()?.chord_middle_mm?;
            Some((profile.x_mm, sense * y.deviation))
        })
        .collect();
    section::index_deg(&sections)
}
