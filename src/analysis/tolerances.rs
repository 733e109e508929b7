//! Tolerances on the parameters of a part's sections and blades, from its part file and its ISO 484 class, and
//! the verdict on each parameter. The class table is config/iso484.toml, compiled in, which cites its source.

use std::fmt;
use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use super::section::{ParameterValue, SectionParametersReport};

/// The class table, read once from the binary.
const CLASS_TABLE: &str = include_str!("../../config/iso484.toml");

/// An ISO 484 accuracy class of ship screw propellers, S the finest.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Iso484Class {
    S,
    I,
    II,
    III,
}

impl fmt::Display for Iso484Class {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self {
            Iso484Class::S => "S",
            Iso484Class::I => "I",
            Iso484Class::II => "II",
            Iso484Class::III => "III",
        };
        f.write_str(name)
    }
}

/// A tolerance as written: limits on the deviation (measured - nominal) in the parameter's unit (`lower`,
/// `upper`) and in percent of the nominal (`lower_pct`, `upper_pct`); where a side has both, the wider applies
/// (ISO 484's "+2 % with a minimum of 2 mm").
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct ToleranceRule {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_pct: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_pct: Option<f64>,
}

impl ToleranceRule {
    /// The lowest and highest deviation allowed from `nominal`.
    pub(crate) fn limits(&self, nominal: f64) -> (f64, f64) {
        let of_nominal = |pct: Option<f64>| pct.map(|pct| pct / 100.0 * nominal.abs());
        let lower = [self.lower, of_nominal(self.lower_pct)]
            .into_iter()
            .flatten()
            .fold(f64::INFINITY, f64::min);
        let upper = [self.upper, of_nominal(self.upper_pct)]
            .into_iter()
            .flatten()
            .fold(f64::NEG_INFINITY, f64::max);
        (lower, upper)
    }

    /// Each side given, finite, and on its side of zero; `name` is the parameter's key, for the message.
    fn check(&self, name: &str) -> Result<(), String> {
        let sides = [
            ("lower", self.lower, self.lower_pct, -1.0),
            ("upper", self.upper, self.upper_pct, 1.0),
        ];
        for (side, absolute, pct, sign) in sides {
            if absolute.is_none() && pct.is_none() {
                return Err(format!(
                    "{name} has no {side} limit: give {side} (in the parameter's unit) or {side}_pct (percent \
                     of the nominal), or both"
                ));
            }
            for value in [absolute, pct].into_iter().flatten() {
                if !value.is_finite() || value * sign < 0.0 {
                    let wanted = if sign < 0.0 {
                        "at most 0"
                    } else {
                        "at least 0"
                    };
                    return Err(format!(
                        "{name}: {side} limit {value} must be a finite deviation {wanted}"
                    ));
                }
            }
        }
        Ok(())
    }
}

/// A parameter a tolerance can be given on: a section's (`chord_mm` ... `pitch_mm`), a blade's mean pitch and
/// angular spacing, the propeller's mean pitch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Parameter {
    Chord,
    MaxThickness,
    LeThickness,
    TeThickness,
    LeRadius,
    TeRadius,
    MaxCamber,
    ChordAngle,
    Pitch,
    BladePitch,
    PropellerPitch,
    AngularSpacing,
}

impl Parameter {
    /// Its name in reports and in `[tolerance.parameters]`.
    pub(crate) fn key(self) -> &'static str {
        ParameterRules::default()
            .entries()
            .into_iter()
            .find(|(p, ..)| *p == self)
            .map_or("", |(_, key, _)| key)
    }
}

