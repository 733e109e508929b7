//! Live deviation: the signed orthogonal distance of each arriving point to its reference profile's 2-D IP, or to
//! the reference's supershape solid (the exact 3-D Euclidean distance).
//!
//! A gauge is built once per profile (sampling the zero set is the expensive part, milliseconds) and shared by
//! every scan of that profile; a scan's measurer seeds each point's foot from the previous one, so a point along a
//! scan costs a Newton solve of a few iterations (microseconds). The supershape's distance is shared by every
//! profile: one solid, sampled once.

use std::sync::{Arc, OnceLock};

use nalgebra::{Point3, Vector2};
use serde::{Deserialize, Serialize};

use super::edges::{sharpen, SharpEdge};
use super::reference::Reference;
use super::section;
use crate::geometry::distance::{DistanceError, ExactDistance, Foot};
use crate::geometry::faces::FacedProfile;
use crate::geometry::implicit::IpModel;
use crate::geometry::sampling::{Aabb, ZeroSetSamples};
use crate::geometry::section_parameters::{section_parameters, SectionParameters};
use crate::geometry::supershape::distance::SolidDistance;
use crate::model_file::ReferenceModel;

/// The zero set is sampled over the profile's data box enlarged by this on every side: it covers any deviation
/// worth measuring (a blade 10 mm off is scrap), and points beyond it still get a distance, from farther seeds.
const SAMPLING_MARGIN_MM: f64 = 10.0;
/// Grid cells along the longest side of the sampled box, as for the fit statistics: a cell of a fraction of a
/// millimetre on a blade section, fine enough to seed Newton on the near face of a thin trailing edge.
const SAMPLING_CELLS: usize = 512;

/// Everything needed to measure points against one reference profile, built once per profile (samples its zero
/// set over its domain, enlarged by a margin that covers the expected deviations).
pub struct ProfileGauge {
    name: String,
    x_mm: f64,
    model: GaugeModel,
    /// The profile's nominal parameters, worked out the first time they are asked for.
    parameters: OnceLock<Result<SectionParameters, String>>,
}

/// What a profile's points are measured against.
enum GaugeModel {
    /// The profile's own 2-D IP in its (y, z) plane, and the sharp edges found on the master.
    Ip {
        model: IpModel<2>,
        samples: Box<ZeroSetSamples<2>>,
        edges: Vec<SharpEdge>,
        /// The taught nominal points in (y, z), in order round the section: where its outline is drawn from.
        nominals: Vec<Vector2<f64>>,
        /// The profile's faces between its sharp edges, where it has them: measured against instead of the IP.
        faces: Option<Box<FacedProfile>>,
    },
    /// The reference's solid, the same for every profile.
    Solid(Arc<SolidDistance>),
}

impl ProfileGauge {
    /// The gauges of every profile of a taught or loaded reference, in its order.
    pub fn all(reference: &Reference) -> Vec<Self> {
        let solid = Self::solid_of(reference);
        (0..reference.profiles.len())
            .map(|profile| Self::of_profile(reference, profile, solid.as_ref()))
            .collect()
    }

    /// The gauge of the reference's profile named `name` alone, if it has one.
    pub fn named(reference: &Reference, name: &str) -> Option<Self> {
        let profile = reference.profiles.iter().position(|p| p.name == name)?;
        Some(Self::of_profile(
            reference,
            profile,
            Self::solid_of(reference).as_ref(),
        ))
    }

    /// The distance to the reference's solid, sampled once for every profile; `None` for a stack of profiles.
    fn solid_of(reference: &Reference) -> Option<Arc<SolidDistance>> {
        match &reference.model.model {
            ReferenceModel::Supershape { solid, .. } => Some(Arc::new(SolidDistance::new(solid))),
            _ => None,
        }
    }

    fn of_profile(
        reference: &Reference,
        profile: usize,
        solid: Option<&Arc<SolidDistance>>,
    ) -> Self {
        match solid {
            Some(distance) => Self {
                name: reference.profiles[profile].name.clone(),
                x_mm: reference.profiles[profile].x_mm,
                model: GaugeModel::Solid(Arc::clone(distance)),
                parameters: OnceLock::new(),
            },
            None => Self::of_ip_profile(reference, profile),
        }
    }

