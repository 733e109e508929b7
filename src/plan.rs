//! The plan of a part: its instances x its profiles, and the machine scan of each. Teach scans the master's
//! profiles with an in-plane scan of unknown shape that starts from the drawing's nominal point; inspect scans
//! every instance's profiles along the curve taught on the master. Profiles, start points and taught nominals
//! are given in the part frame of the master; the plan moves them onto each instance and into machine
//! coordinates, so the scheduler and the machine workers only ever see machine coordinates.

use nalgebra::{Isometry3, Point3, Unit, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use zeroset_drivers::machine::{CurveScan, Density, InPlaneScan, InPlaneSpacing, Nominal, Xyz};

use crate::analysis::edges::SharpEdge;
use crate::analysis::reference::Reference;
use crate::analysis::rolls::rolling;
use crate::analysis::section::BestFitSettings;
use crate::analysis::NominalPoint;
use crate::config::{
    ConfigError, PartConfig, ProfileEntry, ReferenceSettings, ScanSettings, StationConfig,
    ToleranceEntry,
};

/// A teach scan stops in a sphere centred this far off its start along the start normal: where the ball
/// centre of the station's 1 mm probe sits when it touches the start, so the scan ends as it comes back
/// round; the sphere's radius absorbs other balls.
const STOP_CENTRE_OFF_START_MM: f64 = 1.0;

/// A teach scan's heading is given as a point this far from its start along the profile's direction (I++
/// only needs a point apart from the start).
const HEADING_POINT_MM: f64 = 10.0;

/// Nominals closer than this to a neighbour are one point of a sharp edge that the ball rolled around, mm.
const EDGE_POINT_MM: f64 = 0.05;

/// A curve scan starts at least this far from a sharp edge, mm, where the profile leaves room: the compensation
/// of a roll round the edge looks back along the centres before it (up to 24 of them), which a scan that has
/// just started does not have. Blade B's r500 scans, started on the face 0.7 mm before the trailing edge (its
/// last nominal there points most nearly up), read the edge's contacts up to 45 um apart and the chord 37 um long.
const START_CLEAR_OF_EDGE_MM: f64 = 15.0;

/// One scan of the plan: an instance's profile (indices into [`Plan::instance_names`] and
/// [`Plan::profile_names`]). Ordered by instance, then profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ProfileKey {
    pub instance: usize,
    pub profile: usize,
}

/// A part's scans, in machine coordinates.
#[derive(Debug, Clone)]
pub struct Plan {
    part: PartConfig,
    master: usize,
    /// Per instance: the master's part frame moved onto the instance, in machine coordinates.
    placements: Vec<Isometry3<f64>>,
}

impl Plan {
    /// The plan of a loaded part (whose master is among its instances, as [`PartConfig::load`] checks),
    /// placed on the table by `part_to_machine`.
    pub fn new(part: &PartConfig, part_to_machine: Isometry3<f64>) -> Plan {
        let instances = &part.instances;
        let master = instances
            .names
            .iter()
            .position(|name| *name == instances.master)
            .expect("PartConfig::load checks that the master is among the instances");
        let axis = Unit::new_normalize(Vector3::from(instances.axis_direction));
        let axis_point = Point3::from(instances.axis_point_mm);
        let placements = (0..instances.names.len())
            .map(|instance| {
                let steps = instance as f64 - master as f64;
                let turn = UnitQuaternion::from_axis_angle(
                    &axis,
                    (steps * instances.step_deg).to_radians(),
                );
                part_to_machine * Isometry3::rotation_wrt_point(turn, axis_point)
            })
            .collect();
        Plan {
            part: part.clone(),
            master,
            placements,
        }
    }

    /// The radius of the master's profile plane `profile` about the instances' axis, when that axis is the part's z
    /// axis through its origin (the profile planes x = r are then the blade's sections at radius r, y their
    /// tangential direction: what a propeller's pitch is measured in); `None` for any other axis.
    pub fn profile_radius(&self, profile: usize) -> Option<f64> {
        self.hub_sense().map(|_| self.profile_x(profile))
    }

