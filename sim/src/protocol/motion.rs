//! Commands that move the machine, planned ahead as a timeline: the probe centre's trajectory and the
//! response lines with the machine time (seconds from the command's start) at which each goes out. A scan's
//! points go out in blocks as they are measured; an error mid-move goes out where the machine stopped.

use nalgebra::{Point3, Vector3};
use zeroset_drivers::wire::{Arg, Response, ResponseKind, Tag};

use super::args::{call, call_number, data_calls, data_numbers, numbers, unit, Item, Reading};
use super::errors::{code, error_line};
use super::properties::Properties;
use crate::kinematics::{Limits, Trajectory};
use crate::part::{Part, Plane};
use crate::probe::{first_touch, plane_scan, Contact, Probe, Spacing, StopSphere};

/// Scan points per data line: the spec allows blocking them (11.1.2), and long lines keep the share of the
/// line that carries point data high.
pub const POINTS_PER_LINE: usize = 10;

/// Clearance below which the ball counts as touching, mm.
const TOUCHING: f64 = 1e-4;

/// A command's timeline.
#[derive(Debug)]
pub struct Plan {
    /// Responses with their machine time after the start, ascending; the last is `%`.
    pub steps: Vec<(f64, Response)>,
    pub trajectory: Trajectory,
}

/// Faults armed for the next motion command.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Armed {
    pub collision: bool,
    pub no_touch: bool,
    pub surface_not_found: bool,
}

/// ScanOnCurveDensity and ScanOnCurveHint.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CurveScanSettings {
    pub spacing: ScanSpacing,
    pub at_nominals: bool,
    pub expected_deviation: f64,
}

/// The `Dis` and `Angle` of ScanOnCurveDensity, and of ScanUnknownDensity (the spacing of an unknown-contour
/// scan sent with `StepW` 0): a point at least every `max_distance` mm and wherever the path turns by
/// `max_angle_deg`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanSpacing {
    pub max_distance: f64,
    pub max_angle_deg: f64,
}

impl Default for ScanSpacing {
    fn default() -> Self {
        ScanSpacing {
            max_distance: 1.0,
            max_angle_deg: 10.0,
        }
    }
}

impl ScanSpacing {
    /// Sets `Dis` or `Angle` from a density command's `name(value)`, which must be positive; `None` for another
    /// name.
    pub fn set(&mut self, name: &str, value: f64) -> Option<Result<(), u16>> {
        let field = match name {
            "Dis" => &mut self.max_distance,
            "Angle" => &mut self.max_angle_deg,
            _ => return None,
        };
        Some(if value > 0.0 {
            *field = value;
            Ok(())
        } else {
            Err(code::BAD_ARGUMENT)
        })
    }
}

/// What a motion needs of the machine.
pub struct World<'a> {
    pub part: &'a dyn Part,
    pub radius: f64,
    pub props: &'a Properties,
    pub probe: &'a mut Probe,
    pub armed: &'a mut Armed,
    pub volume: (Point3<f64>, Point3<f64>),
    pub pt_report: &'a [Item],
    pub scan_report: &'a [Item],
    pub curve_scan: CurveScanSettings,
    pub unknown_scan: ScanSpacing,
}

impl World<'_> {
    fn goto_limits(&self) -> Limits {
        Limits {
            speed: self.props.goto_speed.act,
            accel: self.props.goto_accel.act,
        }
    }

    fn ptmeas_limits(&self) -> Limits {
        Limits {
            speed: self.props.ptmeas_speed.act,
            accel: self.props.ptmeas_accel.act,
        }
    }

    fn scan_limits(&self) -> Limits {
        Limits {
            speed: self.props.scan_speed.act,
            accel: self.props.scan_accel.act,
        }
    }

    fn reading(&mut self, contact: &Contact) -> Reading {
        let measured = self.probe.measure(contact);
        Reading {
            centre: measured.centre,
            normal: measured.normal,
            radius: self.radius,
        }
    }

    fn inside_volume(&self, p: &Point3<f64>) -> bool {
        let (lo, hi) = self.volume;
        (0..3).all(|i| (lo[i]..=hi[i]).contains(&p[i]))
    }
}

