//! config/station.toml: the machines the daemon drives, the probe and its speeds, the safety limits, where
//! data, reports and logs go, the control socket, the folder of part files, and where the part sits on the
//! table. See the shipped config/station.toml for every key explained.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use super::{
    finite, folder_of, in_reach, parse_toml, read_text, resolve, ConfigError, MAX_COORDINATE_MM,
};

/// The whole station file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StationConfig {
    /// The station's name, for reports.
    pub name: String,
    /// At least one; names unique.
    pub machines: Vec<MachineEntry>,
    pub probe: ProbeSettings,
    pub safety: Safety,
    /// Absolute after [`StationConfig::load`].
    pub folders: Folders,
    pub control: Control,
    /// The folder of part files, `NAME.toml` each; absolute after [`StationConfig::load`].
    pub parts: PathBuf,
    /// Where the part frame lies in machine coordinates (default: they coincide), so that a fixture
    /// offset is one change here rather than in every part file.
    #[serde(default)]
    pub part_to_machine: Pose,
    /// The file this was read from, for checks made later to name (a part's clearance: see
    /// [`crate::plan::check_clearance`]); empty when not loaded from a file.
    #[serde(skip)]
    pub file: PathBuf,
}

/// One CMM and the line it is reached on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MachineEntry {
    pub name: String,
    /// A serial device (`/dev/ttyUSB0`) or a pseudo-terminal's path (the simulator's, or a link to it).
    pub port: PathBuf,
    /// Bits per second of a serial line; absent for a pseudo-terminal, which has no speed.
    #[serde(default)]
    pub baud: Option<u32>,
    /// How long a command may wait for its `&`; in (0, [`MAX_TIMEOUT_S`]].
    pub ack_timeout_s: f64,
    /// The longest silence within a transaction: longer than the slowest move (homing); in (0, [`MAX_TIMEOUT_S`]].
    pub reply_timeout_s: f64,
    /// Where the machine can put the ball centre, machine coordinates, mm: a move outside is refused at set-up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub volume_mm: Option<Volume>,
}

/// A machine's travel: the box its ball centre can reach, mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Volume {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl Volume {
    pub fn contains(&self, p: &[f64; 3]) -> bool {
        (0..3).all(|i| self.min[i] <= p[i] && p[i] <= self.max[i])
    }
}

/// The probe the station scans with, and its speeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSettings {
    /// The tool's name on the machine, as `ChangeTool` takes it.
    pub tool: String,
    pub travel_mm_s: f64,
    pub probing_mm_s: f64,
    pub scanning_mm_s: f64,
    /// The stylus shank above the ball, along the machine's z axis: the clearance checks sweep it with the ball.
    pub shank_radius_mm: f64,
    pub shank_length_mm: f64,
}

/// The longest timeout a machine may be given, s. The slowest move, homing a large CMM, takes a minute or two;
/// an hour is far beyond any real wait, and a machine silent that long has failed. (A timeout is made a
/// `Duration`, which holds at most about 1.8e19 s: reply_timeout_s = 1e300 panicked the worker.)
pub(crate) const MAX_TIMEOUT_S: f64 = 3600.0;

/// Limits the station keeps to so that it does not hit the part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Safety {
    /// The height of free travel between profiles: machine z, which is the part frame's z when part_to_machine
    /// neither raises nor tilts the part. It must clear the part ([`crate::plan::check_clearance`]).
    pub clearance_z_mm: f64,
    /// A tool whose ball is bigger than this is refused.
    pub max_ball_radius_mm: f64,
    /// The closest the stylus may come to the part model on a move off the surface (a descent to a scan's entry,
    /// a way out); an inspection with a move closer than this is refused before it starts.
    pub move_margin_mm: f64,
}

/// Where the station writes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Folders {
    /// Raw scans and reference models.
    pub data: PathBuf,
    /// One folder per inspected part.
    pub reports: PathBuf,
    pub logs: PathBuf,
}

/// The control API.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Control {
    /// The Unix socket the daemon listens on.
    pub socket: PathBuf,
}

