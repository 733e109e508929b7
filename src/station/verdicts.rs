//! The verdicts on a part's parameters beyond its sections': each blade's mean pitch and angular spacing and the
//! propeller's mean pitch, judged against the part's tolerances, and each blade's verdict made to count every
//! parameter of its own out of tolerance.

use crate::analysis::section::ParameterValue;
use crate::analysis::tolerances::{failures, Parameter, ParameterTolerances};
use crate::report::InstanceReport;

/// Judges each blade's mean pitch (the mean of its sections' pitches) and angular spacing, adds its sections' and
/// its own failures to its verdict, and returns the propeller's mean pitch (the mean of the blades' mean pitches)
/// judged, `None` for a part with no pitch.
pub(super) fn judge_blades(
    tolerances: &ParameterTolerances,
    instances: &mut [InstanceReport],
) -> Option<ParameterValue> {
    for instance in instances.iter_mut() {
        instance.blade_pitch_mm = ParameterValue::mean(
            instance
                .profiles
                .iter()
                .filter_map(|p| p.parameters.as_ref()?.pitch_mm.as_ref()),
        );
        if let Some(pitch) = instance.blade_pitch_mm.as_mut() {
            tolerances.judge(Parameter::BladePitch, pitch);
        }
        if let Some(spacing) = instance.angular_spacing_deg.as_mut() {
            tolerances.judge(Parameter::AngularSpacing, spacing);
        }
        let sections = failures(
            instance
                .profiles
                .iter()
                .filter_map(|p| p.parameters.as_ref())
                .flat_map(|p| p.judged().map(|(_, v)| v)),
        );
        let own = failures(
            instance
                .blade_pitch_mm
                .iter()
                .chain(instance.angular_spacing_deg.iter()),
        );
        instance.verdict = instance
            .verdict
            .clone()
            .with_parameters_outside(sections + own, instance.stats.worst_mm);
    }
    let mut propeller =
        ParameterValue::mean(instances.iter().filter_map(|i| i.blade_pitch_mm.as_ref()))?;
    tolerances.judge(Parameter::PropellerPitch, &mut propeller);
    Some(propeller)
}
