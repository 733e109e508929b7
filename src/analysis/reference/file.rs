//! The reference file: saved atomically, and loaded only when it can be measured against as it was taught.

use std::path::Path;

use nalgebra::Vector3;

use super::{NominalPoint, Reference, ReferenceSettings, FORMAT, UNITS, VERSION};
use crate::fsutil::write_atomically;
use crate::model_file::{self, stack_of, FittedIp, ReferenceModel};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReferenceFileError {
    #[error("{path}: cannot read the reference: {problem}")]
    Read { path: String, problem: String },
    #[error("{path}: cannot save the reference: {problem}")]
    Write { path: String, problem: String },
    #[error("{path}: not a readable reference file: {problem}")]
    Parse { path: String, problem: String },
    #[error("{path}: {problem}; teach the reference again")]
    Invalid { path: String, problem: String },
}

impl Reference {
    /// Saves the reference atomically: a reader never sees half a file.
    pub fn save(&self, path: &Path) -> Result<(), ReferenceFileError> {
        let json = serde_json::to_string_pretty(self).map_err(|e| ReferenceFileError::Write {
            path: path.display().to_string(),
            problem: e.to_string(),
        })?;
        write_atomically(path, json.as_bytes()).map_err(|e| ReferenceFileError::Write {
            path: path.display().to_string(),
            problem: e.to_string(),
        })
    }

    /// Loads a reference and checks that it can be measured against as it was taught: format, version, units,
    /// nominals that can be scanned along, and a model whose profiles match the reference's and blend into a
    /// stack.
    pub fn load(path: &Path) -> Result<Self, ReferenceFileError> {
        let shown = || path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ReferenceFileError::Read {
            path: shown(),
            problem: e.to_string(),
        })?;
        let reference: Self =
            serde_json::from_str(&text).map_err(|e| ReferenceFileError::Parse {
                path: shown(),
                problem: e.to_string(),
            })?;
        reference
            .check()
            .map_err(|problem| ReferenceFileError::Invalid {
                path: shown(),
                problem,
            })?;
        Ok(reference)
    }

    fn check(&self) -> Result<(), String> {
        if self.format != FORMAT {
            return Err(format!("format '{}' is not '{FORMAT}'", self.format));
        }
        if self.version != VERSION {
            return Err(format!(
                "version {} is not supported (this build reads version {VERSION})",
                self.version
            ));
        }
        if self.units != UNITS || self.model.units != UNITS {
            return Err(format!(
                "units '{}' (model '{}'): only {UNITS} are supported",
                self.units, self.model.units
            ));
        }
        if self.model.format != model_file::FORMAT || self.model.version != model_file::VERSION {
            return Err(format!(
                "model format '{}' version {} is not '{}' version {}",
                self.model.format,
                self.model.version,
                model_file::FORMAT,
                model_file::VERSION
            ));
        }
        for (i, taught) in self.profiles.iter().enumerate() {
            let at = format!("profile {i} '{}' (x = {} mm)", taught.name, taught.x_mm);
            if taught.nominals.is_empty() {
                return Err(format!("{at} has no nominal points to scan along"));
            }
            for (k, nominal) in taught.nominals.iter().enumerate() {
                check_nominal(nominal).map_err(|e| format!("{at}, nominal {k}: {e}"))?;
            }
        }
        let profiles = match (&self.model.model, &self.settings) {
            (ReferenceModel::Stack { profiles }, ReferenceSettings::ImplicitPolynomial { .. }) => {
                profiles
            }
            (ReferenceModel::Supershape { .. }, ReferenceSettings::Supershape { .. }) => {
                return Ok(());
            }
            _ => {
                return Err(format!(
                    "settings.kind {} does not match model.kind (an ip reference holds an \
                     'ip-stack', a supershape reference a 'supershape')",
                    serde_json::to_value(self.settings).expect("settings serialise")["kind"]
                ))
            }
        };
        if profiles.len() != self.profiles.len() {
            return Err(format!(
                "the model has {} profiles but the reference lists {}",
                profiles.len(),
                self.profiles.len()
            ));
        }
        for (i, (taught, model)) in self.profiles.iter().zip(profiles).enumerate() {
            let at = format!("profile {i} '{}' (x = {} mm)", taught.name, taught.x_mm);
            if taught.x_mm != model.x {
                return Err(format!(
                    "{at}: the model's profile {i} is at x = {} mm",
                    model.x
                ));
            }
            check_profile_model(&model.fitted).map_err(|e| format!("{at}: {e}"))?;
        }
        stack_of(profiles).map_err(|e| e.to_string())?;
        Ok(())
    }
}

/// How far a nominal's normal may be from unit length. The teach writes unit normals, which JSON keeps to the
/// last bit; this leaves room for a hand-edited file's seven decimals. The scans offset the probe along the
/// normals as they are, so one 1e-6 off unit moves a 6 mm offset by 6 nm.
const UNIT_NORMAL_TOLERANCE: f64 = 1e-6;

/// A nominal the station can scan along has a unit normal (its numbers are finite: JSON has no others). A zero
/// normal was accepted once and made every move off the surface NaN.
fn check_nominal(nominal: &NominalPoint) -> Result<(), String> {
    let normal = Vector3::from(nominal.normal);
    if (normal.norm() - 1.0).abs() > UNIT_NORMAL_TOLERANCE {
        return Err(format!(
            "normal {:?} is not a unit vector (length {})",
            nominal.normal,
            normal.norm()
        ));
    }
    Ok(())
}

/// What a profile model must satisfy to be evaluated: a positive scale, a polynomial that is not identically
/// zero and an ordered domain. (Finiteness is already enforced by the JSON readers of these fields.)
fn check_profile_model(fitted: &FittedIp<2>) -> Result<(), String> {
    let scale = fitted.ip.frame.scale;
    if scale <= 0.0 {
        return Err(format!(
            "ip.frame.scale is {scale}; it must be a positive number of mm"
        ));
    }
    if fitted.ip.poly.coeffs().iter().all(|c| *c == 0.0) {
        return Err("ip.poly.coefficients are all zero: the model has no zero set".into());
    }
    if (0..2).any(|k| fitted.domain.min[k] >= fitted.domain.max[k]) {
        return Err("domain.min must be below domain.max on every axis".into());
    }
    Ok(())
}
