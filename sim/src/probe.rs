//! The probe: a ball of known radius. Like a real CMM it reports the ball's centre when it touches (surface
//! point + radius * outward normal) and the surface normal, the centre with seeded Gaussian noise.

use nalgebra::{Point2, Point3, Vector3};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

use crate::part::curve::{angle_of, turn, unit_at, CurvePoint};
use crate::part::{Part, Section, SurfacePoint};

/// Closest approach the path search resolves, mm.
const RESOLUTION: f64 = 1e-7;

/// The smallest step of the path search, mm: it slows down near the surface but must get past it.
const MIN_STEP: f64 = 0.005;

/// The ball touching the part.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    pub centre: Point3<f64>,
    pub surface: SurfacePoint,
}

/// What the machine reports for a contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    pub centre: Point3<f64>,
    pub normal: Vector3<f64>,
}

/// The probe ball and its noise.
pub struct Probe {
    noise: Normal<f64>,
    rng: StdRng,
}

impl Probe {
    pub fn new(sigma_mm: f64, seed: u64) -> Self {
        Probe {
            noise: Normal::new(0.0, sigma_mm.max(0.0)).expect("a non-negative sigma"),
            rng: StdRng::seed_from_u64(seed),
        }
    }

    /// The reported centre (with noise on each axis) and normal of a contact.
    pub fn measure(&mut self, contact: &Contact) -> Measured {
        let noise = Vector3::from_fn(|_, _| self.noise.sample(&mut self.rng));
        Measured {
            centre: contact.centre + noise,
            normal: contact.surface.normal,
        }
    }
}

/// The first position on the straight path `from` -> `to` where a ball of `radius` touches the part, or
/// `None` if it never does. A path that starts inside the material touches at once.
pub fn first_touch(
    part: &dyn Part,
    radius: f64,
    from: Point3<f64>,
    to: Point3<f64>,
) -> Option<Contact> {
    let length = (to - from).norm();
    let direction = if length > 0.0 {
        (to - from) / length
    } else {
        Vector3::zeros()
    };
    let clearance = |t: f64| part.nearest(&(from + direction * t)).signed_distance - radius;
    let mut t = 0.0;
    let mut gap = clearance(0.0);
    if gap <= 0.0 {
        return Some(contact_at(part, from));
    }
    while t < length {
        // The part's distance is measured in section planes, which can exceed the 3-D distance where the
        // surface leans along its axis; half of it is a safe step.
        let next = (t + (gap * 0.5).max(MIN_STEP)).min(length);
        let next_gap = clearance(next);
        if next_gap <= 0.0 {
            let (mut safe, mut hit) = (t, next);
            while hit - safe > RESOLUTION {
                let mid = (safe + hit) / 2.0;
                if clearance(mid) > 0.0 {
                    safe = mid;
                } else {
                    hit = mid;
                }
            }
            return Some(contact_at(part, from + direction * safe));
        }
        t = next;
        gap = next_gap;
    }
    None
}

fn contact_at(part: &dyn Part, centre: Point3<f64>) -> Contact {
    Contact {
        centre,
        surface: part.nearest(&centre),
    }
}

/// Where a plane scan stops: after the `count`th entry of the ball centre into the sphere about `centre`,
/// at the closest point to it (spec 11.3.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StopSphere {
    pub centre: Point3<f64>,
    pub radius: f64,
    pub count: u32,
}

/// Why a plane scan failed.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum PlaneScanError {
    #[error("the scan went twice around the section without meeting its stop sphere")]
    StopSphereNeverReached,
}

/// One node of the ball-centre path around a section: a point of the curve, or a point of an arc the ball
/// rolls about a sharp corner of the curve.
#[derive(Debug, Clone, Copy)]
enum PathNode {
    OnCurve(f64),
    Corner { at: Point2<f64>, angle: f64 },
}

/// Curve samples per trace around a section; corners sharper than [`CORNER_TURN`] get rolled arcs.
const TRACE_SAMPLES: usize = 4000;
const CORNER_TURN: f64 = 0.035;

