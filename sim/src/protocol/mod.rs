//! The server side of the I++ DME subset, with the spec's state rules, free of I/O: lines in, lines out,
//! and machine time (seconds) passed in by the caller, so that the whole protocol runs in unit tests
//! without a clock.
//!
//! Normal-queue commands are acknowledged (`&`) on arrival and run one after the other; fast-queue commands
//! (E-tags: AbortE, GetErrStatusE, OnMoveReportE) are answered at once. State rules: outside a session only
//! StartSession and EndSession (others: 0008); moves need Home first (0507, as NIST's server) and a
//! defined tool (1503; NoTool cannot measure, 2002); after an error of severity 2 or more, or an AbortE, or
//! an emergency stop, commands already waiting are aborted (0006) and every later one gets 0514 until
//! ClearAllErrors.

pub mod args;
pub mod errors;
pub mod motion;
pub mod properties;

use std::collections::VecDeque;
use std::sync::Arc;

use nalgebra::Point3;
use zeroset_drivers::wire::{
    Arg, Call, Command, Keyword, LineError, Name, Response, ResponseKind, Tag, WireError,
    WireString,
};

use crate::config::{MachineConfig, Params};
use crate::part::Part;
use crate::probe::Probe;
use args::{
    call, call_number, data_calls, report_items, value_call, Item, ALL_ITEMS, POSITION_ITEMS,
};
use errors::{code, error_line, needs_clear};
use motion::{Armed, CurveScanSettings, Plan, ScanSpacing, World};
use properties::Properties;

/// The DME version this server implements.
const DME_VERSION: &str = "1.4.3";

/// Move reports go out at most 10 times a second (spec 6.3.2.7).
const REPORT_PERIOD: f64 = 0.1;

/// The active tool.
#[derive(Debug, Clone, PartialEq)]
enum Tool {
    /// Before any ChangeTool: the server does not know what is loaded (spec 6.3.2.14 UnDefTool).
    Undefined,
    /// Can move but not measure.
    None,
    /// A configured probe: name and ball radius.
    Probe(String, f64),
}

/// An OnMoveReportE daemon.
#[derive(Debug, Clone)]
struct MoveDaemon {
    tag: Tag,
    every: Option<f64>,
    distance: Option<f64>,
    items: Vec<Item>,
    last_time: f64,
    last_position: Point3<f64>,
    next_tick: f64,
}

/// The command being executed.
struct Running {
    tag: Tag,
    name: String,
    start: f64,
    plan: Plan,
    sent: usize,
}

/// One simulated CMM controller.
pub struct Controller {
    tools: Vec<(String, f64)>,
    home: Point3<f64>,
    volume: (Point3<f64>, Point3<f64>),
    params: Params,
    part: Arc<dyn Part>,
    probe: Probe,

    session: bool,
    homed: bool,
    position: Point3<f64>,
    tool: Tool,
    props: Properties,
    pt_report: Vec<Item>,
    scan_report: Vec<Item>,
    curve_scan: CurveScanSettings,
    unknown_scan: ScanSpacing,
    /// An error of severity >= 2, an abort or an emergency stop happened: ClearAllErrors is needed.
    in_error: bool,
    armed: Armed,
    queue: VecDeque<Command>,
    running: Option<Running>,
    daemon: Option<MoveDaemon>,
    /// The machine time now, when the controller runs against a clock: a command's motion then starts once its
    /// plan is computed, as a real controller's does, instead of at its arrival (a long scan's planning would
    /// otherwise send the points due meanwhile in one burst).
    clock: Option<Arc<dyn Fn() -> f64 + Send + Sync>>,
}

impl Controller {
    pub fn new(config: &MachineConfig, part: Arc<dyn Part>) -> Self {
        let [hx, hy, hz] = config.home_mm;
        let (lo, hi) = (config.volume_min_mm, config.volume_max_mm);
        Controller {
            tools: config
                .tools
                .iter()
                .map(|t| (t.name.clone(), t.radius_mm))
                .collect(),
            home: Point3::new(hx, hy, hz),
            volume: (Point3::from(lo), Point3::from(hi)),
            params: config.params,
            part,
            probe: Probe::new(config.noise_sigma_mm, config.seed),
            session: false,
            homed: false,
            // Switched on where it was left: at home, but it does not know that until it homes.
            position: Point3::new(hx, hy, hz),
            tool: Tool::Undefined,
            props: Properties::new(&config.params),
            pt_report: POSITION_ITEMS.to_vec(),
            scan_report: vec![Item::X, Item::Y, Item::Z, Item::Q],
            curve_scan: CurveScanSettings::default(),
            unknown_scan: ScanSpacing::default(),
            in_error: false,
            armed: Armed::default(),
            queue: VecDeque::new(),
            running: None,
            daemon: None,
            clock: None,
        }
    }