/// A rigid placement on the table: a tilt about the machine's y axis, a turn about its z axis and a
/// shift. Every key defaults to zero, so `{ z_mm = 12.5 }` is a fixture 12.5 mm high. The tilt stands a
/// part up whose profiles are sections across its length: profiles are the planes x = const of the part
/// frame, so a nut or a gear scanned in horizontal sections has its part x axis up, `rot_y_deg = -90`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Pose {
    pub x_mm: f64,
    pub y_mm: f64,
    pub z_mm: f64,
    pub rot_y_deg: f64,
    pub rot_z_deg: f64,
}

impl Pose {
    /// The tilt about y first, then the turn about z, then the shift.
    pub fn isometry(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(self.x_mm, self.y_mm, self.z_mm),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.rot_z_deg.to_radians())
                * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), self.rot_y_deg.to_radians()),
        )
    }
}

impl StationConfig {
    /// Reads and checks the file; relative paths become absolute against its folder.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        let mut config = Self::from_text(&read_text(path)?, path)?;
        config.resolve_paths(&folder_of(path)?);
        Ok(config)
    }

    /// Parses and checks the text of the file at `path` (which errors name, and which `file` holds); its
    /// paths are left as written.
    pub(crate) fn from_text(text: &str, path: &Path) -> Result<Self, ConfigError> {
        let mut config: StationConfig = parse_toml(text, path)?;
        config.check().map_err(|problem| ConfigError::Invalid {
            path: path.to_owned(),
            problem,
        })?;
        config.file = path.to_owned();
        Ok(config)
    }

    /// Makes every path absolute against `folder`, the file's (absolute: see [`folder_of`]).
    pub(crate) fn resolve_paths(&mut self, folder: &Path) {
        for relative in [
            &mut self.folders.data,
            &mut self.folders.reports,
            &mut self.folders.logs,
            &mut self.control.socket,
            &mut self.parts,
        ] {
            *relative = resolve(folder, relative);
        }
        for machine in &mut self.machines {
            machine.port = resolve(folder, &machine.port);
        }
    }

    /// The file of the part named `part`.
    pub fn part_path(&self, part: &str) -> PathBuf {
        self.parts.join(format!("{part}.toml"))
    }

    /// What serde cannot check: counts, uniqueness and ranges.
    fn check(&self) -> Result<(), String> {
        if self.name.trim().is_empty() {
            return Err("name is empty; give the station a name for its reports".into());
        }
        if self.machines.is_empty() {
            return Err("no [[machines]]; the station needs at least one".into());
        }
        let mut names = HashSet::new();
        for machine in &self.machines {
            machine.check()?;
            if !names.insert(machine.name.as_str()) {
                return Err(format!(
                    "two [[machines]] are named {:?}; give each its own name",
                    machine.name
                ));
            }
        }
        self.probe.check()?;
        let safety = &self.safety;
        if !(safety.clearance_z_mm.is_finite()
            && safety.max_ball_radius_mm > 0.0
            && safety.max_ball_radius_mm.is_finite())
        {
            return Err(format!(
                "[safety] needs a finite clearance_z_mm and max_ball_radius_mm above zero \
                 (got {} and {})",
                safety.clearance_z_mm, safety.max_ball_radius_mm
            ));
        }
        for machine in &self.machines {
            let Some(volume) = &machine.volume_mm else {
                continue;
            };
            let (low, high) = (volume.min[2], volume.max[2]);
            if !(low..=high).contains(&safety.clearance_z_mm) {
                return Err(format!(
                    "[safety] clearance_z_mm = {} is outside machine {}'s reach in z ({low} to {high} mm, its \
                     volume_mm): the probe could not travel at that height; give a height inside it, above the \
                     part",
                    safety.clearance_z_mm, machine.name
                ));
            }
        }
        if !(safety.move_margin_mm >= 0.0 && safety.move_margin_mm.is_finite()) {
            return Err(format!(
                "[safety] move_margin_mm = {} must be zero or more",
                safety.move_margin_mm
            ));
        }
        let pose = &self.part_to_machine;
        if !in_reach(&[pose.x_mm, pose.y_mm, pose.z_mm])
            || !finite(&[pose.rot_y_deg, pose.rot_z_deg])
        {
            return Err(format!(
                "part_to_machine {pose:?}: give a shift within {MAX_COORDINATE_MM} mm and finite angles"
            ));
        }
        Ok(())
    }
}

