//! config/parts/NAME.toml: one kind of part. Its instances are copies of the master turned about an axis
//! (the blades of a propeller), its profiles are the planar sections x = x_mm of the master in the part
//! frame, each with the nominal point from the drawing where the master's teach scan starts. See the
//! shipped config/parts/propeller.toml for every key explained.

use std::collections::HashSet;
use std::path::Path;

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::{finite, in_reach, parse_toml, read_text, ConfigError, MAX_COORDINATE_MM};
use crate::analysis::section::BestFitSettings;
use crate::analysis::tolerances::{Iso484Class, ParameterRules, ParameterTolerances};
pub use crate::analysis::ReferenceSettings;
use crate::geometry::poly::MAX_DEGREE;

/// The highest degree of a reference profile: the profiles blend into a 3-D stack one degree higher, which must
/// stay within the polynomials' [`MAX_DEGREE`] (16), and the degree is even, so 14. (Teaching at 16 or above
/// panicked the fit and left the job finishing for ever.) Time is no tighter bound: teaching the simulated
/// propeller's five profiles of 400 points each (the whole teach fit, all profiles, on two shared cores) took
/// 3.8 s at degree 8, 5.4 s at 12 (which also tries 14) and 5.6 s at 14 in a release build, 4.8, 12.9 and 8.7 s
/// in the test profile.
pub(crate) const MAX_REFERENCE_DEGREE: usize = (MAX_DEGREE - 1) / 2 * 2;

/// The whole part file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartConfig {
    pub name: String,
    pub instances: Instances,
    /// In increasing x; at least two, since the reference surface interpolates between profiles.
    pub profiles: Vec<ProfileEntry>,
    pub scan: ScanSettings,
    /// The reference model fitted to the master's profiles (`kind = "ip"` or `"supershape"`).
    pub reference: ReferenceSettings,
    pub tolerance: ToleranceEntry,
    /// What each inspected section's best fits may move, and how far (`[best_fit]`; by default the translations and
    /// the twist, without limits).
    #[serde(default)]
    pub best_fit: BestFitSettings,
}

/// The repeated features of the part: instance k is instance 0 turned `k * step_deg` about the axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Instances {
    /// In order of turning, e.g. ["A", "B", "C"].
    pub names: Vec<String>,
    /// The instance whose scans define the reference; the part frame has it along +x.
    pub master: String,
    /// A point of the axis the instances repeat about, part frame.
    pub axis_point_mm: [f64; 3],
    /// The axis' direction (any length but zero); the turn is right-handed about it.
    pub axis_direction: [f64; 3],
    /// The turn from one instance to the next.
    pub step_deg: f64,
}

/// One profile: the master's section by the plane x = `x_mm` (part frame).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileEntry {
    pub name: String,
    pub x_mm: f64,
    /// A nominal point of the master's surface in the profile's plane, where its teach scan starts.
    pub start_mm: [f64; 3],
    /// The surface normal at the start as the drawing gives it: the probe comes in along its reverse.
    pub start_normal: [f64; 3],
    /// The way the teach scan sets off from the start, in the profile's plane.
    pub direction: [f64; 3],
}

/// How profiles are scanned.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScanSettings {
    /// The longest gap between scan points, teach and inspect.
    pub step_mm: f64,
    /// The sphere around the start that ends a teach scan when the probe comes back into it.
    pub stop_diameter_mm: f64,
    /// The largest expected distance of a real instance from the taught nominal, along the normal.
    pub max_deviation_mm: f64,
    /// The smallest radius of curvature along a profile; the machine slows down for it.
    pub min_radius_mm: f64,
    /// A curve scan reports a point wherever the path turns by more than this.
    pub max_angle_deg: f64,
    /// Round the tight curves of a profile (a blade's round nose) a scan reports a point wherever the path turns
    /// by more than this instead, where it is smaller: a round edge's tip is fitted to the points within 50 deg of
    /// it, and more points there average more of the probe's noise, on the master (teach) as on each instance. A
    /// sharp edge's roll keeps `max_angle_deg`. Absent: `max_angle_deg` everywhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub round_edge_max_angle_deg: Option<f64>,
}