    /// The controller on a clock of machine time (see the `clock` field).
    pub fn with_clock(mut self, clock: Arc<dyn Fn() -> f64 + Send + Sync>) -> Self {
        self.clock = Some(clock);
        self
    }

    /// Where the probe centre is at machine time `now`.
    pub fn position(&self, now: f64) -> Point3<f64> {
        match &self.running {
            Some(run) => run.plan.trajectory.position(now - run.start),
            None => self.position,
        }
    }

    /// A command line arrived at machine time `now`; returns the lines to send at once.
    pub fn receive(&mut self, command: Command, now: f64) -> Vec<Response> {
        let mut out = Vec::new();
        match command.tag() {
            Tag::Event(_) => self.fast(&command, now, &mut out),
            _ => {
                out.push(ack(command.tag()));
                self.queue.push_back(command);
                out.extend(self.poll(now));
            }
        }
        out
    }

    /// A line that could not be read: reported with E0000, since its tag cannot be trusted (spec 6.2.1
    /// asks this for illegal tags).
    pub fn bad_line(&mut self, error: &LineError) -> Vec<Response> {
        let code = match error.problem() {
            WireError::BadTag | WireError::TagOutOfRange { .. } => code::ILLEGAL_TAG,
            WireError::MissingSpaceAfterTag => code::NO_SPACE_AT_6,
            WireError::IllegalCharacter(_) => code::ILLEGAL_CHARACTER,
            _ => code::PROTOCOL_ERROR,
        };
        let line = error_line(Tag::Unsolicited, code, "Parser");
        if self.session {
            self.in_error = true;
        }
        vec![line]
    }

    /// Lines due by machine time `now`: a running command's timeline, the queue behind it, move reports.
    pub fn poll(&mut self, now: f64) -> Vec<Response> {
        let mut out = Vec::new();
        loop {
            if self.running.is_some() {
                self.daemon_reports(now, &mut out);
                let run = self.running.as_mut().expect("checked above");
                while let Some((t, line)) = run.plan.steps.get(run.sent) {
                    if run.start + t > now {
                        break;
                    }
                    let severe = needs_clear(line);
                    out.push(line.clone());
                    run.sent += 1;
                    if severe {
                        self.in_error = true;
                    }
                }
                let run = self.running.as_ref().expect("still running");
                if run.sent < run.plan.steps.len() {
                    break;
                }
                self.position = run.plan.trajectory.end();
                self.running = None;
                if self.in_error {
                    self.abort_queue(&mut out);
                }
            }
            let Some(command) = self.queue.pop_front() else {
                break;
            };
            self.start(command, now);
        }
        out
    }

