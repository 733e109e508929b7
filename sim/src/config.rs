//! The simulator's configuration (config/sims/*.toml). Unknown keys and missing required keys are errors
//! that name the key and the file.
//!
//! ```toml
//! time_scale = 1.0              # machine seconds per wall second; 100 runs 100x faster
//!
//! [parts.propeller]             # named parts; kind = "propeller" or "supershape"
//! kind = "propeller"
//! ...                           # see part::propeller::PropellerSpec, part::supershape::SupershapeSpec
//!
//! [[machines]]
//! name = "cmm1"
//! part = "propeller"            # a key of [parts]
//! port = "pty"                  # or "tcp" (127.0.0.1 only), with tcp_port = 0 for any free port
//! seed = 1                      # of the probe's noise
//! noise_sigma_mm = 0.002        # optional, default 0.002
//! baud = 115200                 # optional: pace replies at 10 bits per byte
//! transcript = "/tmp/cmm1.log"  # optional: default zeroset-sim-NAME-PID.log in the temp dir
//! home_mm = [0.0, 0.0, 400.0]
//! volume_min_mm = [-700.0, -700.0, -300.0]
//! volume_max_mm = [700.0, 700.0, 500.0]
//! tools = [{ name = "Probe1", radius_mm = 1.0 }]
//! faults = [{ after_commands = 10, kind = "estop" }]   # optional; see faults.rs
//! [machines.params]             # optional, each [min, default, max]; see Params
//! goto_speed = [1.0, 100.0, 500.0]
//! ```

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::Deserialize;

use crate::faults::ScheduledFault;
use crate::part::propeller::{Propeller, PropellerSpec};
use crate::part::supershape::{Supershape, SupershapeSpec};
use crate::part::Part;

/// The whole file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimConfig {
    pub time_scale: f64,
    pub parts: BTreeMap<String, PartSpec>,
    pub machines: Vec<MachineConfig>,
}

/// One part's ground truth.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum PartSpec {
    Propeller(PropellerSpec),
    Supershape(SupershapeSpec),
}

impl PartSpec {
    /// The part's ground truth, placed on the table.
    pub fn build(&self) -> Result<Arc<dyn Part>, String> {
        Ok(match self {
            PartSpec::Propeller(spec) => {
                Arc::new(Propeller::new(spec.clone()).map_err(|e| e.to_string())?)
            }
            PartSpec::Supershape(spec) => {
                Arc::new(Supershape::new(*spec).map_err(|e| e.to_string())?)
            }
        })
    }
}

/// How a machine is reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PortKind {
    Pty,
    Tcp,
}

/// One simulated machine.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineConfig {
    pub name: String,
    pub part: String,
    pub port: PortKind,
    #[serde(default)]
    pub tcp_port: Option<u16>,
    pub seed: u64,
    #[serde(default = "default_sigma")]
    pub noise_sigma_mm: f64,
    #[serde(default)]
    pub baud: Option<u32>,
    #[serde(default)]
    pub transcript: Option<PathBuf>,
    pub home_mm: [f64; 3],
    pub volume_min_mm: [f64; 3],
    pub volume_max_mm: [f64; 3],
    pub tools: Vec<ToolConfig>,
    #[serde(default)]
    pub faults: Vec<ScheduledFault>,
    #[serde(default)]
    pub params: Params,
}

fn default_sigma() -> f64 {
    0.002
}

/// A probe the machine can change to.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToolConfig {
    pub name: String,
    pub radius_mm: f64,
}

/// A tool parameter's range and default: `[min, default, max]`.
pub type Range3 = [f64; 3];

/// The GoToPar, PtMeasPar and ScanPar blocks (spec 6.3.6, 6.3.7, 6.3.15); speeds mm/s, accelerations
/// mm/s^2, distances mm. Every key is optional.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Params {
    pub goto_speed: Range3,
    pub goto_accel: Range3,
    pub ptmeas_speed: Range3,
    pub ptmeas_accel: Range3,
    pub ptmeas_approach: Range3,
    pub ptmeas_search: Range3,
    pub ptmeas_retract: Range3,
    pub scan_speed: Range3,
    pub scan_accel: Range3,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            goto_speed: [1.0, 100.0, 500.0],
            goto_accel: [10.0, 1000.0, 3000.0],
            ptmeas_speed: [0.5, 10.0, 50.0],
            ptmeas_accel: [10.0, 500.0, 2000.0],
            ptmeas_approach: [0.0, 2.0, 50.0],
            ptmeas_search: [0.5, 5.0, 50.0],
            ptmeas_retract: [-1.0, 2.0, 50.0],
            scan_speed: [0.5, 20.0, 100.0],
            scan_accel: [10.0, 500.0, 2000.0],
        }
    }
}

