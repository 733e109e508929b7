//! The XML of report.qif, section by section in the order QIFDocument.xsd requires: header, standard, units,
//! machines, the part, its features (one open curve per scanned profile), their line-profile characteristics,
//! and the results (see [`super::results`]).

use std::io;

use quick_xml::events::{BytesDecl, BytesText, Event};
use quick_xml::Writer;

use super::elements::{counted, decimal, reference, references, text, with_id, Xml};
use super::ids::{scans, DocumentIds, ProfileIds};
use super::parameters::{self, parameter_characteristics};
use super::qpid::inspection_qpid;
use super::results::results;
use super::FORM_VALUE_MEANING;
use crate::analysis::stats::Tolerance;
use crate::report::{InstanceReport, PartReport, ProfileReport};

const QIF_NAMESPACE: &str = "http://qifstandards.org/xsd/qif3";
const QIF_VERSION: &str = "3.0.0";

/// The unit vector normal to every profile's plane in the part's frame: profiles are the sections x = x_mm.
const PROFILE_PLANE_NORMAL: &str = "1 0 0";

/// The whole document.
pub(super) fn qif_document(report: &PartReport) -> io::Result<Vec<u8>> {
    let ids = DocumentIds::assign(report);
    let id_max = ids.max.to_string();
    let mut xml = Writer::new_with_indent(Vec::new(), b' ', 2);
    xml.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    xml.create_element("QIFDocument")
        .with_attributes([
            ("xmlns", QIF_NAMESPACE),
            ("versionQIF", QIF_VERSION),
            ("idMax", id_max.as_str()),
        ])
        .write_inner_content(|xml| {
            let qpid = inspection_qpid(&report.job, &report.serial, &report.finished);
            text(xml, "QPId", &qpid)?;
            header(xml, report)?;
            standards(xml, &ids)?;
            file_units(xml)?;
            measurement_resources(xml, &ids)?;
            product(xml, report, &ids)?;
            features(xml, report, &ids)?;
            characteristics(xml, report, &ids)?;
            results(xml, report, &ids)
        })?;
    Ok(xml.into_inner())
}

/// What the document holds and what its numbers mean, for the person or plant system that imports it.
fn header(xml: &mut Xml, report: &PartReport) -> io::Result<()> {
    let description = format!(
        "zeroset inspection of part {} serial {} (job {}, {} to {}). Lengths in mm. {FORM_VALUE_MEANING} \
         Measured points are probe-compensated surface points in machine coordinates (mm) with their signed \
         deviations ({}; {}); each profile is the section x = const of the part's frame. Blade parameters are \
         length, thickness, radius and angle characteristics (angles in degrees) whose TargetValue is the master's \
         value and whose tolerance is on the deviation from it; NOT_ANALYZED marks one without a tolerance.",
        report.part,
        report.serial,
        report.job,
        report.started,
        report.finished,
        report.distance,
        report.compensation,
    );
    // Comments are not escaped; the text holds no "--".
    xml.write_event(Event::Comment(BytesText::from_escaped(format!(
        " {FORM_VALUE_MEANING} "
    ))))?;
    xml.create_element("Header")
        .write_inner_content(|xml| text(xml, "Description", &description))?;
    Ok(())
}

/// ASME Y14.5-2018, whose profile tolerance the characteristics follow: a zone of ToleranceValue width centred
/// on the nominal unless an outer disposition says otherwise, and the actual value of the smallest centred zone
/// that holds every point.
fn standards(xml: &mut Xml, ids: &DocumentIds) -> io::Result<()> {
    counted(xml, "StandardsDefinitions", 1).write_inner_content(|xml| {
        with_id(xml, "Standard", ids.standard).write_inner_content(|xml| {
            xml.create_element("Organization")
                .write_inner_content(|xml| text(xml, "StandardsOrganizationEnum", "ASME"))?;
            text(xml, "Designator", "Y14.5")?;
            text(xml, "Year", "2018")
        })?;
        Ok(())
    })?;
    Ok(())
}