/// How densely a plane scan reports points: every `max_distance` mm of centre travel at most, and, where
/// `max_angle` is given (rad), wherever the surface normal has turned by that much since the last point (I++'s
/// `StepW`, or `ScanUnknownDensity(Dis(..), Angle(..))` with `StepW` 0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spacing {
    pub max_distance: f64,
    pub max_angle: Option<f64>,
}

/// Scans a section with the ball: from the contact nearest `start` (a ball centre on the section's
/// plane), in the sense that heads towards `towards`, points as `spacing` asks until the stop sphere. Returns
/// the contacts, the first being the start.
pub fn plane_scan(
    section: &Section,
    radius: f64,
    start: Point3<f64>,
    towards: Point3<f64>,
    spacing: Spacing,
    stop: StopSphere,
) -> Result<Vec<Contact>, PlaneScanError> {
    let curve = &section.curve;
    let frame = &section.frame;
    let local = frame.local(&start);
    let first = curve.nearest(&Point2::new(local.x, local.y)).on_curve;
    let hint = frame.local(&towards) - local;
    let tangent = nalgebra::Vector2::new(-first.normal.y, first.normal.x);
    let forward = tangent.dot(&hint.xy()) >= 0.0;

    let nodes = trace_nodes(curve, first.s, forward);
    let place = |node: PathNode| -> (Point2<f64>, nalgebra::Vector2<f64>) {
        match node {
            PathNode::OnCurve(s) => {
                let at: CurvePoint = curve.at(s);
                (at.point, at.normal)
            }
            PathNode::Corner { at, angle } => (at, unit_at(angle)),
        }
    };
    let to_contact = |node: PathNode| {
        let (point, normal) = place(node);
        let normal = frame.world_dir(normal.x, normal.y, 0.0);
        let surface = frame.world(point.x, point.y, 0.0);
        Contact {
            centre: surface + normal * radius,
            surface: SurfacePoint {
                point: surface,
                normal,
                signed_distance: radius,
            },
        }
    };

    let mut contacts = vec![to_contact(nodes[0])];
    let distance_to_stop = |c: &Contact| (c.centre - stop.centre).norm();
    let mut inside = distance_to_stop(&contacts[0]) < stop.radius;
    let mut entries = 0;
    // Centre travel since the last point, and the normal's angle there.
    let mut travelled_since = 0.0;
    let mut last_angle = angle_of(&place(nodes[0]).1);
    let mut previous = contacts[0];
    for pair in nodes.windows(2) {
        let (a, b) = (to_contact(pair[0]), to_contact(pair[1]));
        let segment = (b.centre - a.centre).norm();
        if segment == 0.0 {
            continue;
        }
        // Along the segment the normal turns evenly from a's angle to b's (the nodes are a few hundredths of
        // a radian apart).
        let (angle_a, bend) = {
            let (from, to) = (angle_of(&place(pair[0]).1), angle_of(&place(pair[1]).1));
            (from, turn(from, to))
        };
        let mut at = 0.0;
        loop {
            let by_distance = at + spacing.max_distance - travelled_since;
            let by_angle = spacing
                .max_angle
                .filter(|_| bend != 0.0)
                .map(|max_angle| {
                    // Where the turn from the last point, growing the way the segment bends, reaches the
                    // limit (at once where it already has).
                    let limit = max_angle.copysign(bend);
                    ((limit - turn(last_angle, angle_a)) / bend * segment).max(at)
                })
                .unwrap_or(f64::INFINITY);
            let next = by_distance.min(by_angle);
            if next > segment {
                travelled_since += segment - at;
                break;
            }
            let node = between(pair[0], pair[1], next / segment);
            let contact = to_contact(node);
            let now_inside = distance_to_stop(&contact) < stop.radius;
            if now_inside && !inside {
                entries += 1;
            }
            inside = now_inside;
            if entries >= stop.count
                && inside
                && distance_to_stop(&contact) > distance_to_stop(&previous)
            {
                return Ok(contacts);
            }
            contacts.push(contact);
            previous = contact;
            travelled_since = 0.0;
            last_angle = angle_a + bend * next / segment;
            at = next;
        }
    }
    Err(PlaneScanError::StopSphereNeverReached)
}

