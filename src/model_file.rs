//! Reference-model files: versioned JSON holding the kind, the polynomial (degree and coefficients in the
//! monomial order of seed 003, in normalised coordinates), the normalisation, the units, the fitting method and
//! the fit statistics, so that a report can always say exactly what a deviation was measured against.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::fsutil::write_atomically;
use crate::geometry::faces::{
    check_stack, FacedProfile, FacedSection, FacesError, FittedFaces, Join,
};
use crate::geometry::fit3l::{FitStats, Fitted};
use crate::geometry::implicit::IpModel;
use crate::geometry::interp::{Profile, ProfileStack, StackError};
use crate::geometry::sampling::Aabb;
use crate::geometry::supershape::csg::Solid;
use crate::geometry::supershape::distance::SolidDistance;
use nalgebra::{Point3, Vector2};

pub const FORMAT: &str = "zeroset-model";
pub const VERSION: u32 = 1;
/// How to read the coefficient vectors, written into every file for whoever reads it without this code.
pub const MONOMIAL_ORDER: &str =
    "graded by total degree, then descending powers of the first variable, then of the second (seed 003)";

/// A reference model file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelFile {
    pub format: String,
    pub version: u32,
    pub units: String,
    pub monomial_order: String,
    /// How the model was made: a fitting method, or where a published model comes from.
    pub method: String,
    pub model: ReferenceModel,
}

/// The kinds of reference model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", deny_unknown_fields)]
pub enum ReferenceModel {
    /// One planar profile in the (y, z) plane: variables y, z.
    #[serde(rename = "ip-profile")]
    Profile(FittedIp<2>),
    /// One surface: variables x, y, z.
    #[serde(rename = "ip-surface")]
    Surface(FittedIp<3>),
    /// Parallel profiles along x blended linearly into a piecewise 3-D model (seed 003 section 4).
    #[serde(rename = "ip-stack")]
    Stack { profiles: Vec<StackProfile> },
    /// One planar profile in the (y, z) plane split at its sharp edges into faces, an implicit polynomial each,
    /// joined where they meet (`geometry::faces`).
    #[serde(rename = "ip-faces")]
    Faces(FacedIp),
    /// Parallel profiles along x, each split at its sharp edges into faces, each face lofted to the same face of
    /// the next profile (`geometry::faces::FacedLoft`): the sharp edges run as creases from profile to profile.
    #[serde(rename = "ip-faces-stack")]
    FacesStack { profiles: Vec<FacedStackProfile> },
    /// A CSG tree of supershapes (seeds 000 and 001) with the statistics of its fit.
    #[serde(rename = "supershape")]
    Supershape {
        solid: Solid,
        fit: Option<SolidFitStats>,
    },
}

/// How closely a supershape model, or a profile of faces, follows the points it was made from: exact distances,
/// mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolidFitStats {
    pub points: usize,
    pub rms_distance_mm: f64,
    pub max_distance_mm: f64,
}

impl SolidFitStats {
    /// The exact distances of `points` to the solid; `None` without points or if a point has no foot.
    pub fn of(distance: &SolidDistance, points: &[Point3<f64>]) -> Option<Self> {
        let distances: Vec<f64> = points
            .iter()
            .map(|p| distance.foot(p).map(|f| f.distance_mm))
            .collect::<Option<_>>()?;
        (!distances.is_empty()).then(|| Self {
            points: distances.len(),
            rms_distance_mm: (distances.iter().map(|d| d * d).sum::<f64>()
                / distances.len() as f64)
                .sqrt(),
            max_distance_mm: distances.iter().fold(0.0, |m, d| m.max(d.abs())),
        })
    }
}

/// A supershape model must bound a finite, non-empty region to be measured against.
fn check_solid(solid: &Solid) -> Result<(), String> {
    let bounds = solid.bounds();
    let finite = bounds
        .min
        .iter()
        .chain(bounds.max.iter())
        .all(|c| c.is_finite());
    if !(finite && (0..3).all(|i| bounds.min[i] < bounds.max[i])) {
        return Err(format!(
            "the supershape solid has no finite extent (bounds {:?} to {:?} mm); check its parameters",
            bounds.min, bounds.max
        ));
    }
    Ok(())
}

/// An implicit polynomial with the box of the data it was fitted to (where it is valid) and its statistics.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FittedIp<const N: usize> {
    pub ip: IpModel<N>,
    pub domain: Aabb<N>,
    pub fit: Option<FitStats>,
}

impl<const N: usize> From<Fitted<N>> for FittedIp<N> {
    fn from(fitted: Fitted<N>) -> Self {
        Self {
            ip: fitted.model,
            domain: fitted.domain,
            fit: Some(fitted.stats),
        }
    }
}