/// Builds a plan step by step.
struct Timeline<'t> {
    tag: Tag,
    method: &'t str,
    trajectory: Trajectory,
    steps: Vec<(f64, Response)>,
}

impl<'t> Timeline<'t> {
    fn new(tag: Tag, method: &'t str, start: Point3<f64>) -> Self {
        Timeline {
            tag,
            method,
            trajectory: Trajectory::at(start),
            steps: Vec::new(),
        }
    }

    fn now(&self) -> f64 {
        self.trajectory.duration()
    }

    fn send_at(&mut self, t: f64, response: Response) {
        self.steps.push((t, response));
    }

    fn finish(mut self) -> Plan {
        let complete = Response::new(self.tag, ResponseKind::Complete).expect("a command tag");
        self.send_at(self.now(), complete);
        Plan {
            steps: self.steps,
            trajectory: self.trajectory,
        }
    }

    fn fail(mut self, code: u16) -> Plan {
        let line = error_line(self.tag, code, self.method);
        self.send_at(self.now(), line);
        self.finish()
    }

    /// A straight move that stops where the ball would cut the part (or halfway, with a collision fault
    /// armed); `Err(2504)` then.
    fn checked_move(
        &mut self,
        world: &mut World,
        to: Point3<f64>,
        limits: Limits,
    ) -> Result<(), u16> {
        let from = self.trajectory.end();
        if std::mem::take(&mut world.armed.collision) {
            self.trajectory.move_to(from + (to - from) / 2.0, limits);
            return Err(code::COLLISION);
        }
        match collision_on_path(world.part, world.radius, from, to) {
            Some(stop) => {
                self.trajectory.move_to(stop, limits);
                Err(code::COLLISION)
            }
            None => {
                self.trajectory.move_to(to, limits);
                Ok(())
            }
        }
    }

    /// Scan points as data lines of [`POINTS_PER_LINE`], each sent when its last point is measured.
    fn send_points(&mut self, world: &mut World, contacts: &[Contact], times: &[f64]) {
        for (block, block_times) in contacts
            .chunks(POINTS_PER_LINE)
            .zip(times.chunks(POINTS_PER_LINE))
        {
            let mut values = Vec::new();
            for contact in block {
                world
                    .reading(contact)
                    .numbers(world.scan_report, &mut values);
            }
            let line = data_numbers(self.tag, &values);
            self.send_at(*block_times.last().expect("non-empty block"), line);
        }
    }
}

/// Where the ball, moving from `from` to `to`, first cuts the part, if it does. A ball that starts in
/// contact (after a touch) may leave the surface; moving into it is a collision at once.
fn collision_on_path(
    part: &dyn Part,
    radius: f64,
    from: Point3<f64>,
    to: Point3<f64>,
) -> Option<Point3<f64>> {
    let length = (to - from).norm();
    if length == 0.0 {
        return None;
    }
    let direction = (to - from) / length;
    let start = part.nearest(&from);
    let mut clear_from = from;
    if start.signed_distance - radius < TOUCHING {
        if direction.dot(&start.normal) <= 0.0 {
            return Some(from);
        }
        // Leaving the surface: look for collisions from where the ball is clear of it.
        let mut t = 0.0;
        while part.nearest(&(from + direction * t)).signed_distance - radius < TOUCHING {
            t += TOUCHING.max(0.01);
            if t >= length {
                return None;
            }
        }
        clear_from = from + direction * t;
    }
    first_touch(part, radius, clear_from, to).map(|contact| contact.centre)
}

/// Home(): straight up to the home height, then across to home. The machine's own homing path is safe by
/// construction, so it is not checked against the part.
pub fn home(tag: Tag, start: Point3<f64>, home: Point3<f64>, world: &mut World) -> Plan {
    let mut timeline = Timeline::new(tag, "Home", start);
    let limits = world.goto_limits();
    if start.z < home.z {
        timeline
            .trajectory
            .move_to(Point3::new(start.x, start.y, home.z), limits);
    }
    timeline.trajectory.move_to(home, limits);
    timeline.finish()
}