    /// For a part turned about the z axis through the origin (a propeller's hub axis): +1 if its instances step
    /// counter-clockwise seen from +z (axis +z, step > 0, or both reversed), -1 if clockwise; `None` for other
    /// parts. A blade turned in its step's sense shifts its sections of x = r along +y times this.
    pub fn hub_sense(&self) -> Option<f64> {
        let instances = &self.part.instances;
        let axis = Vector3::from(instances.axis_direction).try_normalize(0.0)?;
        let through_origin = instances.axis_point_mm[0] == 0.0 && instances.axis_point_mm[1] == 0.0;
        let along_z = [1.0, -1.0]
            .into_iter()
            .find(|sign| (axis - Vector3::z() * *sign).norm() < 1e-12)?;
        through_origin.then_some(along_z * instances.step_deg.signum())
    }

    /// The turn from one instance to the next about the axis, deg.
    pub fn instance_step_deg(&self) -> f64 {
        self.part.instances.step_deg
    }

    /// The part's name.
    pub fn part(&self) -> &str {
        &self.part.name
    }

    pub fn instance_names(&self) -> &[String] {
        &self.part.instances.names
    }

    /// The master's index among [`Plan::instance_names`].
    pub fn master(&self) -> usize {
        self.master
    }

    pub fn profile_names(&self) -> Vec<&str> {
        self.part.profiles.iter().map(|p| p.name.as_str()).collect()
    }

    /// The x of the profile's plane in the part frame, mm.
    pub fn profile_x(&self, profile: usize) -> f64 {
        self.part.profiles[profile].x_mm
    }

    /// A scan as operators and logs name it: "instance B, profile r300 (x = 300 mm)".
    pub fn describe(&self, key: ProfileKey) -> String {
        let profile = &self.part.profiles[key.profile];
        format!(
            "instance {}, profile {} (x = {} mm)",
            self.part.instances.names[key.instance], profile.name, profile.x_mm
        )
    }

    /// The master's profiles, in increasing x.
    pub fn teach_scans(&self) -> Vec<ProfileKey> {
        (0..self.part.profiles.len())
            .map(|profile| ProfileKey {
                instance: self.master,
                profile,
            })
            .collect()
    }

    /// Every instance's profiles, instance by instance.
    pub fn inspect_scans(&self) -> Vec<ProfileKey> {
        (0..self.placements.len())
            .flat_map(|instance| {
                (0..self.part.profiles.len()).map(move |profile| ProfileKey { instance, profile })
            })
            .collect()
    }

    /// Rigid transform from the master's part frame to instance `instance` in machine coordinates
    /// (part_to_machine * the turn about the instances' axis).
    pub fn instance_to_machine(&self, instance: usize) -> Isometry3<f64> {
        self.placements[instance]
    }

    /// The normal of instance `instance`'s section planes (the part frame's x axis) in machine coordinates: the
    /// plane a profile's ball centres lie in, into which compensation slides the contacts.
    pub fn plane_normal(&self, instance: usize) -> Vector3<f64> {
        self.instance_to_machine(instance) * Vector3::x()
    }

    /// A point in machine coordinates where the profile's scan starts (for ordering scans to cut travel):
    /// the first point of its curve scan when the taught nominals are given, else the drawing's start.
    pub fn scan_start(&self, key: ProfileKey, nominals: Option<&[NominalPoint]>) -> Point3<f64> {
        let placement = self.instance_to_machine(key.instance);
        match nominals {
            Some(nominals) if !nominals.is_empty() => {
                placement * Point3::from(nominals[self.upmost(key, nominals)].point)
            }
            _ => placement * Point3::from(self.profile(key).start_mm),
        }
    }

    /// The in-plane scan of a profile of unknown shape (teach): it probes the drawing's start along
    /// -start_normal, follows the section x = x_mm heading along `direction`, and stops when it comes back
    /// to the start; everything moved onto `key.instance` in machine coordinates.
    pub fn in_plane_scan(&self, key: ProfileKey) -> InPlaneScan {
        let placement = self.instance_to_machine(key.instance);
        let profile = self.profile(key);
        let start = Point3::from(profile.start_mm);
        let normal = Vector3::from(profile.start_normal).normalize();
        let heading = Vector3::from(profile.direction).normalize();
        let point = |p: Point3<f64>| xyz(&(placement * p).coords);
        let direction = |v: Vector3<f64>| xyz(&(placement * v));
        InPlaneScan {
            start: point(start),
            start_normal: direction(normal),
            plane_normal: xyz(&self.plane_normal(key.instance)),
            direction: point(start + heading * HEADING_POINT_MM),
            // As densely round the master's nose as the inspections' curve scans (its nominal's tip is fitted to
            // the points there, and the chord's nominal with it), and its rolls round sharp edges in the steps of
            // the scan's `max_angle_deg` or finer (the taught rolls are thinned again for the nominals, see `rolls`).
            spacing: InPlaneSpacing::Spacing {
                max_distance: self.part.scan.step_mm,
                max_angle: self.part.scan.finest_angle_deg().to_radians(),
            },
            end: point(start + normal * STOP_CENTRE_OFF_START_MM),
            stop_diameter: self.part.scan.stop_diameter_mm,
            passes: 1,
            end_normal: direction(normal),
        }
    }