/// The path nodes twice around the curve from parameter `s0`, forwards (counterclockwise) or backwards,
/// with arcs inserted where the normal turns sharply between samples (a sharp trailing edge).
fn trace_nodes(
    curve: &crate::part::curve::SampledCurve<crate::part::AnyCurve>,
    s0: f64,
    forward: bool,
) -> Vec<PathNode> {
    let sense = if forward { 1.0 } else { -1.0 };
    let grid_step = 1.0 / TRACE_SAMPLES as f64;
    // Start on the sample grid (offset by half a step, off any corner at s = 0) just past s0.
    let first_index = if forward {
        ((s0 / grid_step) - 0.5).floor() + 1.0
    } else {
        ((s0 / grid_step) - 0.5).ceil() - 1.0
    };
    let mut nodes = vec![PathNode::OnCurve(s0)];
    let mut last = curve.at(s0);
    for k in 0..2 * TRACE_SAMPLES {
        let s = (first_index + sense * k as f64 + 0.5) * grid_step;
        let at = curve.at(s);
        let (from, to) = (angle_of(&last.normal), angle_of(&at.normal));
        let bend = turn(from, to);
        if bend.abs() > CORNER_TURN {
            let corner = Point2::from((last.point.coords + at.point.coords) / 2.0);
            let pieces = (bend.abs() / CORNER_TURN).ceil() as usize;
            for i in 1..pieces {
                nodes.push(PathNode::Corner {
                    at: corner,
                    angle: from + bend * i as f64 / pieces as f64,
                });
            }
        }
        // The parameter runs on past 1 so that interpolation between nodes never wraps.
        nodes.push(PathNode::OnCurve(s));
        last = at;
    }
    nodes
}