/// GoTo(X(..), Y(..), Z(..)).
pub fn goto(tag: Tag, start: Point3<f64>, target: Point3<f64>, world: &mut World) -> Plan {
    let mut timeline = Timeline::new(tag, "GoTo", start);
    if !world.inside_volume(&target) {
        return timeline.fail(code::MACHINE_LIMIT);
    }
    let limits = world.goto_limits();
    match timeline.checked_move(world, target, limits) {
        Ok(()) => timeline.finish(),
        Err(code) => timeline.fail(code),
    }
}

/// PtMeas(X(..), Y(..), Z(..), IJK(..)), spec 6.3.2.13: an implicit GoTo to the approach point, the search
/// towards the end of search at PtMeasPar speed, the retract, then the report.
pub fn ptmeas(
    tag: Tag,
    start: Point3<f64>,
    nominal: Point3<f64>,
    ijk: Option<Vector3<f64>>,
    world: &mut World,
) -> Plan {
    let mut timeline = Timeline::new(tag, "PtMeas", start);
    // Without IJK the direction is from the nominal point to the current position.
    let direction = match unit(ijk.unwrap_or(start - nominal)) {
        Ok(direction) => direction,
        Err(code) => return timeline.fail(code),
    };
    let props = world.props;
    let approach = nominal + direction * (props.ptmeas_approach.act + world.radius);
    let end_of_search = nominal + direction * (world.radius - props.ptmeas_search.act);
    let limits = world.goto_limits();
    if let Err(code) = timeline.checked_move(world, approach, limits) {
        return timeline.fail(code);
    }
    let search = world.ptmeas_limits();
    let touch = if std::mem::take(&mut world.armed.no_touch) {
        None
    } else {
        first_touch(world.part, world.radius, approach, end_of_search)
    };
    let Some(contact) = touch else {
        timeline.trajectory.move_to(end_of_search, search);
        return timeline.fail(code::NO_TOUCH);
    };
    timeline.trajectory.move_to(contact.centre, search);
    let retract = props.ptmeas_retract.act;
    let back = if retract >= 0.0 {
        contact.centre + direction * retract
    } else {
        approach
    };
    timeline.trajectory.move_to(back, limits);
    let reading = world.reading(&contact);
    let line = data_calls(tag, reading.calls(world.pt_report));
    timeline.send_at(timeline.now(), line);
    timeline.finish()
}

/// How many of a scan's `count` points are measured before an armed `no-touch` fault loses the touch: the first
/// half (none of a scan of one point). The machine stops where it last touched, the points it measured sent, then
/// 1003.
fn touch_lost_after(count: usize) -> usize {
    count / 2
}

/// The probing at a scan's start: approach, search, and the contact, or the error to report.
fn probe_start(
    timeline: &mut Timeline,
    world: &mut World,
    nominal: Point3<f64>,
    direction: Vector3<f64>,
) -> Result<Contact, u16> {
    let props = world.props;
    let approach = nominal + direction * (props.ptmeas_approach.act + world.radius);
    let end_of_search = nominal + direction * (world.radius - props.ptmeas_search.act);
    let limits = world.goto_limits();
    timeline.checked_move(world, approach, limits)?;
    let search = world.ptmeas_limits();
    let missing = std::mem::take(&mut world.armed.surface_not_found);
    let touch = if missing {
        None
    } else {
        first_touch(world.part, world.radius, approach, end_of_search)
    };
    match touch {
        Some(contact) => {
            timeline.trajectory.move_to(contact.centre, search);
            Ok(contact)
        }
        None => {
            timeline.trajectory.move_to(end_of_search, search);
            Err(code::SURFACE_NOT_FOUND)
        }
    }
}