    /// The curve scan of any instance's profile along the nominals taught on the master (part frame),
    /// moved onto the instance in machine coordinates. Closed, and starting at the nominal whose normal
    /// points most nearly up (+z in machine coordinates), so the approach from the clearance height above
    /// it is a straight vertical move. `sharp_edges` are the profile's, found in the master's scan: their
    /// rolls keep the scan's `max_angle_deg`, the rest of the profile may be scanned finer round its round
    /// edges (see [`ScanSettings::round_edge_max_angle_deg`]), and near them the probing lines fan out from a
    /// pivot inside the master's edge (see `fan`), aimed at the centres of a ball of `ball_radius_mm`, the ball
    /// the motion is planned and swept for.
    pub fn curve_scan(
        &self,
        key: ProfileKey,
        nominals: &[NominalPoint],
        sharp_edges: &[SharpEdge],
        ball_radius_mm: f64,
    ) -> CurveScan {
        let placement = self.instance_to_machine(key.instance);
        let first = if nominals.is_empty() {
            0
        } else {
            self.upmost(key, nominals)
        };
        let in_order = || nominals[first..].iter().chain(&nominals[..first]);
        let apexes: Vec<[f64; 2]> = sharp_edges.iter().map(|edge| edge.apex).collect();
        let rolling: Vec<bool> = in_order()
            .map(|n| rolling(&Point3::from(n.point), &apexes))
            .collect();
        let taught: Vec<Nominal> = in_order()
            .map(|n| Nominal {
                point: xyz(&Vector3::from(n.point)),
                normal: xyz(&Vector3::from(n.normal).normalize()),
            })
            .collect();
        let scan = &self.part.scan;
        let angle = scan.max_angle_deg.to_radians();
        let round_edge_angle = scan.finest_angle_deg().to_radians();
        let max_angle = |i: usize, j: usize| {
            if rolling[i] || rolling[j] {
                angle
            } else {
                round_edge_angle
            }
        };
        let depth = fan::pivot_depth_mm(scan.max_deviation_mm, ball_radius_mm);
        let dense = at_density(&taught, scan.step_mm, max_angle);
        let nominals = fan::fanned(&dense, sharp_edges, depth, ball_radius_mm)
            .iter()
            .map(|n| Nominal {
                point: xyz(&(placement * Point3::new(n.point.x, n.point.y, n.point.z)).coords),
                normal: xyz(&(placement * Vector3::new(n.normal.x, n.normal.y, n.normal.z))),
            })
            .collect();
        CurveScan {
            closed: true,
            nominals,
            max_deviation: scan.max_deviation_mm,
            min_radius: scan.min_radius_mm,
            density: Density::AtNominals,
        }
    }

    /// The sharp edges of a curve scan's profile (see [`Plan::curve_scan`]) on `key`'s instance, with the depth of
    /// their fans' pivots.
    pub fn edge_fans(
        &self,
        key: ProfileKey,
        sharp_edges: &[SharpEdge],
        ball_radius_mm: f64,
    ) -> Vec<EdgeFan> {
        let placement = self.instance_to_machine(key.instance);
        let x = self.profile_x(key.profile);
        let depth_mm = fan::pivot_depth_mm(self.part.scan.max_deviation_mm, ball_radius_mm);
        sharp_edges
            .iter()
            .map(|edge| EdgeFan {
                apex: placement * Point3::new(x, edge.apex[0], edge.apex[1]),
                depth_mm,
            })
            .collect()
    }