impl<const N: usize> FittedIp<N> {
    /// What a model file must satisfy to be evaluated as it was saved: a positive, finite scale, a polynomial
    /// that is not identically zero, and a domain whose corners are finite and ordered.
    fn check(&self) -> Result<(), String> {
        let scale = self.ip.frame.scale;
        if !(scale.is_finite() && scale > 0.0) {
            return Err(format!(
                "ip.frame.scale is {scale}; it must be a positive number of mm"
            ));
        }
        if self.ip.frame.center.iter().any(|c| !c.is_finite()) {
            return Err("ip.frame.center has a value that is not a finite number".to_string());
        }
        if self.ip.poly.coeffs().iter().all(|c| *c == 0.0) {
            return Err("ip.poly.coefficients are all zero: the model has no zero set".to_string());
        }
        let ordered = (0..N).all(|k| self.domain.min[k] < self.domain.max[k]);
        if !ordered {
            return Err("domain.min must be below domain.max on every axis".to_string());
        }
        Ok(())
    }
}

/// A profile of faces: each face's polynomial with the box of its points and its statistics, counter-clockwise
/// round the part; `joins[j]` is where face j ends and the next begins.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FacedIp {
    pub faces: Vec<FittedIp<2>>,
    pub joins: Vec<Join>,
    /// The whole profile's distances to the fitted points.
    pub fit: Option<SolidFitStats>,
}

impl FacedIp {
    /// A profile fitted face by face, with its distances to the `points` it was fitted to.
    pub fn of(fitted: FittedFaces, points: &[Vector2<f64>]) -> Self {
        let distances: Vec<f64> = points
            .iter()
            .map(|p| fitted.model.foot(p).map_or(f64::INFINITY, |f| f.distance))
            .collect();
        let stats = SolidFitStats {
            points: distances.len(),
            rms_distance_mm: (distances.iter().map(|d| d * d).sum::<f64>()
                / distances.len().max(1) as f64)
                .sqrt(),
            max_distance_mm: distances.iter().fold(0.0, |m, d| m.max(d.abs())),
        };
        Self {
            joins: fitted.model.joins().to_vec(),
            faces: fitted.faces.into_iter().map(FittedIp::from).collect(),
            fit: Some(stats),
        }
    }

    /// The box of every face's points, mm.
    pub fn domain(&self) -> Aabb<2> {
        let mut domain = self.faces[0].domain;
        for face in &self.faces[1..] {
            domain.min = domain.min.inf(&face.domain.min);
            domain.max = domain.max.sup(&face.domain.max);
        }
        domain
    }

    /// The model to measure with: the faces traced from join to join.
    pub fn profile(&self) -> Result<FacedProfile, FacesError> {
        FacedProfile::new(
            self.faces.iter().map(|f| f.ip.clone()).collect(),
            self.joins.clone(),
            &self.domain(),
        )
    }

    fn check(&self) -> Result<(), String> {
        if self.faces.len() < 2 || self.joins.len() != self.faces.len() {
            return Err(format!(
                "a profile of faces needs two or more faces and a join per face; it has {} faces and {} joins",
                self.faces.len(),
                self.joins.len()
            ));
        }
        for (j, face) in self.faces.iter().enumerate() {
            face.check().map_err(|e| format!("face {j}: {e}"))?;
        }
        self.profile().map(drop).map_err(|e| e.to_string())
    }
}

/// One profile of a stack of faces: its position along x (mm) and its faces in the (y, z) plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FacedStackProfile {
    pub x: f64,
    pub profile: FacedIp,
}

/// A stack of faces' profiles as the loft takes them.
pub fn faced_sections(profiles: &[FacedStackProfile]) -> Vec<FacedSection> {
    profiles
        .iter()
        .map(|p| FacedSection {
            x: p.x,
            faces: p.profile.faces.iter().map(|f| f.ip.clone()).collect(),
            joins: p.profile.joins.clone(),
            domain: p.profile.domain(),
        })
        .collect()
}

/// One profile of a stack: its position along x (mm) and its fitted (y, z) model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StackProfile {
    pub x: f64,
    #[serde(flatten)]
    pub fitted: FittedIp<2>,
}

impl ModelFile {
    pub fn new(method: impl Into<String>, model: ReferenceModel) -> Self {
        Self {
            format: FORMAT.to_string(),
            version: VERSION,
            units: "mm".to_string(),
            monomial_order: MONOMIAL_ORDER.to_string(),
            method: method.into(),
            model,
        }
    }