/// The band a deviation must lie in for the instance to pass, and the tolerances on its sections' and blades'
/// parameters: a ship propeller's ISO 484 class (config/iso484.toml), and per parameter, overriding the class.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToleranceEntry {
    pub lower_mm: f64,
    pub upper_mm: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub class: Option<Iso484Class>,
    #[serde(default)]
    pub parameters: ParameterRules,
}

impl ToleranceEntry {
    pub fn parameter_tolerances(&self) -> ParameterTolerances {
        ParameterTolerances::new(self.class, self.parameters)
    }
}

impl PartConfig {
    /// Reads and checks the file.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let config = Self::from_text(&read_text(path)?, path)?;
        config
            .check_file_name(path)
            .map_err(|problem| ConfigError::Invalid {
                path: path.to_owned(),
                problem,
            })?;
        Ok(config)
    }

    /// Parses and checks the text of the file at `path` (which errors name).
    pub(crate) fn from_text(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let config: PartConfig = parse_toml(text, path)?;
        config.check().map_err(|problem| ConfigError::Invalid {
            path: path.to_owned(),
            problem,
        })?;
        Ok(config)
    }

    /// The station finds a part by its file's name and names its references, reports and history by `name`: two
    /// names for one part would file its results under a name the operator never asked for.
    fn check_file_name(&self, path: &Path) -> Result<(), String> {
        let stem = path.file_stem().map(|s| s.to_string_lossy());
        match stem {
            Some(stem) if stem != self.name => Err(format!(
                "name = {:?} but the file is named {stem}.toml; the station asks for a part by its file's name, \
                 so make them the same (rename the file to {}.toml or set name = {stem:?})",
                self.name, self.name
            )),
            _ => Ok(()),
        }
    }

    /// What serde cannot check: references between keys, order, ranges and directions.
    fn check(&self) -> Result<(), String> {
        if self.name.trim().is_empty() {
            return Err("name is empty; name the part as the station is asked for it".into());
        }
        self.instances.check()?;
        if self.profiles.len() < 2 {
            return Err(format!(
                "{} [[profiles]]; the reference surface is interpolated between profiles, so give at \
                 least two",
                self.profiles.len()
            ));
        }
        let mut names = HashSet::new();
        for profile in &self.profiles {
            profile.check()?;
            if !names.insert(profile.name.as_str()) {
                return Err(format!(
                    "two [[profiles]] are named {:?}; give each its own name",
                    profile.name
                ));
            }
        }
        for pair in self.profiles.windows(2) {
            if pair[1].x_mm <= pair[0].x_mm {
                return Err(format!(
                    "profile {} (x = {} mm) follows profile {} (x = {} mm); list the profiles in \
                     increasing x, each at its own x",
                    pair[1].name, pair[1].x_mm, pair[0].name, pair[0].x_mm
                ));
            }
        }
        self.scan.check()?;
        check_reference(&self.reference)?;
        let tolerance = &self.tolerance;
        if !(finite(&[tolerance.lower_mm, tolerance.upper_mm])
            && tolerance.lower_mm < tolerance.upper_mm)
        {
            return Err(format!(
                "[tolerance] lower_mm = {} must be below upper_mm = {}",
                tolerance.lower_mm, tolerance.upper_mm
            ));
        }
        tolerance
            .parameters
            .check()
            .map_err(|problem| format!("[tolerance.parameters] {problem}"))?;
        self.best_fit
            .check()
            .map_err(|problem| format!("[best_fit] {problem}"))?;
        Ok(())
    }
}

/// Whether a direction can be normalised: its length neither 0 nor overflowing (a length of infinity
/// normalises to the zero vector, which the part fuzz target's checks
/// showed turning instances by a rotation that is not one).
fn usable_direction(v: [f64; 3]) -> bool {
    let norm = Vector3::from(v).norm();
    norm > 1e-12 && norm.is_finite()
}