    /// The index into `remaining` of the scan to do next from `from`: the one whose start is nearest.
    /// Travel at the clearance height is horizontal, so horizontal distances are compared; ties go to
    /// the first in [`ProfileKey`] order, so the choice does not depend on the order of `remaining`.
    pub fn nearest(
        &self,
        remaining: &[ProfileKey],
        from: Point3<f64>,
        starts: impl Fn(ProfileKey) -> Point3<f64>,
    ) -> Option<usize> {
        remaining
            .iter()
            .enumerate()
            .map(|(index, key)| {
                let start = starts(*key);
                ((start.x - from.x).hypot(start.y - from.y), *key, index)
            })
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            .map(|(_, _, index)| index)
    }

    pub fn scan_settings(&self) -> &ScanSettings {
        &self.part.scan
    }

    pub fn reference_settings(&self) -> &ReferenceSettings {
        &self.part.reference
    }

    pub fn tolerance(&self) -> &ToleranceEntry {
        &self.part.tolerance
    }

    /// What each inspected section's best fits may move, and how far.
    pub fn best_fit(&self) -> &BestFitSettings {
        &self.part.best_fit
    }

    fn profile(&self, key: ProfileKey) -> &ProfileEntry {
        &self.part.profiles[key.profile]
    }

    /// The index of the non-empty `nominals`' point whose normal, on the instance in machine coordinates,
    /// points most nearly up (the first of equals).
    ///
    /// Nominals on a sharp edge are passed over (where the taught ball rolled around an edge, one point carries a
    /// fan of normals, one of them straight up): a scan that starts on an edge approaches a tip, and sends its
    /// hardest points to the analysis in one burst (seen as a 3 ms p99 latency of deviation events). So are those
    /// within [`START_CLEAR_OF_EDGE_MM`] of one, where the profile has others.
    fn upmost(&self, key: ProfileKey, nominals: &[NominalPoint]) -> usize {
        let placement = self.instance_to_machine(key.instance);
        let upness = |n: &NominalPoint| (placement * Vector3::from(n.normal)).normalize().z;
        let count = nominals.len();
        let on_edge = |i: usize| {
            let here = Point3::from(nominals[i].point);
            [(i + count - 1) % count, (i + 1) % count]
                .iter()
                .any(|&j| j != i && (Point3::from(nominals[j].point) - here).norm() < EDGE_POINT_MM)
        };
        let edges: Vec<Point3<f64>> = (0..count)
            .filter(|&i| on_edge(i))
            .map(|i| Point3::from(nominals[i].point))
            .collect();
        let clear_of_edges = |i: usize| {
            let here = Point3::from(nominals[i].point);
            edges
                .iter()
                .all(|edge| (edge - here).norm() >= START_CLEAR_OF_EDGE_MM)
        };
        // Clear of every edge where the profile leaves room; else off the edges at least; else anywhere.
        let candidates = [
            (0..count)
                .filter(|&i| clear_of_edges(i))
                .collect::<Vec<_>>(),
            (0..count).filter(|&i| !on_edge(i)).collect(),
            (0..count).collect(),
        ]
        .into_iter()
        .find(|c| !c.is_empty())
        .expect("the nominals are not empty");
        candidates.into_iter().fold(usize::MAX, |best, i| {
            if best == usize::MAX || upness(&nominals[i]) > upness(&nominals[best]) {
                i
            } else {
                best
            }
        })
    }
}