/// ScanInPlaneEndIsSphere(Sx,Sy,Sz, Si,Sj,Sk, Ni,Nj,Nk, Dx,Dy,Dz, StepW, Ex,Ey,Ez, Dia, n, Ei,Ej,Ek),
/// spec 11.3.2: a closed unknown contour in the plane through the probed start.
pub fn scan_in_plane(tag: Tag, start: Point3<f64>, args: &[Arg], world: &mut World) -> Plan {
    let mut timeline = Timeline::new(tag, "ScanInPlaneEndIsSphere", start);
    let v = match numbers(args) {
        Ok(v) if v.len() == 21 => v,
        _ => return timeline.fail(code::INCORRECT_ARGUMENTS),
    };
    let point = |i: usize| Point3::new(v[i], v[i + 1], v[i + 2]);
    let vector = |i: usize| unit(Vector3::new(v[i], v[i + 1], v[i + 2]));
    let (s, d, e) = (point(0), point(9), point(13));
    let (step, diameter, count) = (v[12], v[16], v[17]);
    let directions = vector(3).and_then(|si| Ok((si, vector(6)?, vector(18)?)));
    let (surface_dir, plane_normal, end_dir) = match directions {
        Ok(directions) => directions,
        Err(code) => return timeline.fail(code),
    };
    let sane = (d - s).norm() > 0.0
        && step >= 0.0
        && diameter > 0.0
        && count >= 1.0
        && count.fract() == 0.0;
    if !sane {
        return timeline.fail(code::BAD_ARGUMENT);
    }
    let contact = match probe_start(&mut timeline, world, s, surface_dir) {
        Ok(contact) => contact,
        Err(code) => return timeline.fail(code),
    };
    let plane = Plane {
        point: contact.centre,
        normal: plane_normal,
    };
    let Some(section) = world.part.section(&plane) else {
        return timeline.fail(code::SURFACE_NOT_FOUND);
    };
    let stop = StopSphere {
        centre: e,
        radius: diameter / 2.0,
        count: count as u32,
    };
    // Spec 11.3.1.1: StepW 0 asks for ScanUnknownDensity's spacing.
    let spacing = if step > 0.0 {
        Spacing {
            max_distance: step,
            max_angle: None,
        }
    } else {
        Spacing {
            max_distance: world.unknown_scan.max_distance,
            max_angle: Some(world.unknown_scan.max_angle_deg.to_radians()),
        }
    };
    let mut contacts = match plane_scan(&section, world.radius, contact.centre, d, spacing, stop) {
        Ok(contacts) => contacts,
        Err(_) => return timeline.fail(code::ERROR_PROCESSING_METHOD),
    };
    let touch_lost = std::mem::take(&mut world.armed.no_touch);
    if touch_lost {
        contacts.truncate(touch_lost_after(contacts.len()));
    }
    let centres: Vec<Point3<f64>> = contacts.iter().map(|c| c.centre).collect();
    let times = timeline.trajectory.follow(&centres, world.scan_limits());
    timeline.send_points(world, &contacts, &times);
    if touch_lost {
        return timeline.fail(code::NO_TOUCH);
    }
    let last = *centres.last().expect("a scan has its start point");
    let retract = world.props.ptmeas_retract.act.max(0.0);
    let limits = world.goto_limits();
    timeline
        .trajectory
        .move_to(last + end_dir * retract, limits);
    timeline.finish()
}

/// A nominal point of ScanOnCurve.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Nominal {
    point: Point3<f64>,
    normal: Vector3<f64>,
    on_surface: bool,
}