impl Instances {
    fn check(&self) -> Result<(), String> {
        if self.names.is_empty() {
            return Err("[instances] names is empty; list at least the master".into());
        }
        let mut seen = HashSet::new();
        if let Some(twice) = self.names.iter().find(|name| !seen.insert(name.as_str())) {
            return Err(format!(
                "[instances] names lists {twice:?} twice; give each instance its own name"
            ));
        }
        if !self.names.contains(&self.master) {
            return Err(format!(
                "[instances] master = {:?} is not among names = {:?}",
                self.master, self.names
            ));
        }
        if !in_reach(&self.axis_point_mm) || !usable_direction(self.axis_direction) {
            return Err(format!(
                "[instances] needs an axis_point_mm within {MAX_COORDINATE_MM} mm of the origin and a \
                 non-zero axis_direction (got {:?} and {:?})",
                self.axis_point_mm, self.axis_direction
            ));
        }
        if self.names.len() > 1 && self.step_deg == 0.0 {
            return Err(
                "[instances] step_deg = 0 would put every instance in the same place; give the turn \
                 from one instance to the next"
                    .into(),
            );
        }
        // Beyond a turn the instances' angles lose their meaning, and at 1e308 (the fuzz target's checks showed) they
        // overflow to infinity and the plan's coordinates to NaN.
        if self.step_deg.is_nan() || self.step_deg.abs() > 360.0 {
            return Err(format!(
                "[instances] step_deg = {}: give the turn from one instance to the next, from -360 to 360 \
                 degrees",
                self.step_deg
            ));
        }
        Ok(())
    }
}

impl ProfileEntry {
    /// The plane's normal is x: the start must lie in the plane, and the probe and the scan must move in it.
    fn check(&self) -> Result<(), String> {
        let name = &self.name;
        if !in_reach(&self.start_mm) || !in_reach(&[self.x_mm]) {
            return Err(format!(
                "profile {name}: x_mm and start_mm must be numbers within {MAX_COORDINATE_MM} mm of the \
                 origin"
            ));
        }
        if (self.start_mm[0] - self.x_mm).abs() > 1e-6 {
            return Err(format!(
                "profile {name}: start_mm {:?} is not in the profile's plane x = {} mm; give a start \
                 point with x = {}",
                self.start_mm, self.x_mm, self.x_mm
            ));
        }
        for (key, v) in [
            ("start_normal", self.start_normal),
            ("direction", self.direction),
        ] {
            if !usable_direction(v) || v[0].abs() > 1e-9 * Vector3::from(v).norm() {
                return Err(format!(
                    "profile {name}: {key} = {v:?} must be a non-zero direction in the profile's plane \
                     (its x component 0)"
                ));
            }
        }
        let (normal, direction) = (
            Vector3::from(self.start_normal).normalize(),
            Vector3::from(self.direction).normalize(),
        );
        if normal.cross(&direction).norm() < 1e-6 {
            return Err(format!(
                "profile {name}: direction {:?} runs along start_normal {:?}; give a direction along the \
                 surface",
                self.direction, self.start_normal
            ));
        }
        Ok(())
    }
}

impl ScanSettings {
    /// The finest turn between scan points asked for: round the round edges, where one is given (deg).
    pub(crate) fn finest_angle_deg(&self) -> f64 {
        self.round_edge_max_angle_deg
            .map_or(self.max_angle_deg, |a| a.min(self.max_angle_deg))
    }