    /// The gauge of `reference.profiles[profile]` of an IP stack. Panics when `profile` is out of range or the
    /// model is not a stack, neither of which a taught or loaded reference allows (a programming error).
    fn of_ip_profile(reference: &Reference, profile: usize) -> Self {
        let ReferenceModel::Stack { profiles } = &reference.model.model else {
            panic!(
                "the reference of part '{}' has no stack of profile models",
                reference.part
            );
        };
        let taught = &reference.profiles[profile];
        let fitted = &profiles[profile].fitted;
        let margin = Vector2::repeat(SAMPLING_MARGIN_MM);
        let bounds = Aabb {
            min: fitted.domain.min - margin,
            max: fitted.domain.max + margin,
        };
        Self {
            name: taught.name.clone(),
            x_mm: taught.x_mm,
            model: GaugeModel::Ip {
                samples: Box::new(ZeroSetSamples::new(&fitted.ip, &bounds, SAMPLING_CELLS)),
                model: fitted.ip.clone(),
                edges: taught.edges.clone(),
                nominals: taught
                    .nominals
                    .iter()
                    .map(|n| Vector2::new(n.point[1], n.point[2]))
                    .collect(),
                faces: taught.faces.as_ref().and_then(|faces| {
                    faces
                        .profile()
                        .map_err(|problem| {
                            tracing::warn!(
                                profile = %taught.name,
                                %problem,
                                "the profile's faces cannot be traced: it is measured against its polynomial"
                            )
                        })
                        .ok()
                        .map(Box::new)
                }),
            },
            parameters: OnceLock::new(),
        }
    }

    pub fn name(&self) -> &str {
        &self.name
    }

    /// The position of the profile's plane along the part's x axis, mm.
    pub fn x_mm(&self) -> f64 {
        self.x_mm
    }

    /// The profile's nominal parameters, from its model's outline along its taught nominal points (worked out once,
    /// on first asking); `Err` says why it has none.
    pub fn nominal_parameters(&self) -> Result<&SectionParameters, &str> {
        self.parameters
            .get_or_init(|| match &self.model {
                GaugeModel::Ip {
                    faces: Some(faces),
                    edges,
                    ..
                } => section_parameters(
                    // At the master's sharp edges the apex is the mean of its roll's contacts, as a scan's tip is
                    // (`section_parameters`): the faces' crossing, an extrapolation along a wedge of a few
                    // degrees, put the simulated propeller's nominal trailing edges 2-3 um off along the chord.
                    &sharpen(&section::faces_outline(faces), edges),
                    &[],
                    section::EDGE_DISTANCE_MM,
                )
                .map_err(|e| format!("its nominal: {e}")),
                GaugeModel::Ip {
                    model,
                    nominals,
                    edges,
                    ..
                } => section::nominal_parameters(model, nominals, edges),
                GaugeModel::Solid(_) => {
                    Err("the reference is a solid, not a stack of sections".into())
                }
            })
            .as_ref()
            .map_err(String::as_str)
    }

    /// A measurer for one scan: keeps the previous point's foot so consecutive points are fast.
    pub fn scan(&self) -> ScanGauge<'_> {
        ScanGauge {
            gauge: self,
            previous: None,
        }
    }
}

/// The measurer of one scan of a profile: the points must come in scan order for the seeding to help (any order
/// gives the same distances, only slower).
pub struct ScanGauge<'g> {
    gauge: &'g ProfileGauge,
    /// The last point that got a foot, in the profile's (y, z) plane, and its foot.
    previous: Option<(Vector2<f64>, Foot<2>)>,
}

/// The deviation of one point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointDeviation {
    /// Signed orthogonal distance to the profile's model, mm, positive outside the material.
    pub deviation_mm: f64,
    /// The point's x minus the profile plane's x, mm.
    pub off_plane_mm: f64,
    /// The nearest point of the profile's model, part frame, mm.
    pub foot: [f64; 3],
}

