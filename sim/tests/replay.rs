//! Golden replay: NIST's executable .prg files whose commands the simulator implements, run against the
//! real simulator binary over a pseudo-terminal, give replies of the same shape as NIST's server gave in
//! its logs (`ClientServerLogs/*_Server.log`): per command the same sequence of `&`, `#`, `%`, `!`, and
//! data of the same names and kinds. Values are not compared: NIST's files assume NIST's artifact and
//! machine, the simulator measures a propeller. Every difference that is expected is in [`KNOWN`] with
//! its reason; any other difference, or an entry of [`KNOWN`] that no longer differs, fails the test.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use common::nist::{self, file_reply, Transaction};
use common::shape::{render, ErrorDetail, Shape};
use common::{config_path, Client, Sim, REPLY};
use zeroset_drivers::wire::{Command, Response, ResponseKind};

/// Commands the simulator implements (sim/src/protocol): the station's subset, plus Get.
const IMPLEMENTED: [&str; 22] = [
    "StartSession",
    "EndSession",
    "GetDMEVersion",
    "GetMachineClass",
    "Home",
    "IsHomed",
    "ChangeTool",
    "GetProp",
    "SetProp",
    "Get",
    "GoTo",
    "PtMeas",
    "OnPtMeasReport",
    "OnScanReport",
    "ScanInPlaneEndIsSphere",
    "ScanOnCurve",
    "ScanOnCurveHint",
    "ScanOnCurveDensity",
    "AbortE",
    "ClearAllErrors",
    "GetErrStatusE",
    "OnMoveReportE",
];

/// StopDaemon too; kept apart so that the array above reads as the design's list.
const ALSO_IMPLEMENTED: [&str; 1] = ["StopDaemon"];

/// Files made of implemented commands that are not programs to execute: their .txt says they test a
/// parser with lines meant to fail.
const PARSER_TESTS: [&str; 1] = [
    // "The numbersErrorCmd.prg file contains commands that have number errors."
    "numbersErrorCmd.prg",
];

/// The files replayed: every .prg file of implemented commands but the parser tests. NIST's README lists
/// no file as executable ("NO FILES YET"), so the .txt files decide: each of these describes a session
/// to run (numbersCmdOK.txt: "The file should be executable in simulation").
const REPLAYED: [&str; 21] = [
    "AbortE.prg",
    "ChangeTool.prg",
    "ClearAllErrors.prg",
    "EndSession.prg",
    "Error.prg",
    "Get.prg",
    "GetDMEVersion.prg",
    "GetErrStatusE.prg",
    "GetMachineClass.prg",
    "GoTo.prg",
    "Home.prg",
    "Home_Test.prg",
    "IsHomed.prg",
    "OnMoveReportE.prg",
    "OnPtMeasReport.prg",
    "OnScanReport.prg",
    "PtMeas.prg",
    "ScanInPlaneEndIsSphere.prg",
    "StartSession.prg",
    "StopDaemon.prg",
    "numbersCmdOK.prg",
];

/// Commands replayed over all files, and of those the ones whose replies have NIST's shape, so that a
/// change in what is read or compared cannot go unnoticed.
const REPLAYED_COMMANDS: usize = 294;
const SAME_SHAPE: usize = 185;

/// The tag of the ClearAllErrors the replay sends after a known difference left the simulator in an
/// error state that NIST's server was not in; no NIST file uses it.
const RECOVERY: &str = "99999 ClearAllErrors()";

/// The simulator runs 10 000 times faster than real time: NIST's files move at 2 to 5 mm/s.
const TIME_SCALE: f64 = 10_000.0;

