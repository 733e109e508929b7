//! The blade parameters in report.qif: each section's chord, thicknesses, edge radii, camber, chord angle and
//! pitch, each blade's mean pitch and angular spacing and the propeller's mean pitch, as QIF length, thickness,
//! radius and angle characteristics. The nominal's TargetValue is the master's value; the tolerance, where the part
//! gives one, is on the deviation from it (DefinedAsLimit false: MaxValue and MinValue are the upper and lower
//! tolerances); a parameter without one is NonTolerance MEASURED and its status NOT_ANALYZED.

use std::io;

use super::elements::{decimal, reference, references, text, with_id, Xml};
use super::ids::{scans, DocumentIds};
use crate::analysis::section::ParameterValue;
use crate::analysis::tolerances::{Parameter, ParameterVerdict};
use crate::report::PartReport;

/// What QIF calls the characteristic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Length,
    Thickness,
    Radius,
    Angle,
}

impl Kind {
    fn of(parameter: Parameter) -> Kind {
        match parameter {
            Parameter::MaxThickness | Parameter::LeThickness | Parameter::TeThickness => {
                Kind::Thickness
            }
            Parameter::LeRadius | Parameter::TeRadius => Kind::Radius,
            Parameter::ChordAngle | Parameter::AngularSpacing => Kind::Angle,
            Parameter::Chord
            | Parameter::MaxCamber
            | Parameter::Pitch
            | Parameter::BladePitch
            | Parameter::PropellerPitch => Kind::Length,
        }
    }

    /// The element names' stem, e.g. "ThicknessCharacteristic".
    fn stem(self) -> &'static str {
        match self {
            Kind::Length => "LengthCharacteristic",
            Kind::Thickness => "ThicknessCharacteristic",
            Kind::Radius => "RadiusCharacteristic",
            Kind::Angle => "AngleCharacteristic",
        }
    }
}

/// One parameter of the report as a characteristic.
#[derive(Debug, Clone, Copy)]
pub(super) struct ParameterCharacteristic<'a> {
    pub instance: &'a str,
    /// The scanned profile it was measured on (its index in [`scans`] order and its name), `None` for a
    /// blade's or the part's parameter.
    pub profile: Option<(usize, &'a str)>,
    pub parameter: Parameter,
    pub value: &'a ParameterValue,
}

impl ParameterCharacteristic<'_> {
    /// E.g. "B/r100 max_thickness_mm", "B blade_pitch_mm", "propeller_pitch_mm".
    pub fn name(&self) -> String {
        match (self.instance, self.profile) {
            ("", _) => self.parameter.key().to_string(),
            (instance, None) => format!("{instance} {}", self.parameter.key()),
            (instance, Some((_, profile))) => {
                format!("{instance}/{profile} {}", self.parameter.key())
            }
        }
    }

    fn kind(&self) -> Kind {
        Kind::of(self.parameter)
    }
}

/// Every parameter of the report: each section's in the report's order, then its blade's, then the part's.
pub(super) fn parameter_characteristics(report: &PartReport) -> Vec<ParameterCharacteristic<'_>> {
    let mut all = Vec::new();
    let mut scan = 0;
    for instance in &report.instances {
        for profile in &instance.profiles {
            for (parameter, value) in profile.parameters.iter().flat_map(|p| p.judged()) {
                all.push(ParameterCharacteristic {
                    instance: &instance.name,
                    profile: Some((scan, &profile.name)),
                    parameter,
                    value,
                });
            }
            scan += 1;
        }
        let blade = [
            (Parameter::BladePitch, &instance.blade_pitch_mm),
            (Parameter::AngularSpacing, &instance.angular_spacing_deg),
        ];
        for (parameter, value) in blade {
            if let Some(value) = value {
                all.push(ParameterCharacteristic {
                    instance: &instance.name,
                    profile: None,
                    parameter,
                    value,
                });
            }
        }
    }
    if let Some(pitch) = &report.propeller_pitch_mm {
        all.push(ParameterCharacteristic {
            instance: "",
            profile: None,
            parameter: Parameter::PropellerPitch,
            value: pitch,
        });
    }
    debug_assert_eq!(scan, scans(report).count());
    all
}