/// Why a configuration could not be used.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path}: {source}")]
    Parse {
        path: PathBuf,
        source: toml::de::Error,
    },
    #[error("{path}: {problem}")]
    Invalid { path: PathBuf, problem: String },
}

impl SimConfig {
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Reads `text` as the file at `path` (named in errors).
    pub fn parse(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let config: SimConfig = toml::from_str(text).map_err(|source| ConfigError::Parse {
            path: path.to_owned(),
            source,
        })?;
        config.check().map_err(|problem| ConfigError::Invalid {
            path: path.to_owned(),
            problem,
        })?;
        Ok(config)
    }

    /// What serde cannot check: references between keys and ranges.
    fn check(&self) -> Result<(), String> {
        if !(self.time_scale > 0.0 && self.time_scale.is_finite()) {
            return Err(format!(
                "time_scale = {} must be above zero",
                self.time_scale
            ));
        }
        if self.machines.is_empty() {
            return Err("machines: at least one [[machines]] is needed".into());
        }
        let mut names = std::collections::BTreeSet::new();
        for machine in &self.machines {
            let name = &machine.name;
            let valid_name = !name.is_empty()
                && name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
            if !valid_name {
                return Err(format!(
                    "machines.name = {name:?}: use letters, digits, - and _"
                ));
            }
            if !names.insert(name) {
                return Err(format!("machines.name = {name:?} is used twice"));
            }
            if !self.parts.contains_key(&machine.part) {
                return Err(format!(
                    "machine {name}: part = {:?} is not a key of [parts]",
                    machine.part
                ));
            }
            if machine.port == PortKind::Pty && machine.tcp_port.is_some() {
                return Err(format!(
                    "machine {name}: tcp_port is only for port = \"tcp\""
                ));
            }
            if machine.tools.is_empty() || machine.tools.iter().any(|t| t.radius_mm <= 0.0) {
                return Err(format!(
                    "machine {name}: tools needs at least one tool, each with radius_mm > 0"
                ));
            }
            let inside = (0..3).all(|i| {
                machine.volume_min_mm[i] < machine.volume_max_mm[i]
                    && (machine.volume_min_mm[i]..=machine.volume_max_mm[i])
                        .contains(&machine.home_mm[i])
            });
            if !inside {
                return Err(format!(
                    "machine {name}: home_mm must lie inside volume_min_mm..volume_max_mm"
                ));
            }
            if let Err(problem) = self.parts[&machine.part].build() {
                return Err(format!("parts.{}: {problem}", machine.part));
            }
            if machine.baud == Some(0) {
                return Err(format!("machine {name}: baud must be above zero"));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shipped(name: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../config/sims")
            .join(name)
    }

    #[test]
    fn the_shipped_configs_load() {
        for name in [
            "propeller.toml",
            "two-machines.toml",
            "nut.toml",
            "nut-b.toml",
        ] {
            let config = SimConfig::load(&shipped(name)).unwrap_or_else(|e| panic!("{e}"));
            assert!(!config.machines.is_empty(), "{name}");
        }
    }

    #[test]
    fn unknown_and_missing_keys_name_the_key_and_the_file() {
        let text = std::fs::read_to_string(shipped("propeller.toml")).unwrap();
        let path = Path::new("config/sims/test.toml");
        let unknown = text.replacen("seed = ", "colour = \"red\"\nseed = ", 1);
        let error = SimConfig::parse(&unknown, path).unwrap_err().to_string();
        assert!(
            error.contains("colour") && error.contains("config/sims/test.toml"),
            "{error}"
        );
        let missing = text.replacen("home_mm", "# home_mm", 1);
        let error = SimConfig::parse(&missing, path).unwrap_err().to_string();
        assert!(
            error.contains("home_mm") && error.contains("test.toml"),
            "{error}"
        );
        let in_part = text.replacen("pitch_mm", "pitch_in", 1);
        let error = SimConfig::parse(&in_part, path).unwrap_err().to_string();
        assert!(error.contains("pitch_in"), "{error}");
    }

    #[test]
    fn references_between_keys_are_checked() {
        let text = std::fs::read_to_string(shipped("propeller.toml")).unwrap();
        let path = Path::new("x.toml");
        let dangling = text.replacen("part = \"propeller\"", "part = \"boat\"", 1);
        let error = SimConfig::parse(&dangling, path).unwrap_err().to_string();
        assert!(error.contains("boat"), "{error}");
    }
}