impl MachineEntry {
    fn check(&self) -> Result<(), String> {
        if self.name.trim().is_empty() {
            return Err("a [[machines]] entry has an empty name".into());
        }
        for (key, value) in [
            ("ack_timeout_s", self.ack_timeout_s),
            ("reply_timeout_s", self.reply_timeout_s),
        ] {
            if !(value > 0.0 && value <= MAX_TIMEOUT_S) {
                return Err(format!(
                    "machine {}: {key} = {value:?} must be above 0 and at most {MAX_TIMEOUT_S} s (an hour); \
                     give the seconds to wait (the shipped file waits 10 s for an acknowledgement, 180 s for \
                     a reply)",
                    self.name
                ));
            }
        }
        if let Some(volume) = &self.volume_mm {
            let sound = (0..3).all(|i| {
                volume.min[i].is_finite()
                    && volume.max[i].is_finite()
                    && volume.min[i] < volume.max[i]
            });
            if !sound {
                return Err(format!(
                    "machine {}: volume_mm = {{ min = {:?}, max = {:?} }} must give finite x, y, z with each min \
                     below its max, mm",
                    self.name, volume.min, volume.max
                ));
            }
        }
        if self.baud == Some(0) {
            return Err(format!(
                "machine {}: baud = 0; give the line's speed, or leave baud out for a pseudo-terminal",
                self.name
            ));
        }
        Ok(())
    }
}

impl ProbeSettings {
    fn check(&self) -> Result<(), String> {
        if self.tool.trim().is_empty() {
            return Err("[probe] tool is empty; name the tool as the machine knows it".into());
        }
        let speeds = [self.travel_mm_s, self.probing_mm_s, self.scanning_mm_s];
        if !speeds.iter().all(|s| *s > 0.0 && s.is_finite()) {
            return Err(format!(
                "[probe] speeds must be above zero (got travel {}, probing {}, scanning {} mm/s)",
                self.travel_mm_s, self.probing_mm_s, self.scanning_mm_s
            ));
        }
        if !(self.shank_radius_mm > 0.0
            && self.shank_length_mm > 0.0
            && self.shank_radius_mm.is_finite()
            && self.shank_length_mm.is_finite())
        {
            return Err(format!(
                "[probe] the shank needs a radius and a length above zero (got {} and {} mm)",
                self.shank_radius_mm, self.shank_length_mm
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Point3;

    fn shipped() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("config/station.toml")
    }

    /// The shipped file with `edit` applied to its text, written as `station.toml` in a temporary folder.
    fn edited(edit: impl FnOnce(String) -> String) -> (tempfile::TempDir, PathBuf) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("station.toml");
        let text = std::fs::read_to_string(shipped()).unwrap();
        std::fs::write(&path, edit(text)).unwrap();
        (dir, path)
    }

    #[test]
    fn a_clearance_height_out_of_a_machines_reach_or_a_volume_inside_out_is_refused() {
        let (_dir, path) =
            edited(|t| t.replace("clearance_z_mm = 150.0", "clearance_z_mm = 600.0"));
        let message = StationConfig::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("clearance_z_mm = 600")
                && message.contains("machine cmm1")
                && message.contains("-300 to 500 mm"),
            "{message}"
        );
        let (_dir, path) = edited(|t| {
            t.replace(
                "max = [700.0, 700.0, 500.0]",
                "max = [700.0, -800.0, 500.0]",
            )
        });
        let message = StationConfig::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("volume_mm") && message.contains("machine cmm1"),
            "{message}"
        );
        let config = StationConfig::load(&shipped()).unwrap();
        let volume = config.machines[0]
            .volume_mm
            .expect("the shipped file states the travel");
        assert!(volume.contains(&[0.0, 0.0, 150.0]) && !volume.contains(&[0.0, 0.0, 501.0]));
    }