fn file_units(xml: &mut Xml) -> io::Result<()> {
    xml.create_element("FileUnits").write_inner_content(|xml| {
        xml.create_element("PrimaryUnits")
            .write_inner_content(|xml| {
                xml.create_element("AngularUnit")
                    .write_inner_content(|xml| {
                        text(xml, "SIUnitName", "radian")?;
                        text(xml, "UnitName", "degree")?;
                        xml.create_element("UnitConversion")
                            .write_inner_content(|xml| {
                                decimal(xml, "Factor", std::f64::consts::PI / 180.0)
                            })?;
                        Ok(())
                    })?;
                xml.create_element("LinearUnit")
                    .write_inner_content(|xml| {
                        text(xml, "SIUnitName", "meter")?;
                        text(xml, "UnitName", "mm")?;
                        xml.create_element("UnitConversion")
                            .write_inner_content(|xml| text(xml, "Factor", "0.001"))?;
                        Ok(())
                    })?;
                Ok(())
            })?;
        Ok(())
    })?;
    Ok(())
}

/// One measurement device per machine that scanned a profile.
fn measurement_resources(xml: &mut Xml, ids: &DocumentIds) -> io::Result<()> {
    xml.create_element("MeasurementResources")
        .write_inner_content(|xml| {
            counted(xml, "MeasurementDevices", ids.devices.len()).write_inner_content(|xml| {
                for (name, id) in &ids.devices {
                    with_id(xml, "MeasurementDevice", *id)
                        .write_inner_content(|xml| text(xml, "Name", name))?;
                }
                Ok(())
            })?;
            Ok(())
        })?;
    Ok(())
}

fn product(xml: &mut Xml, report: &PartReport, ids: &DocumentIds) -> io::Result<()> {
    xml.create_element("Product").write_inner_content(|xml| {
        counted(xml, "PartSet", 1).write_inner_content(|xml| {
            with_id(xml, "Part", ids.part).write_inner_content(|xml| {
                xml.create_element("Header")
                    .write_inner_content(|xml| text(xml, "Name", &report.part))?;
                Ok(())
            })?;
            Ok(())
        })?;
        Ok(())
    })?;
    Ok(())
}

/// The nominal and the planned (item) curve of every profile of every instance.
fn features(xml: &mut Xml, report: &PartReport, ids: &DocumentIds) -> io::Result<()> {
    let count = ids.profiles.len();
    xml.create_element("Features").write_inner_content(|xml| {
        counted(xml, "FeatureDefinitions", 1).write_inner_content(|xml| {
            with_id(xml, "OtherCurveFeatureDefinition", ids.curve_definition).write_empty()?;
            Ok(())
        })?;
        counted(xml, "FeatureNominals", count).write_inner_content(|xml| {
            for ((instance, profile), profile_ids) in scans(report).zip(&ids.profiles) {
                with_id(xml, "OtherCurveFeatureNominal", profile_ids.feature_nominal)
                    .write_inner_content(|xml| {
                        text(xml, "Name", &scan_name(instance, profile))?;
                        reference(xml, "FeatureDefinitionId", ids.curve_definition)
                    })?;
            }
            Ok(())
        })?;
        counted(xml, "FeatureItems", count).write_inner_content(|xml| {
            for ((instance, profile), profile_ids) in scans(report).zip(&ids.profiles) {
                with_id(xml, "OtherCurveFeatureItem", profile_ids.feature_item)
                    .write_inner_content(|xml| {
                        reference(xml, "FeatureNominalId", profile_ids.feature_nominal)?;
                        text(xml, "FeatureName", &scan_name(instance, profile))?;
                        determined_by_measurement(xml)
                    })?;
            }
            Ok(())
        })?;
        Ok(())
    })?;
    Ok(())
}

fn determined_by_measurement(xml: &mut Xml) -> io::Result<()> {
    xml.create_element("DeterminationMode")
        .write_inner_content(|xml| {
            xml.create_element("Checked").write_inner_content(|xml| {
                xml.create_element("CheckDetails")
                    .write_inner_content(|xml| {
                        xml.create_element("Measured").write_empty()?;
                        Ok(())
                    })?;
                Ok(())
            })?;
            Ok(())
        })?;
    Ok(())
}