/// A tolerance per parameter, each optional; the keys are the report's parameter names.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Default)]
#[serde(deny_unknown_fields)]
pub struct ParameterRules {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chord_mm: Option<ToleranceRule>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_thickness_mm: Option<ToleranceRule>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub le_thickness_mm: Option<ToleranceRule>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub te_thickness_mm: Option<ToleranceRule>,
    /// The edges' radii, where they are round.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub le_radius_mm: Option<ToleranceRule>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub te_radius_mm: Option<ToleranceRule>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_camber_mm: Option<ToleranceRule>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chord_angle_deg: Option<ToleranceRule>,
    /// A section's pitch, P = 2 pi r tan(chord angle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_mm: Option<ToleranceRule>,
    /// A blade's mean pitch: the mean of its sections' pitches.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blade_pitch_mm: Option<ToleranceRule>,
    /// The propeller's mean pitch: the mean of its blades' mean pitches.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub propeller_pitch_mm: Option<ToleranceRule>,
    /// The angle from the blade before, about the hub axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angular_spacing_deg: Option<ToleranceRule>,
}

impl ParameterRules {
    fn entries(&self) -> [(Parameter, &'static str, Option<ToleranceRule>); 12] {
        [
            (Parameter::Chord, "chord_mm", self.chord_mm),
            (
                Parameter::MaxThickness,
                "max_thickness_mm",
                self.max_thickness_mm,
            ),
            (
                Parameter::LeThickness,
                "le_thickness_mm",
                self.le_thickness_mm,
            ),
            (
                Parameter::TeThickness,
                "te_thickness_mm",
                self.te_thickness_mm,
            ),
            (Parameter::LeRadius, "le_radius_mm", self.le_radius_mm),
            (Parameter::TeRadius, "te_radius_mm", self.te_radius_mm),
            (Parameter::MaxCamber, "max_camber_mm", self.max_camber_mm),
            (
                Parameter::ChordAngle,
                "chord_angle_deg",
                self.chord_angle_deg,
            ),
            (Parameter::Pitch, "pitch_mm", self.pitch_mm),
            (Parameter::BladePitch, "blade_pitch_mm", self.blade_pitch_mm),
            (
                Parameter::PropellerPitch,
                "propeller_pitch_mm",
                self.propeller_pitch_mm,
            ),
            (
                Parameter::AngularSpacing,
                "angular_spacing_deg",
                self.angular_spacing_deg,
            ),
        ]
    }

    fn get(&self, parameter: Parameter) -> Option<ToleranceRule> {
        self.entries()
            .into_iter()
            .find(|(p, ..)| *p == parameter)
            .and_then(|(.., rule)| rule)
    }

    /// Every rule given is usable; the message names its key.
    pub(crate) fn check(&self) -> Result<(), String> {
        self.entries()
            .into_iter()
            .filter_map(|(_, name, rule)| rule.map(|rule| rule.check(name)))
            .collect()
    }
}

/// config/iso484.toml.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ClassTable {
    cites: String,
    #[serde(rename = "S")]
    s: ParameterRules,
    #[serde(rename = "I")]
    i: ParameterRules,
    #[serde(rename = "II")]
    ii: ParameterRules,
    #[serde(rename = "III")]
    iii: ParameterRules,
}

impl ClassTable {
    fn rules(&self, class: Iso484Class) -> &ParameterRules {
        match class {
            Iso484Class::S => &self.s,
            Iso484Class::I => &self.i,
            Iso484Class::II => &self.ii,
            Iso484Class::III => &self.iii,
        }
    }
}

fn class_table() -> &'static ClassTable {
    static TABLE: OnceLock<ClassTable> = OnceLock::new();
    TABLE.get_or_init(|| {
        toml::from_str(CLASS_TABLE)
            .expect("config/iso484.toml is compiled in and a unit test reads it")
    })
}

/// Where a parameter's tolerance came from.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
pub enum ToleranceSource {
    /// The part's ISO 484 class (config/iso484.toml).
    Iso484(Iso484Class),
    /// The part file's `[tolerance.parameters]`.
    PartFile,
}

impl fmt::Display for ToleranceSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ToleranceSource::Iso484(class) => write!(f, "ISO 484 class {class}"),
            ToleranceSource::PartFile => f.write_str("the part file"),
        }
    }
}