/// Refuses a clearance height (`[safety] clearance_z_mm`) that does not clear the part: travel between profiles
/// happens at that machine z, and a teach enters each profile by a vertical move down from it, so with
/// clearance_z_mm = 10 the teach drove its first move into blade A.
///
/// The clearance must be above the highest point the part is known to reach, plus the part file's
/// `max_deviation_mm` (a real part may lie that far off its nominal), plus the largest ball the station accepts
/// (`max_ball_radius_mm`: the machine moves the ball's centre) and the move margin. What is known: the drawing's
/// start points of every instance's profiles, and, when `taught` is given (the part's reference, to inspect or
/// teach again), the taught nominal points, which run round the whole of every profile. Everything is placed in
/// machine coordinates by `plan`, which holds `station.part_to_machine`.
///
/// A start point lies on the surface, so a clearance below it is certainly wrong; above it the part may still
/// rise higher between the starts (the propeller's trailing edges near the hub stand at about 83 mm over starts
/// at 24 mm or less), which only the taught nominals show, and something that is never scanned (a hub) is
/// known to neither. The station's inspection move check (`station::clearance`) measures descents against the
/// taught model as well.
pub(crate) fn check_clearance(
    station: &StationConfig,
    plan: &Plan,
    taught: Option<&Reference>,
) -> Result<(), ConfigError> {
    let (top, what) = plan.highest_known_point(taught);
    let safety = &station.safety;
    let deviation = plan.part.scan.max_deviation_mm;
    let needed = top + deviation + safety.max_ball_radius_mm + safety.move_margin_mm;
    if safety.clearance_z_mm > needed {
        return Ok(());
    }
    Err(ConfigError::Invalid {
        path: station.file.clone(),
        problem: format!(
            "[safety] clearance_z_mm = {} mm does not clear part {} ({}): {what} lies at z = {top:.2} mm \
             (machine), and with the part's [scan] max_deviation_mm = {deviation} mm, [safety] \
             max_ball_radius_mm = {} mm and move_margin_mm = {} mm the probe needs clearance_z_mm above \
             {needed:.2} mm. Raise clearance_z_mm above the part's highest point, or check part_to_machine",
            safety.clearance_z_mm,
            plan.part(),
            station.part_path(plan.part()).display(),
            safety.max_ball_radius_mm,
            safety.move_margin_mm,
        ),
    })
}

impl Plan {
    /// The highest machine z among the points the part is known to reach (see [`check_clearance`]), and which
    /// point it is.
    fn highest_known_point(&self, taught: Option<&Reference>) -> (f64, String) {
        let mut highest = (f64::NEG_INFINITY, String::new());
        let mut consider = |point: [f64; 3], instance: usize, what: &dyn Fn() -> String| {
            let z = (self.placements[instance] * Point3::from(point)).z;
            if z > highest.0 {
                highest = (
                    z,
                    format!(
                        "instance {}'s {}",
                        self.part.instances.names[instance],
                        what()
                    ),
                );
            }
        };
        for instance in 0..self.placements.len() {
            for profile in &self.part.profiles {
                consider(profile.start_mm, instance, &|| {
                    format!("profile {} start point", profile.name)
                });
            }
            for profile in taught.iter().flat_map(|r| &r.profiles) {
                for (k, nominal) in profile.nominals.iter().enumerate() {
                    consider(nominal.point, instance, &|| {
                        format!("profile {} taught nominal {k}", profile.name)
                    });
                }
            }
        }
        highest
    }
}

/// The nominals of a closed curve scan at the scan's density: between two taught nominals farther apart than
/// `max_distance` mm, or whose normals turn by more than `max_angle(i, j)` rad (nominals i and j), evenly spaced
/// ones are put in (their normals interpolated). Why the station does it rather than the machine
/// (`ScanOnCurveDensity(Dis, Angle)`): with `AtNominals` the machine reports exactly one point per nominal, so a
/// scan that comes back a point short has lost one, however few (a data line of one point lost at a scan's end
/// leaves no hole its spacing shows).
fn at_density(
    nominals: &[Nominal],
    max_distance: f64,
    max_angle: impl Fn(usize, usize) -> f64,
) -> Vec<Nominal> {
    let n = nominals.len();
    if n < 3 {
        return nominals.to_vec();
    }
    let mut out = Vec::with_capacity(2 * n);
    for i in 0..n {
        let j = (i + 1) % n;
        let (a, b) = (nominals[i], nominals[j]);
        out.push(a);
        let (pa, pb) = (
            Vector3::new(a.point.x, a.point.y, a.point.z),
            Vector3::new(b.point.x, b.point.y, b.point.z),
        );
        let (na, nb) = (
            Vector3::new(a.normal.x, a.normal.y, a.normal.z),
            Vector3::new(b.normal.x, b.normal.y, b.normal.z),
        );
        let pieces = ((pb - pa).norm() / max_distance)
            .ceil()
            .max((na.angle(&nb) / max_angle(i, j)).ceil())
            .max(1.0) as usize;
        for k in 1..pieces {
            let f = k as f64 / pieces as f64;
            out.push(Nominal {
                point: xyz(&(pa + (pb - pa) * f)),
                normal: xyz(&(na * (1.0 - f) + nb * f).normalize()),
            });
        }
    }
    out
}

fn xyz(v: &Vector3<f64>) -> Xyz {
    Xyz::new(v.x, v.y, v.z)
}

pub(crate) mod fan;
pub use fan::EdgeFan;
#[cfg(test)]
mod tests;