/// One line-profile characteristic (definition with the tolerance zone, nominal, item) per profile and instance,
/// then one per blade parameter.
fn characteristics(xml: &mut Xml, report: &PartReport, ids: &DocumentIds) -> io::Result<()> {
    let blade_parameters = parameter_characteristics(report);
    let count = ids.profiles.len() + blade_parameters.len();
    xml.create_element("Characteristics")
        .write_inner_content(|xml| {
            reference(xml, "FormalStandardId", ids.standard)?;
            counted(xml, "CharacteristicDefinitions", count).write_inner_content(|xml| {
                for ((instance, profile), profile_ids) in scans(report).zip(&ids.profiles) {
                    let name = scan_name(instance, profile);
                    line_profile_definition(xml, &name, &report.tolerance, profile_ids)?;
                }
                for (parameter, own) in blade_parameters.iter().zip(&ids.parameters) {
                    parameters::definition(xml, parameter, own.definition)?;
                }
                Ok(())
            })?;
            counted(xml, "CharacteristicNominals", count).write_inner_content(|xml| {
                for ((instance, profile), profile_ids) in scans(report).zip(&ids.profiles) {
                    with_id(
                        xml,
                        "LineProfileCharacteristicNominal",
                        profile_ids.characteristic_nominal,
                    )
                    .write_inner_content(|xml| {
                        reference(
                            xml,
                            "CharacteristicDefinitionId",
                            profile_ids.characteristic_definition,
                        )?;
                        references(xml, "FeatureNominalIds", &[profile_ids.feature_nominal])?;
                        text(xml, "Name", &scan_name(instance, profile))?;
                        text(xml, "Vector", PROFILE_PLANE_NORMAL)
                    })?;
                }
                for (k, parameter) in blade_parameters.iter().enumerate() {
                    parameters::nominal(xml, parameter, ids, k)?;
                }
                Ok(())
            })?;
            counted(xml, "CharacteristicItems", count).write_inner_content(|xml| {
                for ((instance, profile), profile_ids) in scans(report).zip(&ids.profiles) {
                    with_id(
                        xml,
                        "LineProfileCharacteristicItem",
                        profile_ids.characteristic_item,
                    )
                    .write_inner_content(|xml| {
                        text(xml, "Name", &scan_name(instance, profile))?;
                        references(xml, "FeatureItemIds", &[profile_ids.feature_item])?;
                        references(xml, "MeasurementDeviceIds", &[ids.device(&profile.machine)])?;
                        reference(
                            xml,
                            "CharacteristicNominalId",
                            profile_ids.characteristic_nominal,
                        )
                    })?;
                }
                for (k, parameter) in blade_parameters.iter().enumerate() {
                    parameters::item(xml, report, parameter, ids, k)?;
                }
                Ok(())
            })?;
            Ok(())
        })?;
    Ok(())
}

/// The tolerance zone: its width, and where its outer boundary lies when it is not centred on the nominal
/// (QIF's OuterDisposition, the upper limit; deviations are positive outside the material as in QIF).
fn line_profile_definition(
    xml: &mut Xml,
    name: &str,
    tolerance: &Tolerance,
    profile_ids: &ProfileIds,
) -> io::Result<()> {
    with_id(
        xml,
        "LineProfileCharacteristicDefinition",
        profile_ids.characteristic_definition,
    )
    .write_inner_content(|xml| {
        text(xml, "Name", name)?;
        decimal(
            xml,
            "ToleranceValue",
            tolerance.upper_mm - tolerance.lower_mm,
        )?;
        if tolerance.upper_mm != -tolerance.lower_mm {
            decimal(xml, "OuterDisposition", tolerance.upper_mm)?;
        }
        Ok(())
    })?;
    Ok(())
}

/// The name of one profile of one instance in the document, e.g. "B/r200".
pub(super) fn scan_name(instance: &InstanceReport, profile: &ProfileReport) -> String {
    format!("{}/{}", instance.name, profile.name)
}
