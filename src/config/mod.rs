//! The station's configuration files: config/station.toml (machines, probe, safety, folders: see
//! [`station`]) and config/parts/NAME.toml (a part's instances, profiles and scan settings: see [`part`]).
//!
//! Both are TOML read with serde and `deny_unknown_fields`, so that a misspelt key is an error rather than a
//! silently ignored setting. Every error names the file; parse errors add toml's own report of the key and
//! line. Relative paths in a file are resolved against that file's folder, so the station works from any
//! working directory.

#[doc(hidden)]
pub mod fuzz;
pub mod part;
pub mod station;

use std::path::{Component, Path, PathBuf};

use serde::de::DeserializeOwned;

pub use part::{
    Instances, PartConfig, ProfileEntry, ReferenceSettings, ScanSettings, ToleranceEntry,
};
pub use station::{
    Control, Folders, MachineEntry, Pose, ProbeSettings, Safety, StationConfig, Volume,
};

/// Why a configuration file cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{}: cannot read the file ({source}); check the path and its permissions", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {source}", path.display())]
    Parse {
        path: PathBuf,
        source: toml::de::Error,
    },
    #[error("{}: {problem}", path.display())]
    Invalid { path: PathBuf, problem: String },
}

/// Reads a configuration file's text; the error names it.
fn read_text(path: &Path) -> Result<String, ConfigError> {
    std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_owned(),
        source,
    })
}

/// Deserialises the TOML text of the file at `path`; errors name it.
fn parse_toml<T: DeserializeOwned>(text: &str, path: &Path) -> Result<T, ConfigError> {
    toml::from_str(text).map_err(|source| ConfigError::Parse {
        path: path.to_owned(),
        source,
    })
}

/// The absolute folder that holds `file`, against which the file's relative paths are resolved.
fn folder_of(file: &Path) -> Result<PathBuf, ConfigError> {
    let folder = match file.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    folder.canonicalize().map_err(|source| ConfigError::Read {
        path: file.to_owned(),
        source,
    })
}

/// `path` made absolute against `folder` (itself absolute, with no symbolic links: see [`folder_of`]),
/// with `.` and `..` removed so that logs and reports show plain paths.
fn resolve(folder: &Path, path: &Path) -> PathBuf {
    let mut resolved = PathBuf::new();
    for component in folder.join(path).components() {
        match component {
            Component::CurDir => {}
            Component::ParentDir => {
                resolved.pop();
            }
            other => resolved.push(other),
        }
    }
    resolved
}

/// Whether every number is finite.
fn finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// The farthest from the origin, along any axis, that a point or shift of a configuration may lie, mm: a
/// kilometre, far beyond any machine's table, and small enough that placing the part (turns about a point,
/// shifts) cannot overflow. Finite was not enough: the part fuzz target's checks
/// (`config::fuzz`) showed an axis point at 1e308 mm turned into a machine coordinate of infinity.
const MAX_COORDINATE_MM: f64 = 1e6;

/// Whether every number lies within [`MAX_COORDINATE_MM`] of zero (NaN does not).
fn in_reach(values: &[f64]) -> bool {
    values.iter().all(|v| v.abs() <= MAX_COORDINATE_MM)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_resolve_against_the_folder_and_lose_their_dots() {
        let folder = Path::new("/etc/zeroset/config");
        assert_eq!(
            resolve(folder, Path::new("../var/./data")),
            PathBuf::from("/etc/zeroset/var/data")
        );
        assert_eq!(
            resolve(folder, Path::new("/tmp/zeroset/cmm1")),
            PathBuf::from("/tmp/zeroset/cmm1")
        );
        assert_eq!(
            resolve(folder, Path::new("parts")),
            PathBuf::from("/etc/zeroset/config/parts")
        );
    }

    #[test]
    fn the_folder_of_a_bare_file_name_is_the_working_directory() {
        let here = std::env::current_dir().unwrap().canonicalize().unwrap();
        assert_eq!(folder_of(Path::new("station.toml")).unwrap(), here);
    }
}