    pub fn save(&self, path: &Path) -> Result<(), ModelFileError> {
        let json = serde_json::to_string_pretty(self).expect("a model serialises");
        write_atomically(path, json.as_bytes())
            .map_err(|e| ModelFileError::new(path, e.to_string()))
    }

    pub fn load(path: &Path) -> Result<Self, ModelFileError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| ModelFileError::new(path, format!("cannot read: {e}")))?;
        let file: Self =
            serde_json::from_str(&text).map_err(|e| ModelFileError::new(path, e.to_string()))?;
        if file.format != FORMAT {
            return Err(ModelFileError::new(
                path,
                format!("format '{}' is not '{FORMAT}'", file.format),
            ));
        }
        if file.version != VERSION {
            return Err(ModelFileError::new(
                path,
                format!(
                    "version {} is not supported (this build reads version {VERSION})",
                    file.version
                ),
            ));
        }
        if file.units != "mm" {
            return Err(ModelFileError::new(
                path,
                format!("units '{}' (only mm are supported)", file.units),
            ));
        }
        let checked = match &file.model {
            ReferenceModel::Profile(m) => m.check(),
            ReferenceModel::Surface(m) => m.check(),
            ReferenceModel::Stack { profiles } => {
                each_profile(profiles.iter().map(|p| (p.x, p.fitted.check())))
                    .and_then(|()| stack_of(profiles).map(drop).map_err(|e| e.to_string()))
            }
            ReferenceModel::Supershape { solid, .. } => check_solid(solid),
            ReferenceModel::Faces(faced) => faced.check(),
            ReferenceModel::FacesStack { profiles } => {
                each_profile(profiles.iter().map(|p| (p.x, p.profile.check()))).and_then(|()| {
                    check_stack(&mut faced_sections(profiles)).map_err(|e| e.to_string())
                })
            }
        };
        checked.map_err(|problem| ModelFileError::new(path, problem))?;
        Ok(file)
    }
}

/// A stack's profiles' own checks, (x, verdict) in file order: the first problem, naming its profile.
fn each_profile(checks: impl Iterator<Item = (f64, Result<(), String>)>) -> Result<(), String> {
    checks.enumerate().try_for_each(|(i, (x, checked))| {
        checked.map_err(|e| format!("profile {i} (x = {x} mm): {e}"))
    })
}

/// The piecewise 3-D model of a stack's profiles.
pub fn stack_of(profiles: &[StackProfile]) -> Result<ProfileStack, StackError> {
    ProfileStack::new(
        profiles
            .iter()
            .map(|p| Profile {
                x: p.x,
                model: p.fitted.ip.clone(),
            })
            .collect(),
    )
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{path}: {problem}")]
pub struct ModelFileError {
    pub path: String,
    pub problem: String,
}

impl ModelFileError {
    fn new(path: &Path, problem: impl Into<String>) -> Self {
        Self {
            path: path.display().to_string(),
            problem: problem.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::implicit::Frame;
    use crate::geometry::poly::Poly;
    use nalgebra::Vector2;

    #[test]
    fn a_saved_model_loads_bit_for_bit_and_bad_ones_are_refused_by_field() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("m.json");
        let coefficients: Vec<f64> = (0..15).map(|i| (i as f64 * 0.7).sin() / 3.0).collect();
        let fitted = FittedIp {
            ip: IpModel {
                frame: Frame {
                    center: Vector2::new(0.1, 1.0 / 3.0),
                    scale: 27.3,
                },
                poly: Poly::new(4, coefficients.clone()),
            },
            domain: Aabb {
                min: Vector2::new(-1.0, -2.0),
                max: Vector2::new(3.0, 4.0),
            },
            fit: None,
        };
        ModelFile::new("test", ReferenceModel::Profile(fitted.clone()))
            .save(&path)
            .unwrap();
        let loaded = ModelFile::load(&path).unwrap();
        assert_eq!(
            loaded.model,
            ReferenceModel::Profile(fitted.clone()),
            "every coefficient round-trips exactly"
        );
        let mut negative = fitted.clone();
        negative.ip.frame.scale = -3.0;
        ModelFile::new("test", ReferenceModel::Profile(negative))
            .save(&path)
            .unwrap();
        let error = ModelFile::load(&path).unwrap_err().to_string();
        assert!(error.contains("ip.frame.scale is -3"), "{error}");
        let mut swapped = fitted;
        std::mem::swap(&mut swapped.domain.min, &mut swapped.domain.max);
        ModelFile::new("test", ReferenceModel::Profile(swapped))
            .save(&path)
            .unwrap();
        assert!(ModelFile::load(&path)
            .unwrap_err()
            .to_string()
            .contains("domain.min must be below"));
    }
}