/// The node a fraction of the way from `a` to `b`.
fn between(a: PathNode, b: PathNode, fraction: f64) -> PathNode {
    match (a, b) {
        (PathNode::OnCurve(sa), PathNode::OnCurve(sb)) => {
            PathNode::OnCurve(sa + (sb - sa) * fraction)
        }
        (PathNode::Corner { at, angle }, PathNode::Corner { angle: to, .. }) => PathNode::Corner {
            at,
            angle: angle + turn(angle, to) * fraction,
        },
        // Entering or leaving a corner's arc: the nearer end stands for the short step.
        _ if fraction < 0.5 => a,
        _ => b,
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::part::curve::{Circle, SampledCurve};
    use crate::part::{AnyCurve, Frame, Plane};

    /// A cylinder of radius 10 about z, from z = 0 to 20.
    struct Cylinder;

    impl Part for Cylinder {
        fn nearest(&self, p: &Point3<f64>) -> SurfacePoint {
            let radial = Vector3::new(p.x, p.y, 0.0).normalize();
            SurfacePoint {
                point: Point3::from(radial * 10.0) + Vector3::z() * p.z,
                normal: radial,
                signed_distance: p.xy().coords.norm() - 10.0,
            }
        }

        fn section(&self, plane: &Plane) -> Option<Section> {
            Some(Section {
                frame: Frame {
                    origin: Point3::new(0.0, 0.0, plane.point.z),
                    u: Vector3::x(),
                    v: Vector3::y(),
                    w: Vector3::z(),
                },
                curve: Arc::new(SampledCurve::new(Box::new(Circle(10.0)) as AnyCurve)),
            })
        }
    }

    #[test]
    fn a_ball_touches_where_its_centre_is_one_radius_off_the_surface() {
        let touch = first_touch(
            &Cylinder,
            1.0,
            Point3::new(20.0, 0.0, 5.0),
            Point3::new(0.0, 0.0, 5.0),
        )
        .unwrap();
        assert!((touch.centre.x - 11.0).abs() < 1e-6);
        assert!((touch.surface.point.x - 10.0).abs() < 1e-6);
        assert!(first_touch(
            &Cylinder,
            1.0,
            Point3::new(20.0, 0.0, 5.0),
            Point3::new(12.0, 5.0, 5.0)
        )
        .is_none());
    }

    #[test]
    fn noise_is_seeded_and_of_the_configured_size() {
        let contact = first_touch(
            &Cylinder,
            1.0,
            Point3::new(20.0, 0.0, 5.0),
            Point3::new(0.0, 0.0, 5.0),
        )
        .unwrap();
        let (mut a, mut b) = (Probe::new(0.002, 7), Probe::new(0.002, 7));
        let offsets: Vec<f64> = (0..2000)
            .map(|_| {
                let (ma, mb) = (a.measure(&contact), b.measure(&contact));
                assert_eq!(ma, mb);
                ma.centre.x - contact.centre.x
            })
            .collect();
        let rms = (offsets.iter().map(|d| d * d).sum::<f64>() / offsets.len() as f64).sqrt();
        assert!((rms - 0.002).abs() < 0.0002, "rms {rms}");
    }

    /// Where the plane scans round the cylinder start: on its section at z = 5, the ball's centre at (11, 0, 5).
    const AROUND_START: Point3<f64> = Point3::new(11.0, 0.0, 5.0);

    /// A plane scan round the cylinder (radius 10 mm) at z = 5 with a 1 mm ball, from [`AROUND_START`]
    /// counter-clockwise, until `stop`.
    fn around_cylinder(spacing: Spacing, stop: StopSphere) -> Result<Vec<Contact>, PlaneScanError> {
        let section = Cylinder
            .section(&Plane {
                point: Point3::new(0.0, 0.0, 5.0),
                normal: Vector3::z(),
            })
            .unwrap();
        plane_scan(
            &section,
            1.0,
            AROUND_START,
            Point3::new(11.0, 5.0, 5.0),
            spacing,
            stop,
        )
    }

    /// A stop sphere of `radius` round [`AROUND_START`], ending the scan on its first entry.
    fn stop_round_start(radius: f64) -> StopSphere {
        StopSphere {
            centre: AROUND_START,
            radius,
            count: 1,
        }
    }

    #[test]
    fn a_plane_scan_goes_once_around_and_stops_in_its_sphere() {
        let stop = stop_round_start(1.5);
        let every_mm = Spacing {
            max_distance: 1.0,
            max_angle: None,
        };
        let contacts = around_cylinder(every_mm, stop).unwrap();
        // Circumference of the centre path 2 pi 11 = 69.1 mm at 1 mm steps: the last is the closest to start.
        assert_eq!(contacts.len(), 70);
        assert!(contacts[1].centre.y > 0.0, "counterclockwise, towards +y");
        for c in &contacts {
            assert!(((c.centre - Point3::new(0.0, 0.0, 5.0)).norm() - 11.0).abs() < 1e-9);
        }
        let never = StopSphere {
            centre: Point3::new(50.0, 0.0, 5.0),
            ..stop
        };
        assert!(around_cylinder(every_mm, never).is_err());
    }

    #[test]
    fn a_plane_scan_spaced_by_turn_reports_a_point_wherever_the_normal_has_turned_that_much() {
        let stop = stop_round_start(0.7);
        // 3 deg on the centre path of radius 11 mm is 0.58 mm, under the 1 mm distance: the turn sets the
        // spacing, 120 steps round (121 points, the last back at the start, the closest to the stop sphere's
        // centre).
        let spacing = Spacing {
            max_distance: 1.0,
            max_angle: Some(3f64.to_radians()),
        };
        let contacts = around_cylinder(spacing, stop).unwrap();
        assert_eq!(contacts.len(), 121);
        for pair in contacts.windows(2) {
            let turned = pair[0]
                .surface
                .normal
                .angle(&pair[1].surface.normal)
                .to_degrees();
            assert!((turned - 3.0).abs() < 1e-6, "{turned} deg");
        }
        // A turn wider than the distance allows: the distance sets it, as with the angle left out.
        let wide = Spacing {
            max_distance: 1.0,
            max_angle: Some(30f64.to_radians()),
        };
        let by_distance = Spacing {
            max_distance: 1.0,
            max_angle: None,
        };
        let stop = StopSphere {
            radius: 1.5,
            ..stop
        };
        assert_eq!(
            around_cylinder(wide, stop).unwrap().len(),
            around_cylinder(by_distance, stop).unwrap().len()
        );
    }
}