    /// The machine time of the next line due, if any.
    pub fn next_deadline(&self) -> Option<f64> {
        let run = self.running.as_ref()?;
        let step = run.plan.steps.get(run.sent).map(|(t, _)| run.start + t);
        let tick = self.daemon.as_ref().map(|d| d.next_tick);
        match (step, tick) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// An emergency stop at machine time `now`: the unsolicited error, then the running and waiting
    /// commands aborted.
    pub fn emergency_stop(&mut self, now: f64) -> Vec<Response> {
        let mut out = vec![error_line(
            Tag::Unsolicited,
            code::EMERGENCY_STOP,
            "EmergencyStop",
        )];
        self.abort_all(now, &mut out);
        out
    }

    /// Arms a fault for the next motion command.
    /// The faults armed and not yet fired.
    pub fn armed(&self) -> Armed {
        self.armed
    }

    pub fn arm(&mut self, armed: Armed) {
        self.armed.collision |= armed.collision;
        self.armed.no_touch |= armed.no_touch;
        self.armed.surface_not_found |= armed.surface_not_found;
    }

    /// The client went away (or the line died): as on a closed TCP connection, the session ends and
    /// everything in progress is dropped; the machine stops where it is.
    pub fn disconnect(&mut self, now: f64) {
        self.position = self.position(now);
        self.running = None;
        self.queue.clear();
        self.daemon = None;
        self.session = false;
    }

    /// Stops the running command and aborts the waiting ones (AbortE, emergency stop).
    fn abort_all(&mut self, now: f64, out: &mut Vec<Response>) {
        if let Some(run) = self.running.take() {
            self.position = run.plan.trajectory.position(now - run.start);
            if run.name == "Home" {
                self.homed = false;
            }
            out.push(error_line(run.tag, code::TRANSACTION_ABORTED, &run.name));
            out.push(complete(run.tag));
        }
        self.abort_queue(out);
        self.in_error = true;
    }

    /// Commands acknowledged but not started when an error struck: "Transaction aborted" (spec 6.3.1.5).
    fn abort_queue(&mut self, out: &mut Vec<Response>) {
        for command in self.queue.drain(..) {
            out.push(error_line(
                command.tag(),
                code::TRANSACTION_ABORTED,
                command.name().as_str(),
            ));
            out.push(complete(command.tag()));
        }
    }

    /// Move reports due while the machine moves.
    fn daemon_reports(&mut self, now: f64, out: &mut Vec<Response>) {
        let Some(mut daemon) = self.daemon.take() else {
            return;
        };
        while daemon.next_tick <= now {
            let t = daemon.next_tick;
            let position = self.position(t);
            let moved = (position - daemon.last_position).norm();
            let due_by_distance = daemon.distance.is_some_and(|d| moved >= d);
            let due_by_time = daemon.every.is_some_and(|s| t - daemon.last_time >= s);
            if moved > 0.0 && (due_by_distance || due_by_time) {
                let reading = args::Reading {
                    centre: position,
                    normal: nalgebra::Vector3::zeros(),
                    radius: 0.0,
                };
                out.push(data_calls(daemon.tag, reading.calls(&daemon.items)));
                daemon.last_time = t;
                daemon.last_position = position;
            }
            daemon.next_tick = t + REPORT_PERIOD;
        }
        self.daemon = Some(daemon);
    }

    /// Fast-queue commands, answered at once.
    fn fast(&mut self, command: &Command, now: f64, out: &mut Vec<Response>) {
        let tag = command.tag();
        let name = command.name().as_str();
        out.push(ack(tag));
        if !self.session {
            out.push(error_line(tag, code::PROTOCOL_ERROR, name));
            out.push(complete(tag));
            return;
        }
        let no_args = command.args().is_empty();
        match name {
            "AbortE" if no_args => self.abort_all(now, out),
            "GetErrStatusE" if no_args => {
                let status = value_call("ErrStatus", &[f64::from(u8::from(self.in_error))]);
                out.push(data_calls(tag, vec![status]));
            }
            "AbortE" | "GetErrStatusE" => {
                out.push(error_line(tag, code::INCORRECT_ARGUMENTS, name));
            }
            "OnMoveReportE" if self.in_error => {
                out.push(error_line(tag, code::USE_CLEAR_ALL_ERRORS, name));
            }
            "OnMoveReportE" => {
                if let Err(code) = self.start_daemon(tag, command.args(), now) {
                    out.push(error_line(tag, code, name));
                }
            }
            _ => out.push(error_line(tag, code::UNSUPPORTED_COMMAND, name)),
        }
        out.push(complete(tag));
    }

    fn start_daemon(&mut self, tag: Tag, args: &[Arg], now: f64) -> Result<(), u16> {
        if self.daemon.is_some() {
            return Err(code::DAEMON_ALREADY_EXISTS);
        }
        let (mut every, mut distance) = (None, None);
        let mut items = Vec::new();
        for arg in args {
            match call(arg).map(|c| (c.name.as_str(), c)) {
                Some(("Time", c)) => every = Some(call_number(c)?.max(REPORT_PERIOD)),
                Some(("Dis", c)) => distance = Some(call_number(c)?),
                _ => items.extend(report_items(std::slice::from_ref(arg), &POSITION_ITEMS)?),
            }
        }
        if items.is_empty() || (every.is_none() && distance.is_none()) {
            return Err(code::INCORRECT_ARGUMENTS);
        }
        self.daemon = Some(MoveDaemon {
            tag,
            every,
            distance,
            items,
            last_time: now,
            last_position: self.position(now),
            next_tick: now + REPORT_PERIOD,
        });
        Ok(())
    }

    /// Starts a normal-queue command at `now`.
    fn start(&mut self, command: Command, now: f64) {
        let tag = command.tag();
        let name = command.name().as_str().to_owned();
        let plan = self.plan(&command);
        let now = self.clock.as_ref().map_or(now, |clock| clock().max(now));
        if let Some(daemon) = &mut self.daemon {
            daemon.next_tick = daemon.next_tick.max(now);
        }
        self.running = Some(Running {
            tag,
            name,
            start: now,
            plan,
            sent: 0,
        });
    }

    /// What a normal-queue command does, as a timeline.
    fn plan(&mut self, command: &Command) -> Plan {
        let tag = command.tag();
        let name = command.name().as_str();
        let args = command.args();
        let here = self.position;
        let done = |lines: Vec<Response>| immediate(tag, here, lines);
        let fail = |code: u16| immediate(tag, here, vec![error_line(tag, code, name)]);

        match name {
            "StartSession" | "EndSession" if !args.is_empty() => {
                return fail(code::INCORRECT_ARGUMENTS)
            }
            "StartSession" if self.session => return fail(code::PROTOCOL_ERROR),
            "StartSession" => {
                // Spec 6.3.1.1: default report formats, errors cleared, hints reset.
                self.session = true;
                self.in_error = false;
                self.pt_report = POSITION_ITEMS.to_vec();
                self.scan_report = vec![Item::X, Item::Y, Item::Z, Item::Q];
                self.curve_scan = CurveScanSettings::default();
                self.unknown_scan = ScanSpacing::default();
                return done(vec![]);
            }
            "EndSession" => {
                self.session = false;
                self.daemon = None;
                return done(vec![]);
            }
            _ if !self.session => return fail(code::PROTOCOL_ERROR),
            "ClearAllErrors" if args.is_empty() => {
                self.in_error = false;
                return done(vec![]);
            }
            _ if self.in_error => return fail(code::USE_CLEAR_ALL_ERRORS),
            _ => {}
        }

        match name {
            "GetDMEVersion" if args.is_empty() => {
                let version = WireString::new(DME_VERSION).expect("printable");
                done(vec![data_calls(
                    tag,
                    vec![named_call("DMEVersion", vec![version.into()])],
                )])
            }
            "GetMachineClass" if args.is_empty() => {
                let class = Keyword::new("CartCMM").expect("a keyword");
                done(vec![data_calls(
                    tag,
                    vec![named_call("GetMachineClass", vec![class.into()])],
                )])
            }
            "IsHomed" if args.is_empty() => {
                let homed = value_call("IsHomed", &[f64::from(u8::from(self.homed))]);
                done(vec![data_calls(tag, vec![homed])])
            }
            "Home" if args.is_empty() => {
                self.homed = true;
                let home = self.home;
                motion::home(tag, here, home, &mut self.world(0.0))
            }
            "ChangeTool" => match self.change_tool(args) {
                Ok(()) => done(vec![]),
                Err(code) => fail(code),
            },
            "GetProp" => match self.get_prop(tag, args) {
                Ok(line) => done(vec![line]),
                Err(code) => fail(code),
            },
            "SetProp" => match self.set_prop(tag, args) {
                Ok(lines) => done(lines),
                Err(code) => fail(code),
            },
            "Get" => match report_items(args, &POSITION_ITEMS) {
                Ok(items) => {
                    let reading = args::Reading {
                        centre: here,
                        normal: nalgebra::Vector3::zeros(),
                        radius: 0.0,
                    };
                    done(vec![data_calls(tag, reading.calls(&items))])
                }
                Err(code) => fail(code),
            },
            "OnPtMeasReport" | "OnScanReport" => match report_items(args, &ALL_ITEMS) {
                Ok(items) => {
                    if name == "OnPtMeasReport" {
                        self.pt_report = items;
                    } else {
                        self.scan_report = items;
                    }
                    done(vec![])
                }
                Err(code) => fail(code),
            },
            "ScanOnCurveHint" => match args::numbers(args).as_deref() {
                Ok([deviation, min_radius]) if *min_radius > 0.0 && *deviation >= 0.0 => {
                    self.curve_scan.expected_deviation = *deviation;
                    done(vec![])
                }
                Ok([_, _]) => fail(code::BAD_ARGUMENT),
                _ => fail(code::INCORRECT_ARGUMENTS),
            },
            "ScanOnCurveDensity" => match self.set_density(args) {
                Ok(()) => done(vec![]),
                Err(code) => fail(code),
            },
            "ScanUnknownDensity" => match self.set_unknown_density(args) {
                Ok(()) => done(vec![]),
                Err(code) => fail(code),
            },
            "StopDaemon" => match args {
                [Arg::EventTag(event)]
                    if self.daemon.as_ref().map(|d| d.tag) == Some(Tag::Event(*event)) =>
                {
                    self.daemon = None;
                    done(vec![])
                }
                [Arg::EventTag(_)] => fail(code::DAEMON_DOES_NOT_EXIST),
                _ => fail(code::INCORRECT_ARGUMENTS),
            },
            "GoTo" | "PtMeas" | "ScanInPlaneEndIsSphere" | "ScanOnCurve" => {
                self.plan_motion(command)
            }
            "GetDMEVersion" | "GetMachineClass" | "IsHomed" | "Home" | "ClearAllErrors" => {
                fail(code::INCORRECT_ARGUMENTS)
            }
            _ => fail(code::UNSUPPORTED_COMMAND),
        }
    }

    /// Commands that move and measure: homed and a tool first.
    fn plan_motion(&mut self, command: &Command) -> Plan {
        let tag = command.tag();
        let name = command.name().as_str();
        let here = self.position;
        let fail = |code: u16| immediate(tag, here, vec![error_line(tag, code, name)]);
        if !self.homed {
            return fail(code::ILLEGAL_COMMAND);
        }
        let radius = match (&self.tool, name) {
            (Tool::Undefined, _) => return fail(code::TOOL_NOT_DEFINED),
            (Tool::None, "GoTo") => 0.0,
            (Tool::None, _) => return fail(code::PROBE_DOES_NOT_ALLOW),
            (Tool::Probe(_, radius), _) => *radius,
        };
        let args = command.args();
        let mut world = self.world(radius);
        match name {
            "GoTo" => match args::target(args, here, false) {
                Ok((target, _)) => motion::goto(tag, here, target, &mut world),
                Err(code) => fail(code),
            },
            "PtMeas" => match args::target(args, here, true) {
                Ok((nominal, ijk)) => motion::ptmeas(tag, here, nominal, ijk, &mut world),
                Err(code) => fail(code),
            },
            "ScanInPlaneEndIsSphere" => motion::scan_in_plane(tag, here, args, &mut world),
            _ => motion::scan_on_curve(tag, here, args, &mut world),
        }
    }

    fn world(&mut self, radius: f64) -> World<'_> {
        World {
            part: self.part.as_ref(),
            radius,
            props: &self.props,
            probe: &mut self.probe,
            armed: &mut self.armed,
            volume: self.volume,
            pt_report: &self.pt_report,
            scan_report: &self.scan_report,
            curve_scan: self.curve_scan,
            unknown_scan: self.unknown_scan,
        }
    }