    #[test]
    fn the_shipped_station_loads_with_absolute_folders_beside_config() {
        let config = StationConfig::load(&shipped()).unwrap();
        let repo = Path::new(env!("CARGO_MANIFEST_DIR"))
            .canonicalize()
            .unwrap();
        assert_eq!(config.machines.len(), 1);
        let cmm1 = &config.machines[0];
        assert_eq!(
            (cmm1.name.as_str(), cmm1.port.as_path(), cmm1.baud),
            ("cmm1", Path::new("/tmp/zeroset/cmm1"), None)
        );
        assert_eq!(config.probe.tool, "Probe1");
        let probe = &config.probe;
        assert_eq!(
            (probe.travel_mm_s, probe.probing_mm_s, probe.scanning_mm_s),
            (100.0, 5.0, 20.0)
        );
        assert_eq!(config.safety.clearance_z_mm, 150.0);
        assert_eq!(config.folders.data, repo.join("var/zeroset/data"));
        assert_eq!(config.folders.reports, repo.join("var/zeroset/reports"));
        assert_eq!(config.folders.logs, repo.join("var/zeroset/logs"));
        assert_eq!(config.control.socket, repo.join("var/zeroset/zeroset.sock"));
        assert_eq!(
            config.part_path("propeller"),
            repo.join("config/parts/propeller.toml")
        );
        assert_eq!(config.part_to_machine.isometry(), Isometry3::identity());
    }