    fn check(&self) -> Result<(), String> {
        let positive = [
            ("step_mm", self.step_mm),
            ("stop_diameter_mm", self.stop_diameter_mm),
            ("max_deviation_mm", self.max_deviation_mm),
            ("min_radius_mm", self.min_radius_mm),
        ];
        if let Some((key, value)) = positive
            .iter()
            .find(|(_, value)| !(*value > 0.0 && value.is_finite()))
        {
            return Err(format!("[scan] {key} = {value} must be above zero"));
        }
        let angles = [
            ("max_angle_deg", Some(self.max_angle_deg)),
            ("round_edge_max_angle_deg", self.round_edge_max_angle_deg),
        ];
        if let Some((key, value)) = angles.iter().find_map(|(key, value)| {
            value
                .filter(|v| !(*v > 0.0 && *v < 180.0))
                .map(|v| (key, v))
        }) {
            return Err(format!(
                "[scan] {key} = {value} must lie between 0 and 180 degrees"
            ));
        }
        Ok(())
    }
}

/// What serde cannot check in [reference].
fn check_reference(reference: &ReferenceSettings) -> Result<(), String> {
    match *reference {
        ReferenceSettings::ImplicitPolynomial { degree, .. } => {
            if degree < 2 || degree % 2 == 1 || degree > MAX_REFERENCE_DEGREE {
                return Err(format!(
                    "[reference] degree = {degree}: give an even degree from 2 to {MAX_REFERENCE_DEGREE} (a \
                     closed profile needs an even degree; above {MAX_REFERENCE_DEGREE} the profiles do not blend \
                     into one surface); 8 fits the propeller's blades within 30 um"
                ));
            }
        }
        ReferenceSettings::Supershape { symmetry, .. } => {
            if symmetry.is_some_and(|m| !(2..=12).contains(&m)) {
                return Err(format!(
                    "[reference] symmetry = {}: give the part's number of lobes, from 2 to 12 (6 for a hex \
                     nut), or leave it out to have it found from the scans",
                    symmetry.unwrap_or_default()
                ));
            }
        }
    }
    let spacing = reference.nominal_spacing_mm();
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(format!(
            "[reference] nominal_spacing_mm = {spacing} must be above zero"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    use crate::analysis::section::BestFitMode;

    use nalgebra::{Point2, Point3};
    use zeroset_sim::config::{PartSpec, SimConfig};
    use zeroset_sim::part::curve::SampledCurve;
    use zeroset_sim::part::propeller::Propeller;

    fn repo(path: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
    }

    fn shipped() -> PartConfig {
        PartConfig::load(&repo("config/parts/propeller.toml")).unwrap()
    }

    /// The simulator's ground truth of the propeller the part file describes.
    fn simulated_propeller() -> Propeller {
        let sim = SimConfig::load(&repo("config/sims/propeller.toml")).unwrap();
        let PartSpec::Propeller(spec) = &sim.parts["propeller"] else {
            panic!("config/sims/propeller.toml holds a propeller");
        };
        Propeller::new(spec.clone()).unwrap()
    }

    /// Why the shipped file, edited by `edit`, is refused.
    fn refusal(edit: impl FnOnce(&mut PartConfig)) -> String {
        let mut config = shipped();
        edit(&mut config);
        config.check().unwrap_err()
    }

    #[test]
    fn the_shipped_propeller_has_three_blades_and_five_profiles() {
        let part = shipped();
        assert_eq!(part.name, "propeller");
        assert_eq!(part.instances.names, ["A", "B", "C"]);
        assert_eq!(part.instances.master, "A");
        assert_eq!(part.instances.step_deg, 120.0);
        let xs: Vec<f64> = part.profiles.iter().map(|p| p.x_mm).collect();
        assert_eq!(xs, [100.0, 200.0, 300.0, 400.0, 500.0]);
        let names: Vec<&str> = part.profiles.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["r100", "r200", "r300", "r400", "r500"]);
        assert_eq!(
            part.reference,
            ReferenceSettings::ImplicitPolynomial {
                degree: 8,
                method: crate::geometry::fit3l::FitMethod::Orthogonal,
                nominal_spacing_mm: 2.0
            }
        );
        assert_eq!(
            (part.tolerance.lower_mm, part.tolerance.upper_mm),
            (-0.1, 0.1)
        );
    }

    /// The nut's drawing puts each teach start on the middle of a flat, 40 mm from the axis; the simulated
    /// nut, stood up by config/station-nut.toml, is made 0.2% oversize, so the start lies 0.08 mm inside
    /// it, with the flat's normal where the drawing says.
    #[test]
    fn the_nut_starts_on_the_flats_of_the_simulated_nut() {
        let part = PartConfig::load(&repo("config/parts/nut.toml")).unwrap();
        let station = crate::config::StationConfig::load(&repo("config/station-nut.toml")).unwrap();
        let sim = SimConfig::load(&repo("config/sims/nut.toml")).unwrap();
        let truth = sim.parts["nut"].build().unwrap();
        let to_machine = station.part_to_machine.isometry();
        for profile in &part.profiles {
            let start = to_machine * Point3::from(profile.start_mm);
            let nearest = truth.nearest(&start);
            assert!(
                (nearest.signed_distance + 0.08).abs() < 0.005,
                "profile {}: start {start} is {:.4} mm from the nut",
                profile.name,
                nearest.signed_distance
            );
            let normal = to_machine * Vector3::from(profile.start_normal);
            assert!(
                nearest.normal.dot(&normal) > 0.999,
                "profile {}",
                profile.name
            );
        }
    }

    /// The drawing's start points were computed once from the simulator's blade A; if the simulated
    /// propeller changes, this says which numbers to write again.
    #[test]
    fn every_start_point_lies_on_the_simulated_top_of_blade_a() {
        let truth = simulated_propeller();
        for profile in shipped().profiles {
            let frame = truth.section_frame(0, profile.x_mm);
            let section = SampledCurve::new(truth.section_curve(0, profile.x_mm));
            let local = frame.local(&Point3::from(profile.start_mm));
            let nearest = section.nearest(&Point2::new(local.x, local.y));
            assert!(
                nearest.signed_distance.abs() < 0.05,
                "profile {}: start {:?} is {:.4} mm off blade A",
                profile.name,
                profile.start_mm,
                nearest.signed_distance
            );
            // On the top: the outward normal there has an upward component.
            assert!(
                nearest.on_curve.normal.y > 0.5,
                "profile {}: not on the top surface",
                profile.name
            );
        }
    }

    #[test]
    fn a_misspelt_key_names_the_file_and_the_key() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("propeller.toml");
        let text = std::fs::read_to_string(repo("config/parts/propeller.toml")).unwrap();
        std::fs::write(&path, text.replace("step_deg", "step_degrees")).unwrap();
        let message = PartConfig::load(&path).unwrap_err().to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{message}"
        );
        assert!(
            message.contains("unknown field `step_degrees`"),
            "{message}"
        );
        std::fs::write(
            &path,
            text.replace("kind = \"ip\"", "kind = \"supershape\""),
        )
        .unwrap();
        // A supershape reference has no polynomial degree: the key is named.
        let message = PartConfig::load(&path).unwrap_err().to_string();
        assert!(message.contains("unknown field `degree`"), "{message}");
        std::fs::write(&path, text.replace("kind = \"ip\"", "kind = \"gear\"")).unwrap();
        let message = PartConfig::load(&path).unwrap_err().to_string();
        assert!(message.contains("unknown variant `gear`"), "{message}");
    }

    #[test]
    fn a_name_other_than_the_file_s_is_refused_naming_both() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("blade.toml");
        std::fs::copy(repo("config/parts/propeller.toml"), &path).unwrap();
        let message = PartConfig::load(&path).unwrap_err().to_string();
        assert!(
            message.starts_with(&path.display().to_string())
                && message.contains("name = \"propeller\" but the file is named blade.toml"),
            "{message}"
        );
        let renamed = dir.path().join("propeller.toml");
        std::fs::rename(&path, &renamed).unwrap();
        assert_eq!(PartConfig::load(&renamed).unwrap().name, "propeller");
    }

    #[test]
    fn inconsistent_parts_are_refused_with_the_fix() {
        let message = refusal(|c| c.instances.master = "D".into());
        assert!(
            message.contains("master = \"D\" is not among names"),
            "{message}"
        );

        let message = refusal(|c| c.profiles.swap(1, 2));
        assert!(
            message.contains("profile r200 (x = 200 mm) follows profile r300"),
            "{message}"
        );

        let message = refusal(|c| c.profiles.truncate(1));
        assert!(message.contains("give at least two"), "{message}");

        let message = refusal(|c| c.profiles[0].start_normal = [0.0, 0.0, 0.0]);
        assert!(message.contains("profile r100: start_normal"), "{message}");

        let message = refusal(|c| c.profiles[2].start_mm[0] = 301.0);
        assert!(
            message.contains("not in the profile's plane x = 300 mm"),
            "{message}"
        );

        let message = refusal(|c| c.profiles[3].direction = [0.0, 0.0, -2.0]);
        assert!(message.contains("profile r400: direction"), "{message}");

        let message = refusal(|c| {
            c.reference = ReferenceSettings::ImplicitPolynomial {
                degree: 7,
                method: crate::geometry::fit3l::FitMethod::Orthogonal,
                nominal_spacing_mm: 2.0,
            }
        });
        assert!(message.contains("even degree"), "{message}");

        for degree in [16, 30] {
            let message = refusal(|c| {
                c.reference = ReferenceSettings::ImplicitPolynomial {
                    degree,
                    method: crate::geometry::fit3l::FitMethod::Orthogonal,
                    nominal_spacing_mm: 2.0,
                }
            });
            assert!(
                message.contains(&format!(
                    "[reference] degree = {degree}: give an even degree from 2 to 14"
                )),
                "{message}"
            );
        }

        let message = refusal(|c| {
            c.reference = ReferenceSettings::Supershape {
                symmetry: Some(1),
                nominal_spacing_mm: 2.0,
            }
        });
        assert!(message.contains("symmetry = 1"), "{message}");

        let message = refusal(|c| c.tolerance.lower_mm = 0.2);
        assert!(message.contains("must be below upper_mm"), "{message}");

        let message = refusal(|c| c.best_fit.max_dn_mm = Some(-0.1));
        assert!(
            message.contains("[best_fit] max_dn_mm = -0.1") && message.contains("leave it out"),
            "{message}"
        );
        let message = refusal(|c| {
            c.best_fit.mode = BestFitMode::None;
            c.best_fit.max_dchord_mm = Some(0.1);
        });
        assert!(
            message.contains("[best_fit] limits are given but mode = \"none\""),
            "{message}"
        );
        let message = refusal(|c| {
            c.best_fit.mode = BestFitMode::Translation;
            c.best_fit.max_rotation_deg = Some(0.1);
        });
        assert!(
            message.contains("[best_fit] max_rotation_deg") && message.contains("never turns"),
            "{message}"
        );

        let message = refusal(|c| c.instances.names.push("A".into()));
        assert!(message.contains("lists \"A\" twice"), "{message}");

        // The part fuzz target's finds: values that are finite but overflow once the instances are placed.
        let message = refusal(|c| c.instances.step_deg = 1e308);
        assert!(
            message.contains("step_deg = 100000000000000000000") && message.contains("-360 to 360"),
            "{message}"
        );
        assert!(refusal(|c| c.instances.step_deg = -361.0).contains("step_deg = -361"));
        let message = refusal(|c| c.instances.axis_point_mm = [0.0, 1.0e7, 0.0]);
        assert!(
            message.contains("axis_point_mm within 1000000 mm"),
            "{message}"
        );
        let message = refusal(|c| c.instances.axis_direction = [1e308, 1e308, 0.0]);
        assert!(message.contains("non-zero axis_direction"), "{message}");
        let message = refusal(|c| {
            c.profiles[0].x_mm = -2e6;
            c.profiles[0].start_mm[0] = -2e6;
        });
        assert!(
            message.contains("profile r100: x_mm and start_mm must be numbers within 1000000 mm"),
            "{message}"
        );
    }
}