#[test]
fn replies_have_the_shape_of_nists_server_logs() {
    assert_eq!(selected_files(), REPLAYED);
    let (mut commands, mut same_shape) = (0, 0);
    let mut used = BTreeSet::new();
    let mut failures = Vec::new();
    for file in REPLAYED {
        let dir = nist::nist_dir();
        let program = nist::program(&dir.join(file));
        let log = dir
            .join("ClientServerLogs")
            .join(file.replace(".prg", "_Server.log"));
        let nist = nist::server_log(&log);
        let sent: Vec<String> = program.iter().map(ToString::to_string).collect();
        let logged: Vec<String> = nist.iter().map(|t| t.command.to_string()).collect();
        assert_eq!(sent, logged, "{} logs another session", log.display());
        let sim = replay(&program, &nist);
        commands += sim.len();
        for (ours, theirs) in sim.iter().zip(&nist) {
            let line = ours.command.to_string();
            let known = KNOWN
                .iter()
                .position(|k| k.file == file && k.command == line);
            let same = render(&ours.replies, ErrorDetail::Marker)
                == render(&theirs.replies, ErrorDetail::Marker);
            let ours_coded = render(&ours.replies, ErrorDetail::Code);
            match known {
                Some(index) => {
                    used.insert(index);
                    if same || KNOWN[index].sim != ours_coded {
                        failures.push(format!(
                            "{file}: `{line}`: the table expects `{}` ({}), the simulator gave `{ours_coded}`",
                            KNOWN[index].sim, KNOWN[index].why
                        ));
                    }
                }
                None if !same => failures.push(format!(
                    "{file}: `{line}`: NIST `{}`, simulator `{ours_coded}`",
                    render(&theirs.replies, ErrorDetail::Code)
                )),
                None => same_shape += 1,
            }
        }
    }
    for (index, known) in KNOWN.iter().enumerate() {
        if !used.contains(&index) {
            failures.push(format!(
                "{}: `{}` is in the table but was not replayed",
                known.file, known.command
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} differences:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert_eq!((commands, same_shape), (REPLAYED_COMMANDS, SAME_SHAPE));
    assert_eq!(commands - same_shape, KNOWN.len());
}

/// Runs `program` on a fresh simulator, one command at a time as NIST's client did (each after the
/// previous one's `%`), and returns the simulator's transactions.
fn replay(program: &[Command], nist: &[Transaction]) -> Vec<Transaction> {
    let sim = Sim::start(&config_path("propeller.toml"), TIME_SCALE);
    let mut client = Client::open(sim.path("cmm1"));
    let mut transactions: Vec<Transaction> = Vec::new();
    for (command, theirs) in program.iter().zip(nist) {
        transactions.push(Transaction {
            command: command.clone(),
            replies: Vec::new(),
        });
        for response in exchange(&mut client, command) {
            file_reply(&mut transactions, &response);
        }
        let ours = &transactions.last().expect("just pushed").replies;
        if has_error(ours) && !has_error(&theirs.replies) {
            let cleared: Vec<Shape> = exchange(&mut client, &RECOVERY.parse().unwrap())
                .iter()
                .map(Shape::of)
                .collect();
            assert_eq!(cleared, [Shape::Ack, Shape::Complete], "{RECOVERY}");
        }
    }
    transactions
}

fn has_error(replies: &[Shape]) -> bool {
    replies.iter().any(|shape| matches!(shape, Shape::Error(_)))
}

/// Sends `command` and reads every line up to its `%`.
fn exchange(client: &mut Client, command: &Command) -> Vec<Response> {
    client.send(&command.to_string());
    let mut lines = Vec::new();
    loop {
        let response = client
            .response(REPLY)
            .unwrap_or_else(|| panic!("no `%` for {command}; so far {lines:?}"));
        let done =
            response.tag() == command.tag() && matches!(response.kind(), ResponseKind::Complete);
        lines.push(response);
        if done {
            return lines;
        }
    }
}

/// The .prg files whose every command is implemented, less the parser tests.
fn selected_files() -> Vec<String> {
    let dir = nist::nist_dir();
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".prg") && !PARSER_TESTS.contains(&name.as_str()))
        .filter(|name| {
            command_names(&dir.join(name)).iter().all(|command| {
                IMPLEMENTED.contains(&command.as_str())
                    || ALSO_IMPLEMENTED.contains(&command.as_str())
            })
        })
        .collect();
    files.sort();
    files
}

/// The command names of a .prg file, read leniently (parser tests hold lines that do not parse): the
/// word after the tag.
fn command_names(path: &Path) -> BTreeSet<String> {
    let text = String::from_utf8_lossy(&std::fs::read(path).unwrap()).into_owned();
    text.lines()
        .filter_map(|line| line.get(6..))
        .map(|rest| {
            rest.chars()
                .take_while(char::is_ascii_alphanumeric)
                .collect::<String>()
        })
        .filter(|name| !name.is_empty())
        .collect()
}

/// A known difference: the simulator's replies to `command` (as the codec formats it) in `file`,
/// rendered with error codes, and why they differ from NIST's.
struct Known {
    file: &'static str,
    command: &'static str,
    sim: &'static str,
    why: &'static str,
}

const fn known(
    file: &'static str,
    command: &'static str,
    sim: &'static str,
    why: &'static str,
) -> Known {
    Known {
        file,
        command,
        sim,
        why,
    }
}

// Why the simulator answers otherwise than NIST's server. None of these is a departure from 1.4.3: they
// come from the machine and part on the table, or from NIST's server predating or bending the spec.

/// The simulated machine is a CartCMM with fixed ball probes (GetMachineClass answers CartCMM), NIST's a
/// CartCMMWithRotaryTable with an articulating head: the simulator has no rotary table (spec 6.3.3.13,
/// R(): "Implementation in CartCMMWithRotTbl") and no head angles Tool.A/B/C, so it answers 0510 Bad
/// property where they are asked for, and 0509 Bad argument to a GoTo that would turn them.
const NO_ROTARY_AXES: &str = "no rotary table and no head angles on a CartCMM with fixed probes";
/// The daemon this StopDaemon names was refused on the line before (see that line's entry), so it does
/// not exist: 0513, as spec 6.3.1.3 asks.
const NO_DAEMON: &str = "stops a daemon the simulator refused to start";
/// NIST's coordinates assume NIST's artifact near the origin; there the simulated table holds the
/// propeller's hub (a cylinder of radius 50 mm about z, z from -60 to 60 mm). NIST's targets and nominal
/// points lie in or on it, so the move or probe approach cuts the part: 2504 Collision, the machine
/// stopping at the contact, from where the later moves of the file stay in collision.
const HUB: &str = "NIST's coordinates lie inside the simulated propeller's hub";
/// Spec 6.3.2.11 leaves the data's format to the methods enumerated and 6.3.2.7 says the command defines
/// the sequence: the simulator answers in the order asked, NIST's server sorts into X, Y, Z, ...
const REQUEST_ORDER: &str = "values in the order asked, NIST's server sorts them";
/// Spec 6.3.2.8 writes the class as a keyword, `GetMachineClass(CartCMM)`; NIST's server quotes it.
const MACHINE_CLASS_KEYWORD: &str =
    "machine class as the spec's keyword, NIST's server sends a string";
/// propeller.toml's GoToPar.Accel range is [10, 3000] mm/s^2 (sim config Params): 1 is clamped to 10 with
/// warning 0504, as spec 6.3.6 asks for a value out of range; NIST's server allows 1.
const ACCEL_RANGE: &str =
    "acceleration below the simulated machine's minimum: clamped, warning 0504";
/// A move daemon with no Time() or Dis() has nothing to trigger a report (spec 6.3.2.7: "a report if
/// the time interval s has elapsed or the machine has moved more than d millimeters"): the simulator
/// refuses it with 0502 Incorrect arguments; NIST's server accepts it and never reports.
const NO_TRIGGER: &str = "move daemon without Time() or Dis(): refused, 0502";
/// A move daemon with no item to report (no X(), Y(), Z()) could only send data lines without items,
/// which are no I++ response: refused with 0502 Incorrect arguments; NIST's server accepts it.
const NOTHING_TO_REPORT: &str = "move daemon without items: refused, 0502";
/// propeller.toml's machine has the tools Probe1 and Probe3; NIST's has a BaseTool: 1502 Tool not found.
const UNKNOWN_TOOL: &str = "BaseTool is not a tool of the simulated machine";
/// NIST's file has the 17 arguments of I++ DME 1.4; 1.4.3 (spec 11.3.2) has 21 (the direction point
/// Dx, Dy, Dz and the count n were added) and the simulator implements 1.4.3: 0502 Incorrect arguments.
const SCAN_ARGUMENTS_OF_1_4: &str =
    "ScanInPlaneEndIsSphere with the 17 arguments of 1.4, not 1.4.3's 21";

#[rustfmt::skip]
const KNOWN: &[Known] = &[
    known("ChangeTool.prg", "00010 ChangeTool(\"BaseTool\")", "& !1502 %", UNKNOWN_TOOL),
    known("Get.prg", "00010 Get(R())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00050 Get(Tool.A())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00060 Get(Tool.B())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00070 Get(Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00100 Get(X(), R())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00120 Get(Y(), Z(), X())", "& #Y(n),Z(n),X(n) %", REQUEST_ORDER),
    known("Get.prg", "00130 Get(Z(), X(), Y())", "& #Z(n),X(n),Y(n) %", REQUEST_ORDER),
    known("Get.prg", "00140 Get(Tool.A(), Z(), X(), Y())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00150 Get(Tool.A(), Z(), Tool.B(), X(), Y())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00160 Get(Tool.A(), Z(), Tool.B(), X(), Tool.C(), Y())", "& !0510 %", NO_ROTARY_AXES),
    known("Get.prg", "00170 Get(R(), Tool.A(), Z(), Tool.B(), X(), Tool.C(), Y())", "& !0510 %", NO_ROTARY_AXES),
    known("GetMachineClass.prg", "00010 GetMachineClass()", "& #GetMachineClass(k) %", MACHINE_CLASS_KEYWORD),
    known("GoTo.prg", "00007 SetProp(Tool.GoToPar.Accel(1))", "& !0504 %", ACCEL_RANGE),
    known("GoTo.prg", "00010 GoTo(X(1.003E01), Y(-0.129), Z(+1.245E01))", "& !2504 %", HUB),
    known("GoTo.prg", "00020 GoTo(X(10), Y(11))", "& !2504 %", HUB),
    known("GoTo.prg", "00030 GoTo(X(10), Z(12))", "& !2504 %", HUB),
    known("GoTo.prg", "00040 GoTo(Y(23), Z(12))", "& !2504 %", HUB),
    known("GoTo.prg", "00050 GoTo(X(-10.5453452))", "& !2504 %", HUB),
    known("GoTo.prg", "00060 GoTo(Y(11))", "& !2504 %", HUB),
    known("GoTo.prg", "00070 GoTo(Z(12))", "& !2504 %", HUB),
    known("GoTo.prg", "00080 GoTo(Z(-4.003E-01), Y(-0.129), X(+1.245E01))", "& !2504 %", HUB),
    known("GoTo.prg", "00090 GoTo(Tool.A(45.0))", "& !0509 %", NO_ROTARY_AXES),
    known("GoTo.prg", "00100 GoTo(Tool.B(-45.0))", "& !0509 %", NO_ROTARY_AXES),
    known("GoTo.prg", "00110 GoTo(Tool.C(4.50E00))", "& !0509 %", NO_ROTARY_AXES),
    known("GoTo.prg", "00120 GoTo(Tool.A(45), Z(-4.003E-01), Y(-0.129), X(+1.245E01), Tool.B(4.0))", "& !0509 %", NO_ROTARY_AXES),
    known("Home_Test.prg", "00040 SetProp(Tool.GoToPar.Accel(1.0))", "& !0504 %", ACCEL_RANGE),
    known("Home_Test.prg", "00060 GoTo(X(10), Y(11), Z(12))", "& !2504 %", HUB),
    known("OnMoveReportE.prg", "E0010 OnMoveReportE(Time(15), Dis(3), R(), X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00015 StopDaemon(E0010)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0020 OnMoveReportE(R(), Time(15), Dis(3), Tool.A(), Tool.B(), X(), Y(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00025 StopDaemon(E0020)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0030 OnMoveReportE(Time(15), Dis(3), R(), X(), Y(), Z(), Tool.A(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00035 StopDaemon(E0030)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0040 OnMoveReportE(R(), Time(15), Tool.A(), Tool.B(), X(), Y(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00045 StopDaemon(E0040)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0050 OnMoveReportE(Tool.A(), Tool.B(), Time(15), Dis(3), X(), Y(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00055 StopDaemon(E0050)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0060 OnMoveReportE(Tool.C(), Time(15), Tool.B(), Dis(3), X(), Y(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00065 StopDaemon(E0060)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0070 OnMoveReportE(Tool.A(), Tool.B(), Time(15), Dis(3), X(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00075 StopDaemon(E0070)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0080 OnMoveReportE(Time(15), Tool.B(), Dis(3), X(), Y(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00085 StopDaemon(E0080)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0130 OnMoveReportE(Y(), Z(), X())", "& !0502 %", NO_TRIGGER),
    known("OnMoveReportE.prg", "00135 StopDaemon(E0130)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0170 OnMoveReportE(R())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00175 StopDaemon(E0170)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0180 OnMoveReportE(X())", "& !0502 %", NO_TRIGGER),
    known("OnMoveReportE.prg", "00185 StopDaemon(E0180)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0190 OnMoveReportE(Y())", "& !0502 %", NO_TRIGGER),
    known("OnMoveReportE.prg", "00195 StopDaemon(E0190)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0200 OnMoveReportE(Z())", "& !0502 %", NO_TRIGGER),
    known("OnMoveReportE.prg", "00205 StopDaemon(E0200)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0210 OnMoveReportE(Tool.A())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00215 StopDaemon(E0210)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0220 OnMoveReportE(Tool.B())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00225 StopDaemon(E0220)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0230 OnMoveReportE(Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnMoveReportE.prg", "00235 StopDaemon(E0230)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0240 OnMoveReportE(Dis(2.2))", "& !0502 %", NOTHING_TO_REPORT),
    known("OnMoveReportE.prg", "00245 StopDaemon(E0240)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0250 OnMoveReportE(Time(0.712))", "& !0502 %", NOTHING_TO_REPORT),
    known("OnMoveReportE.prg", "00255 StopDaemon(E0250)", "& !0513 %", NO_DAEMON),
    known("OnMoveReportE.prg", "E0260 OnMoveReportE()", "& !0502 %", NOTHING_TO_REPORT),
    known("OnPtMeasReport.prg", "00010 OnPtMeasReport(ER(), IJK(), R(), X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00020 OnPtMeasReport(X(), IJK(), Y(), Tool.A(), R(), Tool.B(), Z(), ER(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00030 OnPtMeasReport(ER(), IJK(), R(), X(), Y(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00040 OnPtMeasReport(X(), IJK(), Y(), Tool.A(), R(), Z(), ER(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00050 OnPtMeasReport(R(), X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00050 OnPtMeasReport(X(), Y(), Tool.A(), R(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00070 OnPtMeasReport(X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00080 OnPtMeasReport(X(), Y(), Tool.A(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00090 OnPtMeasReport(Y(), Tool.A(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00100 OnPtMeasReport(X(), Y(), Tool.A(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00110 OnPtMeasReport(X(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00120 OnPtMeasReport(Y(), Tool.A(), Tool.B(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00130 OnPtMeasReport(X(), Tool.B(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00200 OnPtMeasReport(Tool.A(), Y(), IJK())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00300 OnPtMeasReport(R())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00340 OnPtMeasReport(Tool.A())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00350 OnPtMeasReport(Tool.B())", "& !0510 %", NO_ROTARY_AXES),
    known("OnPtMeasReport.prg", "00360 OnPtMeasReport(Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00010 OnScanReport(R(), X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00020 OnScanReport(X(), Y(), Tool.A(), R(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00030 OnScanReport(X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00040 OnScanReport(X(), Y(), Tool.A(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00050 OnScanReport(Y(), Tool.A(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00060 OnScanReport(X(), Y(), Tool.A(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00070 OnScanReport(X(), Tool.B(), Z(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00080 OnScanReport(Y(), Tool.A(), Tool.B(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00090 OnScanReport(X(), Tool.B(), Z())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00220 OnScanReport(R())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00260 OnScanReport(Tool.A())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00270 OnScanReport(Tool.B())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00280 OnScanReport(Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00300 OnScanReport(Q(), R(), X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("OnScanReport.prg", "00330 OnScanReport(ER(), IJK(), Q(), R(), X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C())", "& !0510 %", NO_ROTARY_AXES),
    known("PtMeas.prg", "00080 PtMeas(X(1.33), Y(-2.6E01), Z(30.998), IJK(2, 2, 2))", "& !2504 %", HUB),
    known("PtMeas.prg", "00090 PtMeas(X(1.33), IJK(0, 0, 1.0), Y(-2.6E01), Z(30.998))", "& !2504 %", HUB),
    known("PtMeas.prg", "00120 OnPtMeasReport(Z(), X(), Y(), Tool.A(), Tool.B(), Tool.C(), ER())", "& !0510 %", NO_ROTARY_AXES),
    known("PtMeas.prg", "00130 PtMeas(Z(+1.9473294E-01), X(-2.6E01), Y(0.77998))", "& !2504 %", HUB),
    known("PtMeas.prg", "00150 PtMeas(IJK(2, 2, 2), Z(2.1))", "& !2504 %", HUB),
    known("PtMeas.prg", "00160 OnPtMeasReport(X(), Y(), Z(), Tool.A(), Tool.B(), Tool.C(), ER())", "& !0510 %", NO_ROTARY_AXES),
    known("PtMeas.prg", "00170 PtMeas(X(-2.6E01), Y(0.779))", "& !2504 %", HUB),
    known("PtMeas.prg", "00180 OnPtMeasReport(X(), Tool.A(), ER())", "& !0510 %", NO_ROTARY_AXES),
    known("PtMeas.prg", "00190 PtMeas(X(-2.6E01))", "& !2504 %", HUB),
    known("PtMeas.prg", "00210 PtMeas(Y(0.779))", "& !2504 %", HUB),
    known("ScanInPlaneEndIsSphere.prg", "00010 ScanInPlaneEndIsSphere(0, 0, 0, 0, 0, 1, 2, 0, 0, 0.5, 9, 0, 0, 1.4, 0, 0, 1)", "& !0502 %", SCAN_ARGUMENTS_OF_1_4),
];
