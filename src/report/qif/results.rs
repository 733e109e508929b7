//! The results section of report.qif: per profile the measured curve, its point set and its line-profile
//! characteristic's actual value and status; the inspection's status; the actual part with its serial number.

use std::io;

use super::document::scan_name;
use super::elements::{counted, decimal, numbers, reference, references, text, with_id, Xml};
use super::form_value_mm;
use super::ids::{scans, DocumentIds, ProfileIds};
use super::parameters::{self, parameter_characteristics};
use crate::analysis::stats::Verdict;
use crate::report::{InstanceReport, PartReport, ProfileReport};

/// The Results element.
pub(super) fn results(xml: &mut Xml, report: &PartReport, ids: &DocumentIds) -> io::Result<()> {
    let count = ids.profiles.len();
    let part_status = status(&report.verdict);
    xml.create_element("Results").write_inner_content(|xml| {
        counted(xml, "MeasurementResultsSet", 1).write_inner_content(|xml| {
            with_id(xml, "MeasurementResults", ids.measurement_results).write_inner_content(
                |xml| {
                    counted(xml, "MeasuredFeatures", count).write_inner_content(|xml| {
                        for ((instance, profile), profile_ids) in scans(report).zip(&ids.profiles) {
                            measured_curve(xml, instance, profile, profile_ids, ids)?;
                        }
                        Ok(())
                    })?;
                    counted(xml, "MeasuredPointSets", count).write_inner_content(|xml| {
                        for ((_, profile), profile_ids) in scans(report).zip(&ids.profiles) {
                            point_set(xml, report, profile, profile_ids, ids)?;
                        }
                        Ok(())
                    })?;
                    let blade_parameters = parameter_characteristics(report);
                    let characteristics = count + blade_parameters.len();
                    xml.create_element("MeasuredCharacteristics")
                        .write_inner_content(|xml| {
                            counted(xml, "CharacteristicMeasurements", characteristics)
                                .write_inner_content(|xml| {
                                    for ((_, profile), profile_ids) in
                                        scans(report).zip(&ids.profiles)
                                    {
                                        line_profile_measurement(xml, profile, profile_ids, ids)?;
                                    }
                                    for (k, parameter) in blade_parameters.iter().enumerate() {
                                        parameters::measurement(xml, report, parameter, ids, k)?;
                                    }
                                    Ok(())
                                })?;
                            Ok(())
                        })?;
                    inspection_status(xml, "InspectionStatus", part_status)?;
                    references(xml, "ActualComponentIds", &[ids.actual_component])
                },
            )?;
            Ok(())
        })?;
        counted(xml, "ActualComponentSets", 1).write_inner_content(|xml| {
            counted(xml, "ActualComponentSet", 1).write_inner_content(|xml| {
                with_id(xml, "ActualComponent", ids.actual_component).write_inner_content(
                    |xml| {
                        text(xml, "SerialNumber", &report.serial)?;
                        inspection_status(xml, "Status", part_status)
                    },
                )?;
                Ok(())
            })?;
            Ok(())
        })?;
        Ok(())
    })?;
    Ok(())
}

/// The measured curve of one profile: which item it measures, when, on which machine, and its points.
fn measured_curve(
    xml: &mut Xml,
    instance: &InstanceReport,
    profile: &ProfileReport,
    profile_ids: &ProfileIds,
    ids: &DocumentIds,
) -> io::Result<()> {
    with_id(
        xml,
        "OtherCurveFeatureMeasurement",
        profile_ids.feature_measurement,
    )
    .write_inner_content(|xml| {
        reference(xml, "FeatureItemId", profile_ids.feature_item)?;
        text(xml, "FeatureName", &scan_name(instance, profile))?;
        text(xml, "TimeStamp", &profile.scanned_at)?;
        reference(xml, "ActualComponentId", ids.actual_component)?;
        references(xml, "MeasurementDeviceIds", &[ids.device(&profile.machine)])?;
        counted(xml, "PointList", 1)
            .write_inner_content(|xml| reference(xml, "WholePointSetId", profile_ids.point_set))?;
        Ok(())
    })?;
    Ok(())
}

/// Every probe-compensated surface point of one profile with its reported normal, quality and deviation.
fn point_set(
    xml: &mut Xml,
    report: &PartReport,
    profile: &ProfileReport,
    profile_ids: &ProfileIds,
    ids: &DocumentIds,
) -> io::Result<()> {
    let points = &profile.points;
    let count = points.len().to_string();
    let id = profile_ids.point_set.to_string();
    let ball_radius_mm = report
        .machines
        .iter()
        .find(|machine| machine.name == profile.machine)
        .map(|machine| machine.ball_radius_mm);
    xml.create_element("MeasuredPointSet")
        .with_attributes([("count", count.as_str()), ("id", id.as_str())])
        .write_inner_content(|xml| {
            text(
                xml,
                "Points",
                &numbers(points.iter().flat_map(|p| p.surface)),
            )?;
            text(
                xml,
                "Normals",
                &numbers(points.iter().flat_map(|p| p.normal)),
            )?;
            text(xml, "Compensated", "true")?;
            if let Some(radius) = ball_radius_mm {
                decimal(xml, "ProbeRadius", radius)?;
            }
            reference(xml, "MeasurementDeviceId", ids.device(&profile.machine))?;
            text(xml, "TimeStamp", &profile.scanned_at)?;
            text(xml, "Quality", &numbers(points.iter().map(|p| p.quality)))?;
            text(
                xml,
                "Deviations",
                &numbers(points.iter().map(|p| p.deviation_mm)),
            )
        })?;
    Ok(())
}

/// The actual line-profile characteristic of one profile: status, form value and worst deviations.
fn line_profile_measurement(
    xml: &mut Xml,
    profile: &ProfileReport,
    profile_ids: &ProfileIds,
    ids: &DocumentIds,
) -> io::Result<()> {
    with_id(
        xml,
        "LineProfileCharacteristicMeasurement",
        profile_ids.characteristic_measurement,
    )
    .write_inner_content(|xml| {
        xml.create_element("Status").write_inner_content(|xml| {
            text(xml, "CharacteristicStatusEnum", status(&profile.verdict))
        })?;
        reference(xml, "CharacteristicItemId", profile_ids.characteristic_item)?;
        text(xml, "TimeStamp", &profile.scanned_at)?;
        references(
            xml,
            "FeatureMeasurementIds",
            &[profile_ids.feature_measurement],
        )?;
        reference(xml, "ActualComponentId", ids.actual_component)?;
        references(xml, "MeasurementDeviceIds", &[ids.device(&profile.machine)])?;
        decimal(xml, "Value", form_value_mm(&profile.stats))?;
        decimal(xml, "WorstPositiveDeviation", profile.stats.max_mm)?;
        decimal(xml, "WorstNegativeDeviation", profile.stats.min_mm)
    })?;
    Ok(())
}

fn inspection_status(xml: &mut Xml, name: &str, status: &str) -> io::Result<()> {
    xml.create_element(name)
        .write_inner_content(|xml| text(xml, "InspectionStatusEnum", status))?;
    Ok(())
}

/// QIF's status word for a verdict (the same in the characteristic and inspection status enumerations).
fn status(verdict: &Verdict) -> &'static str {
    match verdict {
        Verdict::Pass => "PASS",
        Verdict::Fail { .. } => "FAIL",
    }
}