/// The definition: its tolerance on the deviation, or none.
pub(super) fn definition(
    xml: &mut Xml,
    characteristic: &ParameterCharacteristic,
    id: u32,
) -> io::Result<()> {
    let element = format!("{}Definition", characteristic.kind().stem());
    with_id(xml, &element, id).write_inner_content(|xml| {
        text(xml, "Name", &characteristic.name())?;
        match characteristic.value.tolerance {
            Some(tolerance) => {
                xml.create_element("Tolerance").write_inner_content(|xml| {
                    decimal(xml, "MaxValue", tolerance.upper)?;
                    decimal(xml, "MinValue", tolerance.lower)?;
                    text(xml, "DefinedAsLimit", "false")
                })?;
            }
            None => text(xml, "NonTolerance", "MEASURED")?,
        }
        Ok(())
    })?;
    Ok(())
}

/// The nominal: the master's value, on the profile's curve where it has one.
pub(super) fn nominal(
    xml: &mut Xml,
    characteristic: &ParameterCharacteristic,
    ids: &DocumentIds,
    k: usize,
) -> io::Result<()> {
    let own = ids.parameters[k];
    let element = format!("{}Nominal", characteristic.kind().stem());
    with_id(xml, &element, own.nominal).write_inner_content(|xml| {
        reference(xml, "CharacteristicDefinitionId", own.definition)?;
        if let Some((scan, _)) = characteristic.profile {
            references(
                xml,
                "FeatureNominalIds",
                &[ids.profiles[scan].feature_nominal],
            )?;
        }
        text(xml, "Name", &characteristic.name())?;
        decimal(xml, "TargetValue", characteristic.value.nominal)
    })?;
    Ok(())
}

/// The item: what is measured, on which curve and machine.
pub(super) fn item(
    xml: &mut Xml,
    report: &PartReport,
    characteristic: &ParameterCharacteristic,
    ids: &DocumentIds,
    k: usize,
) -> io::Result<()> {
    let own = ids.parameters[k];
    let element = format!("{}Item", characteristic.kind().stem());
    with_id(xml, &element, own.item).write_inner_content(|xml| {
        text(xml, "Name", &characteristic.name())?;
        if let Some((scan, _)) = characteristic.profile {
            references(xml, "FeatureItemIds", &[ids.profiles[scan].feature_item])?;
            let (_, profile) = scans(report)
                .nth(scan)
                .expect("the scan the parameter names");
            references(xml, "MeasurementDeviceIds", &[ids.device(&profile.machine)])?;
        }
        reference(xml, "CharacteristicNominalId", own.nominal)
    })?;
    Ok(())
}

/// The measurement: its status and measured value.
pub(super) fn measurement(
    xml: &mut Xml,
    report: &PartReport,
    characteristic: &ParameterCharacteristic,
    ids: &DocumentIds,
    k: usize,
) -> io::Result<()> {
    let own = ids.parameters[k];
    let element = format!("{}Measurement", characteristic.kind().stem());
    let status = match characteristic.value.verdict {
        Some(ParameterVerdict::Pass) => "PASS",
        Some(ParameterVerdict::Fail) => "FAIL",
        None => "NOT_ANALYZED",
    };
    with_id(xml, &element, own.measurement).write_inner_content(|xml| {
        xml.create_element("Status")
            .write_inner_content(|xml| text(xml, "CharacteristicStatusEnum", status))?;
        reference(xml, "CharacteristicItemId", own.item)?;
        let scanned = characteristic
            .profile
            .map(|(scan, _)| (scan, scans(report).nth(scan).expect("its scan").1));
        if let Some((scan, profile)) = scanned {
            text(xml, "TimeStamp", &profile.scanned_at)?;
            references(
                xml,
                "FeatureMeasurementIds",
                &[ids.profiles[scan].feature_measurement],
            )?;
        }
        reference(xml, "ActualComponentId", ids.actual_component)?;
        if let Some((_, profile)) = scanned {
            references(xml, "MeasurementDeviceIds", &[ids.device(&profile.machine)])?;
        }
        decimal(xml, "Value", characteristic.value.measured)
    })?;
    Ok(())
}