impl ScanGauge<'_> {
    /// Signed deviation (mm, positive outside) of a compensated part-frame point; its distance from the profile's
    /// plane is returned too (a point far off the plane means a wrong transform or a wrong profile).
    ///
    /// Against a profile's IP the point is measured in the profile's plane: its x is set aside, as the profile's
    /// model knows nothing of x. Against a solid it is measured in 3-D. A point with a non-finite coordinate has
    /// no foot.
    pub fn measure(&mut self, surface: &Point3<f64>) -> Result<PointDeviation, DistanceError> {
        let off_plane_mm = surface.x - self.gauge.x_mm;
        if !(off_plane_mm.is_finite() && surface.iter().all(|c| c.is_finite())) {
            return Err(DistanceError::NoFootPoint);
        }
        match &self.gauge.model {
            GaugeModel::Ip {
                faces: Some(faces), ..
            } => {
                let in_plane = Vector2::new(surface.y, surface.z);
                let foot = faces.foot(&in_plane).ok_or(DistanceError::NoFootPoint)?;
                Ok(PointDeviation {
                    deviation_mm: foot.distance,
                    off_plane_mm,
                    foot: [self.gauge.x_mm, foot.point.x, foot.point.y],
                })
            }
            GaugeModel::Ip {
                model,
                samples,
                edges,
                ..
            } => self.measure_in_plane(surface, model, samples, edges),
            GaugeModel::Solid(distance) => {
                let foot = distance.foot(surface).ok_or(DistanceError::NoFootPoint)?;
                Ok(PointDeviation {
                    deviation_mm: foot.distance_mm,
                    off_plane_mm,
                    foot: foot.point.coords.into(),
                })
            }
        }
    }

    fn measure_in_plane(
        &mut self,
        surface: &Point3<f64>,
        model: &IpModel<2>,
        samples: &ZeroSetSamples<2>,
        edges: &[SharpEdge],
    ) -> Result<PointDeviation, DistanceError> {
        let off_plane_mm = surface.x - self.gauge.x_mm;
        let in_plane = Vector2::new(surface.y, surface.z);
        let exact = ExactDistance::new(model, samples);
        let previous = self.previous.as_ref().map(|(point, foot)| (point, foot));
        // A point without a foot leaves the previous one in place: the next point still starts from a good foot.
        let foot = exact.foot(&in_plane, previous)?;
        self.previous = Some((in_plane, foot));
        // Near a sharp edge the model cannot stand for the part (its zero set crosses itself there and goes on):
        // there the distance is to the wedge of the edge's faces, and the nearest point reported is the edge.
        let at_edge = edges.iter().find_map(|edge| {
            edge.distance(&in_plane, &foot.point)
                .map(|distance| (distance, Vector2::from(edge.apex)))
        });
        let (deviation_mm, nearest) = at_edge.unwrap_or((foot.distance, foot.point));
        Ok(PointDeviation {
            deviation_mm,
            off_plane_mm,
            foot: [self.gauge.x_mm, nearest.x, nearest.y],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::test_profiles::{taught_ellipses, Ellipse};

    fn assert_send_sync<T: Send + Sync + 'static>() {}

    #[test]
    fn a_gauge_can_be_shared_between_threads() {
        assert_send_sync::<ProfileGauge>();
    }

    /// Points offset along the true normal of each ellipse by +0.3 mm (outside) and -0.3 mm (inside) read 0.3 mm
    /// with their sign, along a scan and one by one; the x offset is reported, not measured.
    #[test]
    fn offsets_along_the_true_normal_read_back_within_five_microns() {
        let reference = taught_ellipses();
        let mut worst: f64 = 0.0;
        let mut seeded = (0, std::time::Duration::ZERO);
        for (index, ellipse) in Ellipse::stack().iter().enumerate() {
            let gauge = &ProfileGauge::all(reference)[index];
            assert_eq!(gauge.name(), ellipse.name());
            for offset in [0.3, -0.3] {
                let mut scan = gauge.scan();
                // Between the taught points, so nothing is read off the fitted data.
                for k in 0..300 {
                    let t = std::f64::consts::TAU * (k as f64 + 0.37) / 300.0;
                    let mut p = ellipse.offset_point(t, offset);
                    p.x += 0.7;
                    let started = std::time::Instant::now();
                    let along = scan.measure(&p).unwrap();
                    seeded = (seeded.0 + 1, seeded.1 + started.elapsed());
                    let alone = gauge.scan().measure(&p).unwrap();
                    assert!(
                        (along.deviation_mm - alone.deviation_mm).abs() < 1e-6,
                        "seeded {along:?} and unseeded {alone:?} disagree"
                    );
                    assert!((along.off_plane_mm - 0.7).abs() < 1e-9, "{along:?}");
                    assert_eq!(along.foot[0], ellipse.x);
                    let error = along.deviation_mm - offset;
                    worst = worst.max(error.abs());
                    assert!(
                        error.abs() < 5e-3,
                        "{} at t = {t:.3}: read {:.6} mm for {offset} mm",
                        ellipse.name(),
                        along.deviation_mm
                    );
                    let foot_on_ellipse = ellipse.distance_in_plane(along.foot[1], along.foot[2]);
                    assert!(foot_on_ellipse.abs() < 5e-3, "foot {:?}", along.foot);
                }
            }
        }
        let per_point = seeded.1.as_secs_f64() / seeded.0 as f64;
        eprintln!(
            "worst error {worst:.2e} mm; {:.1} us per point along a scan",
            per_point * 1e6
        );
    }

    /// A master of NACA 2412 sections (chord 100 mm, sharp trailing edge) at x = 100 and 200 mm, scanned with 2 um
    /// of noise: its profiles are taught face by face, and measured and given nominal parameters by their faces.
    #[test]
    fn a_profile_with_a_sharp_edge_is_taught_and_measured_face_by_face() {
        use crate::analysis::reference::{teach, MasterProfile, ReferenceSettings};
        use crate::geometry::fit3l::tests::with_probe_noise;
        use crate::geometry::fit3l::FitMethod;
        use crate::geometry::normals::ordered_profile_normals;
        use nalgebra::Vector3;
        use zeroset_sim::naca::Naca4;

        let foil = Naca4::from_digits("2412", 100.0, true).unwrap();
        let section: Vec<Vector2<f64>> = foil.points(400).into_iter().map(Vector2::from).collect();
        let normals = ordered_profile_normals(&section);
        let master: Vec<MasterProfile> = [100.0, 200.0]
            .iter()
            .map(|&x| MasterProfile {
                name: format!("x{x}"),
                x_mm: x,
                points: with_probe_noise(&section, 0.002, x as u64)
                    .iter()
                    .map(|q| Point3::new(x, q.x, q.y))
                    .collect(),
                normals: normals
                    .iter()
                    .map(|n| Vector3::new(0.0, n.x, n.y))
                    .collect(),
            })
            .collect();
        let settings = ReferenceSettings::ImplicitPolynomial {
            degree: 6,
            method: FitMethod::Orthogonal,
            nominal_spacing_mm: 2.0,
        };
        let reference = teach("naca", &master, &settings).unwrap();
        assert!(reference.profiles.iter().all(|p| p.faces.is_some()));
        let gauge = &ProfileGauge::all(&reference)[0];
        // Points 0.1 mm out and in along the true normal, between the scanned ones (in: where the section is thick
        // enough that the face it came from is still the nearest), and 0.1 mm beyond the edge.
        let dense: Vec<Vector2<f64>> = foil.points(4_000).into_iter().map(Vector2::from).collect();
        let dense_normals = ordered_profile_normals(&dense);
        let mut scan = gauge.scan();
        for offset in [0.1, -0.1] {
            let along = dense.iter().zip(&dense_normals).skip(1);
            for (p, n) in along.filter(|(p, _)| offset > 0.0 || p.x < 98.0) {
                let q = p + n * offset;
                let read = scan.measure(&Point3::new(100.0, q.x, q.y)).unwrap();
                assert!(
                    (read.deviation_mm - offset).abs() < 0.005,
                    "{q:?}: {} for {offset}",
                    read.deviation_mm
                );
            }
        }
        let beyond = scan.measure(&Point3::new(100.0, 100.1, 0.0)).unwrap();
        assert!((beyond.deviation_mm - 0.1).abs() < 0.005, "{beyond:?}");
        // The nominal chord runs from the faces' sharp edge to the nose: within 5 um of the true section's.
        let true_chord = foil
            .points(200_000)
            .iter()
            .map(|p| (p[0] - 100.0).hypot(p[1]))
            .fold(0.0, f64::max);
        let nominal = gauge.nominal_parameters().unwrap();
        assert!(
            (nominal.chord_mm - true_chord).abs() < 0.005,
            "{} for {true_chord}",
            nominal.chord_mm
        );
    }

    #[test]
    fn a_point_with_no_coordinates_has_no_foot_and_the_scan_goes_on() {
        let reference = taught_ellipses();
        let ellipse = &Ellipse::stack()[2];
        let gauge = &ProfileGauge::all(reference)[2];
        let mut scan = gauge.scan();
        let before = scan.measure(&ellipse.offset_point(0.1, 0.2)).unwrap();
        assert_eq!(
            scan.measure(&Point3::new(f64::NAN, 0.0, 0.0)),
            Err(DistanceError::NoFootPoint)
        );
        let after = scan.measure(&ellipse.offset_point(0.12, 0.2)).unwrap();
        assert!(
            (before.deviation_mm - 0.2).abs() < 5e-3 && (after.deviation_mm - 0.2).abs() < 5e-3
        );
    }
}