/// The limits a parameter's deviation was held to (in its unit) and where they came from.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq)]
pub struct AppliedTolerance {
    pub lower: f64,
    pub upper: f64,
    pub from: ToleranceSource,
}

/// Whether a toleranced parameter, or every toleranced parameter of a section, blade or part, is within its limits.
#[derive(Serialize, Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub enum ParameterVerdict {
    Pass,
    Fail,
}

/// A part's parameter tolerances: its part file's rules, and for the parameters they leave out its class's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParameterTolerances {
    class: Option<Iso484Class>,
    part: ParameterRules,
}

impl ParameterTolerances {
    pub fn new(class: Option<Iso484Class>, part: ParameterRules) -> Self {
        ParameterTolerances { class, part }
    }

    /// The class, with the citation of its table.
    pub fn class(&self) -> Option<(Iso484Class, &'static str)> {
        self.class
            .map(|class| (class, class_table().cites.as_str()))
    }

    fn rule(&self, parameter: Parameter) -> Option<(ToleranceRule, ToleranceSource)> {
        self.part
            .get(parameter)
            .map(|rule| (rule, ToleranceSource::PartFile))
            .or_else(|| {
                let class = self.class?;
                let rule = class_table().rules(class).get(parameter)?;
                Some((rule, ToleranceSource::Iso484(class)))
            })
    }

    /// Sets `value`'s tolerance and verdict where `parameter` has a tolerance.
    pub(crate) fn judge(&self, parameter: Parameter, value: &mut ParameterValue) {
        if let Some((rule, from)) = self.rule(parameter) {
            let (lower, upper) = rule.limits(value.nominal);
            value.tolerance = Some(AppliedTolerance { lower, upper, from });
            value.verdict = Some(if lower <= value.deviation && value.deviation <= upper {
                ParameterVerdict::Pass
            } else {
                ParameterVerdict::Fail
            });
        }
    }

    /// Judges each of a section's parameters that has a tolerance, and the section on them.
    pub(crate) fn judge_section(&self, section: &mut SectionParametersReport) {
        for (parameter, value) in section.judged_mut() {
            self.judge(parameter, value);
        }
        section.verdict = verdict_of(section.judged().map(|(_, v)| v));
    }
}

/// A parameter out of its tolerance in words, e.g. "max_thickness_mm -0.0382 mm outside [-0.0300, +0.0300] mm";
/// `None` if it is not out of one. `name` is the report's key, whose ending gives the unit.
pub(crate) fn failure_text(name: &str, value: &ParameterValue) -> Option<String> {
    let tolerance = value
        .tolerance
        .filter(|_| value.verdict == Some(ParameterVerdict::Fail))?;
    let unit = if name.ends_with("_deg") { "deg" } else { "mm" };
    Some(format!(
        "{name} {:+.4} {unit} outside [{:+.4}, {:+.4}] {unit}",
        value.deviation, tolerance.lower, tolerance.upper
    ))
}

/// The verdict on several parameters: none toleranced, `None`; else a failure if any fails.
pub(crate) fn verdict_of<'a>(
    values: impl IntoIterator<Item = &'a ParameterValue>,
) -> Option<ParameterVerdict> {
    values
        .into_iter()
        .filter_map(|v| v.verdict)
        .reduce(|whole, one| match (whole, one) {
            (ParameterVerdict::Pass, ParameterVerdict::Pass) => ParameterVerdict::Pass,
            _ => ParameterVerdict::Fail,
        })
}

/// How many of `values` are out of tolerance.
pub(crate) fn failures<'a>(values: impl IntoIterator<Item = &'a ParameterValue>) -> usize {
    values
        .into_iter()
        .filter(|v| v.verdict == Some(ParameterVerdict::Fail))
        .count()
}

#[cfg(test)]
mod tests;