    fn change_tool(&mut self, args: &[Arg]) -> Result<(), u16> {
        let [Arg::String(name)] = args else {
            return Err(code::INCORRECT_ARGUMENTS);
        };
        let name = name.as_str();
        self.tool = if name == "NoTool" {
            Tool::None
        } else {
            let (name, radius) = self
                .tools
                .iter()
                .find(|(tool, _)| tool == name)
                .ok_or(code::TOOL_NOT_FOUND)?;
            Tool::Probe(name.clone(), *radius)
        };
        // Spec 6.3.6: a new tool starts with its default parameters.
        self.props = Properties::new(&self.params);
        Ok(())
    }

    /// GetProp(Tool.GoToPar.Speed(), Tool.AvrRadius(), Tool.Name(), ...).
    fn get_prop(&mut self, tag: Tag, args: &[Arg]) -> Result<Response, u16> {
        if args.is_empty() {
            return Err(code::INCORRECT_ARGUMENTS);
        }
        let calls = args
            .iter()
            .map(|arg| {
                let asked = call(arg)
                    .filter(|c| c.args.is_empty())
                    .ok_or(code::BAD_PROPERTY)?;
                let name = asked.name.as_str();
                match (name, &self.tool) {
                    ("Tool.Name", tool) => {
                        let text = match tool {
                            Tool::Undefined => "UnDefTool",
                            Tool::None => "NoTool",
                            Tool::Probe(name, _) => name,
                        };
                        let text = WireString::new(text).map_err(|_| code::BAD_PROPERTY)?;
                        Ok(named_call(name, vec![text.into()]))
                    }
                    ("Tool.AvrRadius", Tool::Probe(_, radius)) => Ok(value_call(name, &[*radius])),
                    ("Tool.AvrRadius", Tool::None) => Ok(value_call(name, &[0.0])),
                    ("Tool.AvrRadius", Tool::Undefined) => Err(code::TOOL_NOT_DEFINED),
                    _ => Ok(value_call(name, &[self.props.get(name)?])),
                }
            })
            .collect::<Result<Vec<Call>, u16>>()?;
        Ok(data_calls(tag, calls))
    }