/// ScanOnCurve(Closed(b), Format(X(), Y(), Z(), IJK(), tag[, pi, pj, pk[, si, sj, sk]]), Data(...)),
/// spec 11.2.7: each nominal point (and points between them per ScanOnCurveDensity) is probed along its
/// nominal normal, within the expected deviation plus the search distance.
pub fn scan_on_curve(tag: Tag, start: Point3<f64>, args: &[Arg], world: &mut World) -> Plan {
    let mut timeline = Timeline::new(tag, "ScanOnCurve", start);
    let nominals = match parse_curve(args) {
        Ok((closed, nominals)) => densify(&nominals, closed, &world.curve_scan),
        Err(code) => return timeline.fail(code),
    };
    let window = world.curve_scan.expected_deviation + world.props.ptmeas_search.act;
    let first = nominals[0];
    let approach = first.point + first.normal * (world.radius + window);
    let limits = world.goto_limits();
    if let Err(code) = timeline.checked_move(world, approach, limits) {
        return timeline.fail(code);
    }
    if std::mem::take(&mut world.armed.surface_not_found) {
        return timeline.fail(code::SURFACE_NOT_FOUND);
    }
    // An armed no-touch fires once the first half of the points to measure are measured, the probe at the last
    // of them (at the approach when there are none to keep); it is taken only when it fires, so a scan that fails
    // before leaves it armed for the next.
    let keep = world.armed.no_touch.then(|| {
        let to_measure = nominals.iter().filter(|n| n.on_surface).count();
        touch_lost_after(to_measure)
    });
    let mut path = vec![approach];
    let mut measured = Vec::new();
    let mut failed = None;
    for nominal in &nominals {
        if keep == Some(measured.len()) {
            world.armed.no_touch = false;
            failed = Some(code::NO_TOUCH);
            break;
        }
        let centre_at = |offset: f64| nominal.point + nominal.normal * (world.radius + offset);
        if !nominal.on_surface {
            path.push(centre_at(window));
            continue;
        }
        let from = centre_at(window);
        let clear = world.part.nearest(&from).signed_distance - world.radius > 0.0;
        match first_touch(world.part, world.radius, from, centre_at(-window)).filter(|_| clear) {
            Some(contact) => {
                path.push(contact.centre);
                measured.push((path.len() - 1, contact));
            }
            None => {
                failed = Some(code::SURFACE_NOT_FOUND);
                break;
            }
        }
    }
    let times = timeline.trajectory.follow(&path, world.scan_limits());
    let contacts: Vec<Contact> = measured.iter().map(|(_, c)| *c).collect();
    let point_times: Vec<f64> = measured.iter().map(|(i, _)| times[*i]).collect();
    timeline.send_points(world, &contacts, &point_times);
    if let Some(code) = failed {
        return timeline.fail(code);
    }
    let last = nominals.last().expect("at least one nominal");
    let retract = world.props.ptmeas_retract.act.max(0.0);
    let end = timeline.trajectory.end() + last.normal * retract;
    timeline.trajectory.move_to(end, limits);
    timeline.finish()
}

/// Reads Closed, Format and Data into nominal points.
fn parse_curve(args: &[Arg]) -> Result<(bool, Vec<Nominal>), u16> {
    let [closed, format, data] = args else {
        return Err(code::INCORRECT_ARGUMENTS);
    };
    let named = |arg: &Arg, name: &str| call(arg).filter(|c| c.name.as_str() == name).cloned();
    let closed = named(closed, "Closed").ok_or(code::INCORRECT_ARGUMENTS)?;
    let closed = call_number(&closed)? != 0.0;
    let format = named(format, "Format").ok_or(code::INCORRECT_ARGUMENTS)?;
    let data = named(data, "Data").ok_or(code::INCORRECT_ARGUMENTS)?;
    // Offsets of each field in a record; the optional tool directions are read past and ignored, since
    // the simulated probe is a ball that needs no alignment.
    let mut offsets = std::collections::HashMap::new();
    let mut width = 0;
    for field in &format.args {
        let name = match field {
            Arg::Call(c) if c.args.is_empty() => c.name.as_str().to_owned(),
            Arg::Keyword(k) => k.as_str().to_owned(),
            _ => return Err(code::BAD_ARGUMENT),
        };
        let size = if name == "IJK" { 3 } else { 1 };
        if ![
            "X", "Y", "Z", "IJK", "tag", "pi", "pj", "pk", "si", "sj", "sk",
        ]
        .contains(&name.as_str())
        {
            return Err(code::BAD_ARGUMENT);
        }
        offsets.insert(name, width);
        width += size;
    }
    let field = |name: &str| offsets.get(name).copied().ok_or(code::INCORRECT_ARGUMENTS);
    let (x, y, z, ijk, flag) = (
        field("X")?,
        field("Y")?,
        field("Z")?,
        field("IJK")?,
        field("tag")?,
    );
    let values = numbers(&data.args)?;
    if values.is_empty() || values.len() % width != 0 {
        return Err(code::INCORRECT_ARGUMENTS);
    }
    let nominals = values
        .chunks(width)
        .map(|r| {
            Ok(Nominal {
                point: Point3::new(r[x], r[y], r[z]),
                normal: unit(Vector3::new(r[ijk], r[ijk + 1], r[ijk + 2]))?,
                on_surface: r[flag] > 0.0,
            })
        })
        .collect::<Result<Vec<_>, u16>>()?;
    Ok((closed, nominals))
}