    #[test]
    fn a_misspelt_key_is_named_with_the_file_and_its_line() {
        let (_dir, path) = edited(|t| t.replace("clearance_z_mm", "clearence_z_mm"));
        let message = StationConfig::load(&path).unwrap_err().to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{message}"
        );
        assert!(
            message.contains("unknown field `clearence_z_mm`"),
            "{message}"
        );
        assert!(message.contains("line"), "{message}");
    }

    #[test]
    fn a_missing_key_is_named_with_the_file() {
        let (_dir, path) = edited(|t| {
            t.lines()
                .filter(|line| !line.starts_with("scanning_mm_s"))
                .collect::<Vec<_>>()
                .join("\n")
        });
        let message = StationConfig::load(&path).unwrap_err().to_string();
        assert!(
            message.starts_with(&path.display().to_string()),
            "{message}"
        );
        assert!(
            message.contains("missing field `scanning_mm_s`"),
            "{message}"
        );
    }

    #[test]
    fn relative_paths_resolve_against_the_files_own_folder() {
        let (dir, path) = edited(|t| t.replace("\"/tmp/zeroset/cmm1\"", "\"ports/cmm1\""));
        let config = StationConfig::load(&path).unwrap();
        let folder = dir.path().canonicalize().unwrap();
        assert_eq!(config.machines[0].port, folder.join("ports/cmm1"));
        assert_eq!(config.parts, folder.join("parts"));
        assert_eq!(
            config.folders.data,
            folder.parent().unwrap().join("var/zeroset/data")
        );
    }

    #[test]
    fn duplicate_machine_names_and_bad_numbers_are_refused_with_the_fix() {
        let twice = |t: String| {
            let machine = t
                .split("[[machines]]")
                .nth(1)
                .and_then(|rest| rest.split("\n\n").next())
                .map(str::to_owned)
                .unwrap();
            format!("{t}\n[[machines]]{machine}\n")
        };
        let (_dir, path) = edited(twice);
        let message = StationConfig::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("two [[machines]] are named \"cmm1\""),
            "{message}"
        );

        let (_dir, path) = edited(|t| t.replace("scanning_mm_s = 20.0", "scanning_mm_s = 0.0"));
        let message = StationConfig::load(&path).unwrap_err().to_string();
        assert!(message.contains("speeds must be above zero"), "{message}");
    }

    #[test]
    fn a_timeout_beyond_an_hour_or_not_above_zero_is_refused_naming_the_key_and_the_range() {
        for (from, to, key) in [
            (
                "reply_timeout_s = 180.0",
                "reply_timeout_s = 1e300",
                "reply_timeout_s = 1e300",
            ),
            (
                "reply_timeout_s = 180.0",
                "reply_timeout_s = 3600.5",
                "reply_timeout_s = 3600.5",
            ),
            (
                "ack_timeout_s = 10.0",
                "ack_timeout_s = 0.0",
                "ack_timeout_s = 0.0",
            ),
            (
                "ack_timeout_s = 10.0",
                "ack_timeout_s = nan",
                "ack_timeout_s = NaN",
            ),
            (
                "ack_timeout_s = 10.0",
                "ack_timeout_s = inf",
                "ack_timeout_s = inf",
            ),
        ] {
            let (_dir, path) = edited(|t| t.replacen(from, to, 1));
            let message = StationConfig::load(&path).unwrap_err().to_string();
            assert!(
                message.starts_with(&path.display().to_string()),
                "{message}"
            );
            assert!(
                message.contains(&format!(
                    "machine cmm1: {key} must be above 0 and at most 3600 s"
                )),
                "{message}"
            );
        }
        // The bound itself is a timeout the station can keep.
        let (_dir, path) =
            edited(|t| t.replacen("reply_timeout_s = 180.0", "reply_timeout_s = 3600.0", 1));
        let config = StationConfig::load(&path).unwrap();
        assert_eq!(
            std::time::Duration::from_secs_f64(config.machines[0].reply_timeout_s),
            std::time::Duration::from_secs(3600)
        );
        assert_eq!(config.file, path);
    }

    #[test]
    fn a_fixture_offset_turns_then_shifts() {
        let pose = Pose {
            x_mm: 10.0,
            y_mm: -5.0,
            z_mm: 12.5,
            rot_z_deg: 90.0,
            ..Pose::default()
        };
        let moved = pose.isometry() * Point3::new(100.0, 0.0, 0.0);
        assert!(
            (moved - Point3::new(10.0, 95.0, 12.5)).norm() < 1e-12,
            "{moved}"
        );
        // Stood up: the part's x axis (its length, across the profiles) points up, its z along -x.
        let standing = Pose {
            rot_y_deg: -90.0,
            ..pose
        };
        let up = standing.isometry() * Point3::new(20.0, 0.0, 0.0);
        assert!((up - Point3::new(10.0, -5.0, 32.5)).norm() < 1e-12, "{up}");
        let side = standing.isometry() * Point3::new(0.0, 0.0, 40.0);
        assert!(
            (side - Point3::new(10.0, -45.0, 12.5)).norm() < 1e-12,
            "{side}"
        );
        let (_dir, path) = edited(|t| {
            t.replace(
                "part_to_machine = { x_mm = 0.0, y_mm = 0.0, z_mm = 0.0, rot_z_deg = 0.0 }",
                "part_to_machine = { z_mm = 12.5 }",
            )
        });
        let config = StationConfig::load(&path).unwrap();
        assert_eq!(
            config.part_to_machine,
            Pose {
                z_mm: 12.5,
                ..Pose::default()
            }
        );
        // A shift is a length on the table: one beyond a kilometre is a mistake, and near f64's range it
        // overflows once a part's point is added.
        for shift in ["{ x_mm = 1e308 }", "{ z_mm = -1000000.5 }"] {
            let (_dir, path) = edited(|t| {
                t.replace(
                    "part_to_machine = { x_mm = 0.0, y_mm = 0.0, z_mm = 0.0, rot_z_deg = 0.0 }",
                    &format!("part_to_machine = {shift}"),
                )
            });
            let message = StationConfig::load(&path).unwrap_err().to_string();
            assert!(
                message.contains("give a shift within 1000000 mm and finite angles"),
                "{shift}: {message}"
            );
        }
    }
}