    /// SetProp(Tool.GoToPar.Speed(50), ...): values out of range are clamped with warning 0504.
    fn set_prop(&mut self, tag: Tag, args: &[Arg]) -> Result<Vec<Response>, u16> {
        if args.is_empty() {
            return Err(code::INCORRECT_ARGUMENTS);
        }
        let mut clamped = false;
        for arg in args {
            let asked = call(arg).ok_or(code::BAD_PROPERTY)?;
            let value = call_number(asked)?;
            clamped |= self.props.set(asked.name.as_str(), value)?;
        }
        Ok(if clamped {
            vec![error_line(tag, code::ARGUMENT_OUT_OF_RANGE, "SetProp")]
        } else {
            vec![]
        })
    }

    /// ScanOnCurveDensity(Dis(..), Angle(..), AtNominals(..)), any of them.
    fn set_density(&mut self, args: &[Arg]) -> Result<(), u16> {
        let mut settings = self.curve_scan;
        for (name, value) in density_properties(args)? {
            match settings.spacing.set(name, value) {
                Some(set) => set?,
                None if name == "AtNominals" => settings.at_nominals = value != 0.0,
                None => return Err(code::BAD_ARGUMENT),
            }
        }
        self.curve_scan = settings;
        Ok(())
    }

    /// ScanUnknownDensity(Dis(..), Angle(..)), either or both (spec 11.3.1.1; the angle in degrees, as
    /// ScanOnCurveDensity's).
    fn set_unknown_density(&mut self, args: &[Arg]) -> Result<(), u16> {
        if args.is_empty() {
            return Err(code::INCORRECT_ARGUMENTS);
        }
        let mut spacing = self.unknown_scan;
        for (name, value) in density_properties(args)? {
            spacing
                .set(name, value)
                .unwrap_or(Err(code::BAD_ARGUMENT))?;
        }
        self.unknown_scan = spacing;
        Ok(())
    }
}

/// A density command's arguments as `(name, number)`: each must be a call of one number.
fn density_properties(args: &[Arg]) -> Result<Vec<(&str, f64)>, u16> {
    args.iter()
        .map(|arg| {
            let asked = call(arg).ok_or(code::INCORRECT_ARGUMENTS)?;
            Ok((asked.name.as_str(), call_number(asked)?))
        })
        .collect()
}

fn ack(tag: Tag) -> Response {
    Response::new(tag, ResponseKind::Ack).expect("a command tag")
}

fn complete(tag: Tag) -> Response {
    Response::new(tag, ResponseKind::Complete).expect("a command tag")
}

fn named_call(name: &str, args: Vec<Arg>) -> Call {
    Call::new(Name::new(name).expect("a valid name"), args)
}

/// A plan that sends `lines` and `%` at once, without moving.
fn immediate(tag: Tag, here: Point3<f64>, lines: Vec<Response>) -> Plan {
    let mut steps: Vec<(f64, Response)> = lines.into_iter().map(|l| (0.0, l)).collect();
    steps.push((0.0, complete(tag)));
    Plan {
        steps,
        trajectory: crate::kinematics::Trajectory::at(here),
    }
}

#[cfg(test)]
mod tests;