/// Inserts points between nominals so that neighbours are at most `max_distance` apart and their normals
/// turn at most `max_angle_deg` (none with `at_nominals`); a closed curve also closes back to its start.
fn densify(nominals: &[Nominal], closed: bool, settings: &CurveScanSettings) -> Vec<Nominal> {
    let mut out = Vec::with_capacity(nominals.len());
    let pairs = nominals.len() - 1 + usize::from(closed && nominals.len() > 2);
    for i in 0..pairs {
        let (a, b) = (nominals[i], nominals[(i + 1) % nominals.len()]);
        out.push(a);
        if settings.at_nominals {
            continue;
        }
        let distance = (b.point - a.point).norm();
        let angle = a.normal.angle(&b.normal).to_degrees();
        let pieces = (distance / settings.spacing.max_distance)
            .ceil()
            .max((angle / settings.spacing.max_angle_deg).ceil())
            .max(1.0) as usize;
        for k in 1..pieces {
            let f = k as f64 / pieces as f64;
            out.push(Nominal {
                point: a.point + (b.point - a.point) * f,
                normal: (a.normal * (1.0 - f) + b.normal * f).normalize(),
                on_surface: a.on_surface && b.on_surface,
            });
        }
    }
    if !closed || nominals.len() <= 2 {
        out.push(*nominals.last().expect("at least one nominal"));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nominal(x: f64, i: f64) -> Nominal {
        Nominal {
            point: Point3::new(x, 0.0, 0.0),
            normal: Vector3::new(i, 0.0, 1.0).normalize(),
            on_surface: true,
        }
    }

    #[test]
    fn densify_respects_distance_and_angle() {
        let settings = CurveScanSettings {
            spacing: ScanSpacing {
                max_distance: 1.0,
                max_angle_deg: 10.0,
            },
            ..CurveScanSettings::default()
        };
        let open = densify(&[nominal(0.0, 0.0), nominal(3.0, 0.0)], false, &settings);
        assert_eq!(open.len(), 4);
        assert_eq!(open[3].point.x, 3.0);
        // 45 degrees of turn over 1 mm: 5 pieces.
        let turning = densify(&[nominal(0.0, 0.0), nominal(1.0, 1.0)], false, &settings);
        assert_eq!(turning.len(), 6);
        let at_nominals = CurveScanSettings {
            at_nominals: true,
            ..settings
        };
        let square = [nominal(0.0, 0.0), nominal(5.0, 0.0), nominal(10.0, 0.0)];
        assert_eq!(densify(&square, true, &at_nominals).len(), 3);
        // Closed: back from 10 to 0 in 1 mm pieces.
        assert_eq!(densify(&square, true, &settings).len(), 20);
    }

    #[test]
    fn reads_the_spec_example_format() {
        let command: zeroset_drivers::wire::Command = "00017 ScanOnCurve(Closed(0), \
             Format(X(), Y(), Z(), IJK(), tag, pi, pj, pk), \
             Data(10.0, 0.0, 0.0, 0, 0, 1, 1, 0, 0, 1, 22.0, 0.0, 0.0, 0, 0, 1, -1, 0, 0, 1))"
            .parse()
            .unwrap();
        let (closed, nominals) = parse_curve(command.args()).unwrap();
        assert!(!closed);
        assert_eq!(nominals.len(), 2);
        assert_eq!(nominals[1].point, Point3::new(22.0, 0.0, 0.0));
        assert!(nominals[0].on_surface && !nominals[1].on_surface);
    }
}
