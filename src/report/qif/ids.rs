//! The QIF ids of one document. QIF requires every id to be unique in the document and every reference to name
//! an element of the right kind; assigning them all up front, in one place, keeps the writer from inventing or
//! reusing one, and gives the document its `idMax`.

use super::parameters::parameter_characteristics;
use crate::report::{InstanceReport, PartReport, ProfileReport};

/// The ids of everything one scanned profile of one instance contributes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct ProfileIds {
    pub feature_nominal: u32,
    pub feature_item: u32,
    pub characteristic_definition: u32,
    pub characteristic_nominal: u32,
    pub characteristic_item: u32,
    pub point_set: u32,
    pub feature_measurement: u32,
    pub characteristic_measurement: u32,
}

/// The ids of one blade parameter's characteristic.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct ParameterIds {
    pub definition: u32,
    pub nominal: u32,
    pub item: u32,
    pub measurement: u32,
}

/// Every id of the document, numbered from 1 in the order the elements are written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct DocumentIds {
    /// The standard the characteristics are defined by (QIF requires one).
    pub standard: u32,
    pub part: u32,
    /// The one feature definition every profile's curve shares (an open "other curve": an airfoil section).
    pub curve_definition: u32,
    /// Each machine that scanned a profile, by name.
    pub devices: Vec<(String, u32)>,
    /// One per profile, in [`scans`] order.
    pub profiles: Vec<ProfileIds>,
    /// One per blade parameter, in [`parameter_characteristics`] order.
    pub parameters: Vec<ParameterIds>,
    pub measurement_results: u32,
    pub actual_component: u32,
    /// The largest id, QIF's `idMax`.
    pub max: u32,
}

/// Every (instance, profile) of the report, instance by instance, in the report's order.
pub(super) fn scans(
    report: &PartReport,
) -> impl Iterator<Item = (&InstanceReport, &ProfileReport)> {
    report.instances.iter().flat_map(|instance| {
        instance
            .profiles
            .iter()
            .map(move |profile| (instance, profile))
    })
}

impl DocumentIds {
    pub fn assign(report: &PartReport) -> Self {
        let mut last = 0;
        let mut next = || {
            last += 1;
            last
        };
        let standard = next();
        let part = next();
        let curve_definition = next();
        let devices = machine_names(report)
            .into_iter()
            .map(|name| (name, next()))
            .collect();
        let profiles = scans(report)
            .map(|_| ProfileIds {
                feature_nominal: next(),
                feature_item: next(),
                characteristic_definition: next(),
                characteristic_nominal: next(),
                characteristic_item: next(),
                point_set: next(),
                feature_measurement: next(),
                characteristic_measurement: next(),
            })
            .collect();
        let parameters = parameter_characteristics(report)
            .iter()
            .map(|_| ParameterIds {
                definition: next(),
                nominal: next(),
                item: next(),
                measurement: next(),
            })
            .collect();
        let measurement_results = next();
        let actual_component = next();
        DocumentIds {
            standard,
            part,
            curve_definition,
            devices,
            profiles,
            parameters,
            measurement_results,
            actual_component,
            max: last,
        }
    }

    /// The id of the measurement device named `machine` (every profile's machine has one, see [`Self::assign`]).
    pub fn device(&self, machine: &str) -> u32 {
        self.devices
            .iter()
            .find(|(name, _)| name == machine)
            .map(|&(_, id)| id)
            .expect("every profile's machine is given a device id when the ids are assigned")
    }
}

/// The machines of the report, then any machine a profile names that the report's list lacks, each once: a
/// profile's device reference must resolve even if the machine list is incomplete.
fn machine_names(report: &PartReport) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    let listed = report.machines.iter().map(|machine| machine.name.as_str());
    let scanning = scans(report).map(|(_, profile)| profile.machine.as_str());
    for name in listed.chain(scanning) {
        if !names.iter().any(|known| known == name) {
            names.push(name.to_string());
        }
    }
    names
}
