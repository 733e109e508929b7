//! The simulator's transcript (what the machine received and sent), read as the campaign goes: every motion
//! command the machine received while an error of severity 2 or more (an emergency stop's included) stood
//! uncleared, unless the daemon's log shows it sent before the error was read (the two crossed on the line),
//! every collision or missing surface that no injected fault explains, and which faults fired.

use std::collections::BTreeMap;
use std::io::{Read, Seek, SeekFrom};
use std::path::PathBuf;

use super::plan::Kind;
use super::wire_log::WireLog;

/// Commands that move the probe (the settings around them, ScanOnCurveDensity and the like, do not).
const MOTION: [&str; 14] = [
    "GoTo",
    "PtMeas",
    "Home",
    "ChangeTool",
    "AlignTool",
    "ScanOnCurve",
    "ScanInPlaneEndIsSphere",
    "ScanInPlaneEndIsPlane",
    "ScanInPlaneEndIsCyl",
    "ScanInCylEndIsSphere",
    "ScanInCylEndIsPlane",
    "ScanOnCircle",
    "ScanOnLine",
    "ScanUnknownHint",
];

const EMERGENCY_STOP: &str = "0500";
const PROTOCOL_ERROR: &str = "0008";
const COLLISION: &str = "2504";
const NO_TOUCH: &str = "1003";
const SURFACE_NOT_FOUND: &str = "1006";

/// The error that put the machine in its error state, until ClearAllErrors.
struct Standing {
    line: String,
    /// The error line as the machine sent it (None: the simulator dropped it, so the station never saw it).
    sent: Option<String>,
    code: String,
    at: f64,
    /// A StartSession came since (the simulator, as the spec says, clears errors then too).
    new_session: bool,
    /// A motion was already reported in this error's window (one violation per window, not per command).
    reported: bool,
}

/// Faults the machine fired (`# fired KIND`, logged as a motion command takes an armed fault) whose error has not
/// been met yet. Not their arming (`# fault KIND`): a scan may take one arming before a second is logged and send
/// its error after it, and the second then fires on the next scan.
#[derive(Default)]
struct Armed {
    collision: bool,
    no_touch: bool,
    surface_not_found: bool,
}

pub(crate) struct TranscriptWatch {
    path: PathBuf,
    wire: WireLog,
    offset: u64,
    /// The end of the last read when it fell inside a line.
    partial: String,
    standing: Option<Standing>,
    armed: Armed,
    fired: BTreeMap<Kind, usize>,
}

impl TranscriptWatch {
    /// The transcript at `path`; `wire` the daemon's log of the same machine's line.
    pub(crate) fn new(path: PathBuf, wire: WireLog) -> TranscriptWatch {
        TranscriptWatch {
            path,
            wire,
            offset: 0,
            partial: String::new(),
            standing: None,
            armed: Armed::default(),
            fired: BTreeMap::new(),
        }
    }

    pub(crate) fn path(&self) -> &std::path::Path {
        &self.path
    }

    /// How often each fault was seen to take effect on the line so far (drop-lines: lines dropped).
    pub(crate) fn fired(&self) -> &BTreeMap<Kind, usize> {
        &self.fired
    }

    /// Reads what the simulator wrote since the last call; returns the violations found in it.
    pub(crate) fn read_on(&mut self) -> Vec<String> {
        let mut text = std::mem::take(&mut self.partial);
        let read = std::fs::File::open(&self.path).and_then(|mut file| {
            file.seek(SeekFrom::Start(self.offset))?;
            let mut bytes = Vec::new();
            file.read_to_end(&mut bytes)?;
            Ok(bytes)
        });
        let bytes = match read {
            Ok(bytes) => bytes,
            Err(e) => return vec![format!("the transcript {}: {e}", self.path.display())],
        };
        self.offset += bytes.len() as u64;
        // The transcript escapes every byte outside printable ASCII: it is ASCII.
        text.push_str(&String::from_utf8_lossy(&bytes));
        let complete = text.rfind('\n').map_or(0, |end| end + 1);
        self.partial = text[complete..].to_string();
        // Read after the transcript: whatever the daemon sent that the machine received is in it.
        self.wire.read_on();
        text[..complete]
            .lines()
            .filter_map(|line| self.entry(line))
            .collect()
    }

    /// One transcript line: `SECONDS DIR TEXT`, DIR `<` received, `>` sent, `#` an event.
    fn entry(&mut self, line: &str) -> Option<String> {
        let (time, rest) = line.split_once(' ')?;
        let at: f64 = time.parse().ok()?;
        let (direction, text) = rest.split_at_checked(1)?;
        let text = text.trim_start();
        match direction {
            "#" => self.event(text, at),
            ">" => self.sent(text, at, line),
            "<" => self.received(text, at, line),
            _ => None,
        }
    }

    fn event(&mut self, text: &str, at: f64) -> Option<String> {
        if text.starts_with("fired Collision") {
            self.armed.collision = true;
        } else if text.starts_with("fired NoTouch") {
            self.armed.no_touch = true;
        } else if text.starts_with("fired SurfaceNotFound") {
            self.armed.surface_not_found = true;
        } else if text == "line alive again" {
            self.count(Kind::Disconnect);
        } else if let Some(dropped) = text.strip_prefix("dropped: ") {
            self.count(Kind::DropLines);
            // The machine is in error whether or not the station ever saw the line.
            if let Some((severity, _)) = error_of(dropped) {
                self.error_stands(severity, &format!("{text} (dropped)"), None, at);
            }
        }
        None
    }

    fn sent(&mut self, text: &str, at: f64, line: &str) -> Option<String> {
        if text.contains("#!garbage") {
            self.count(Kind::Garbage);
            return None;
        }
        let (severity, code) = error_of(text)?;
        self.error_stands(severity, line, Some(text), at);
        let unexplained = match code {
            EMERGENCY_STOP => {
                self.count(Kind::Estop);
                None
            }
            COLLISION => self.met(Kind::Collision, "a collision"),
            NO_TOUCH => self.met(Kind::NoTouch, "a probing or scan that lost its touch"),
            SURFACE_NOT_FOUND => self.met(Kind::SurfaceNotFound, "a scan that found no surface"),
            _ => None,
        };
        unexplained.map(|what| format!("{what} that no injected fault explains: {}", shorten(line)))
    }

    fn received(&mut self, text: &str, at: f64, line: &str) -> Option<String> {
        // `TAG NAME(ARGS)`
        let command = text.split_once(' ')?.1;
        let name = &command[..command.find('(')?];
        match name {
            "ClearAllErrors" => {
                self.standing = None;
                None
            }
            // A command refused with 0008 outside a session (the line was lost, the session with it) is the
            // session's state, not the machine's: a new session ends it (spec 6.3.1.1). Any other error
            // stands until ClearAllErrors, new session or not.
            "StartSession" => {
                match self.standing.as_mut() {
                    Some(standing) if standing.code == PROTOCOL_ERROR => self.standing = None,
                    Some(standing) => standing.new_session = true,
                    None => {}
                }
                None
            }
            _ if MOTION.contains(&name) => {
                let standing = self.standing.as_mut().filter(|s| !s.reported)?;
                let knew = match &standing.sent {
                    Some(error) => self.wire.knew(error, standing.at, &shorten(text))?,
                    None => "the error line was dropped".to_string(),
                };
                standing.reported = true;
                Some(format!(
                    "motion {:.0} ms after an error, before ClearAllErrors{} (the first of this error's window; {knew}): `{}` then `{}`",
                    (at - standing.at) * 1000.0,
                    if standing.new_session {
                        " (a new session came between)"
                    } else {
                        ""
                    },
                    standing.line,
                    shorten(line)
                ))
            }
            _ => None,
        }
    }

    fn error_stands(&mut self, severity: u32, line: &str, sent: Option<&str>, at: f64) {
        if severity >= 2 && self.standing.is_none() {
            self.standing = Some(Standing {
                line: shorten(line),
                sent: sent.map(shorten),
                code: error_of(line).map_or(String::new(), |(_, code)| code.to_string()),
                at,
                new_session: false,
                reported: false,
            });
        }
    }

    /// An armed fault met, or, with none armed, what the station did of its own (returned for the violation).
    fn met(&mut self, kind: Kind, what: &'static str) -> Option<&'static str> {
        let armed = match kind {
            Kind::Collision => &mut self.armed.collision,
            Kind::NoTouch => &mut self.armed.no_touch,
            _ => &mut self.armed.surface_not_found,
        };
        if std::mem::take(armed) {
            self.count(kind);
            None
        } else {
            Some(what)
        }
    }

    fn count(&mut self, kind: Kind) {
        *self.fired.entry(kind).or_default() += 1;
    }
}

/// A transcript line cut to its first 160 characters (a scan's command carries its whole path).
pub(super) fn shorten(line: &str) -> String {
    match line.char_indices().nth(160) {
        Some((end, _)) => format!("{}...", &line[..end]),
        None => line.to_string(),
    }
}

/// The severity and code of an error line `TAG ! Error(SEVERITY, CODE, ...)`.
fn error_of(text: &str) -> Option<(u32, &str)> {
    let (_, args) = text.split_once("! Error(")?;
    let mut fields = args.split(',').map(str::trim);
    let severity = fields.next()?.parse().ok()?;
    Some((severity, fields.next()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn watch(lines: &[&str]) -> (TranscriptWatch, Vec<String>, tempfile::TempDir) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.log");
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
        let wire = WireLog::new(dir.path().join("zeroset-daemon.jsonl"), "cmm1");
        let mut watch = TranscriptWatch::new(path, wire);
        let found = watch.read_on();
        (watch, found, dir)
    }

    #[test]
    fn a_motion_that_crossed_the_error_on_the_line_is_not_the_stations_but_the_next_one_is() {
        let dir = tempfile::tempdir().unwrap();
        let estop = "E0000 ! Error(3, 0500, \"EmergencyStop\", \"Emergency stop\")";
        // The daemon sent 00012 at 10:00:01.000000 and read the stop 0.3 ms later, then sent 00013 before
        // ClearAllErrors.
        let logged = [
            (
                "2026-12-02T10:00:01.000000Z",
                "> 00012 GoTo(X(1))".to_string(),
            ),
            ("2026-12-02T10:00:01.000300Z", format!("< {estop}")),
            (
                "2026-12-02T10:00:01.000400Z",
                "> 00013 GoTo(X(2))".to_string(),
            ),
        ];
        let log: Vec<String> = logged
            .iter()
            .map(|(at, message)| {
                serde_json::json!({"timestamp": at, "fields": {"message": message, "machine": "cmm1"}})
                    .to_string()
            })
            .collect();
        std::fs::write(
            dir.path().join("zeroset-daemon.jsonl"),
            log.join("\n") + "\n",
        )
        .unwrap();
        let path = dir.path().join("t.log");
        let transcript = [
            format!("1796205601.000100 > {estop}"),
            "1796205601.000150 < 00012 GoTo(X(1))".to_string(),
            "1796205601.000450 < 00013 GoTo(X(2))".to_string(),
        ];
        std::fs::write(&path, transcript.join("\n") + "\n").unwrap();
        let wire = WireLog::new(dir.path().join("zeroset-daemon.jsonl"), "cmm1");
        let found = TranscriptWatch::new(path, wire).read_on();
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(
            found[0].contains("00013 GoTo") && found[0].contains("had read the error"),
            "{}",
            found[0]
        );
    }

    #[test]
    fn a_motion_after_an_error_before_clear_all_errors_is_a_violation_and_after_it_is_not() {
        let (_, found, _dir) = watch(&[
            "100.000000 < 00010 ScanOnCurve(1,2,3)",
            "100.100000 > E0000 ! Error(3, 0500, \"EmergencyStop\", \"Emergency stop\")",
            "100.150000 < 00011 ScanOnCurveDensity(Dis(0.1))",
            "100.200000 < 00012 GoTo(X(1),Y(2),Z(3))",
            "100.300000 < 00013 ClearAllErrors()",
            "100.400000 < 00014 GoTo(X(1),Y(2),Z(3))",
            "100.500000 > 00014 ! Error(3, 2504, \"GoTo\", \"Collision\")",
            "100.600000 < 00015 GoTo(X(1),Y(2),Z(9))",
            "100.700000 < 00016 GoTo(X(1),Y(2),Z(10))",
        ]);
        // One per error's window: the first motion in it; and a collision with none armed is the station's own.
        assert_eq!(found.len(), 3, "{found:?}");
        assert!(
            found[0].starts_with("motion 100 ms after an error") && found[0].contains("00012 GoTo"),
            "{}",
            found[0]
        );
        assert!(
            found[1].starts_with("a collision that no injected fault"),
            "{}",
            found[1]
        );
        assert!(found[2].contains("00015 GoTo"), "{}", found[2]);
    }

    #[test]
    fn a_severity_one_error_needs_no_clear_and_a_dropped_error_line_still_counts() {
        let (_, found, _dir) = watch(&[
            "1.0 > 00005 ! Error(1, 0504, \"SetProp\", \"Argument out of range\")",
            "1.1 < 00006 GoTo(X(1))",
            "2.0 # dropped: 00007 ! Error(2, 0006, \"ScanOnCurve\", \"Transaction aborted\")",
            "2.1 < 00008 StartSession()",
            "2.2 < 00009 PtMeas(X(1))",
        ]);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(
            found[0].contains("a new session came between"),
            "{}",
            found[0]
        );
        assert!(found[0].contains("(dropped)"), "{}", found[0]);
    }

    #[test]
    fn a_lost_session_ends_with_a_new_one_but_an_emergency_stop_does_not() {
        let (_, found, _dir) = watch(&[
            "1.0 > 00018 ! Error(3, 0008, \"Get\", \"Protocol error\")",
            "1.1 < 00020 StartSession()",
            "1.2 < 00024 ChangeTool(\"Probe1\")",
            "2.0 > E0000 ! Error(3, 0500, \"EmergencyStop\", \"Emergency stop\")",
            "2.1 < 00030 StartSession()",
            "2.2 < 00031 GoTo(X(1))",
        ]);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(
            found[0].contains("0500") && found[0].contains("00031 GoTo"),
            "{}",
            found[0]
        );
    }

    #[test]
    fn a_fault_armed_again_after_a_scan_took_the_first_explains_the_next_scans_error() {
        // The campaign's SN-C0059: armed, a scan takes it, armed again before that scan's error is sent.
        let (_, found, _dir) = watch(&[
            "1.0 # fault SurfaceNotFound",
            "1.1 < 00098 ScanOnCurve(1,2,3)",
            "1.11 # fired SurfaceNotFound",
            "1.12 # fault SurfaceNotFound",
            "1.13 > 00098 ! Error(2, 1006, \"ScanOnCurve\", \"Surface not found\")",
            "1.2 < 00099 ClearAllErrors()",
            "1.3 < 00114 ScanOnCurve(1,2,3)",
            "1.31 # fired SurfaceNotFound",
            "1.32 > 00114 ! Error(2, 1006, \"ScanOnCurve\", \"Surface not found\")",
            "1.4 < 00115 ClearAllErrors()",
            "1.5 < 00116 ScanOnCurve(1,2,3)",
            "1.52 > 00116 ! Error(2, 1006, \"ScanOnCurve\", \"Surface not found\")",
        ]);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(
            found[0].starts_with("a scan that found no surface that no injected fault explains")
                && found[0].contains("00116"),
            "{}",
            found[0]
        );
    }

    #[test]
    fn injected_faults_are_counted_and_an_unexplained_collision_is_a_violation() {
        let (mut watch, found, dir) = watch(&[
            "1.0 # fault Collision",
            "1.05 # fired Collision",
            "1.1 > 00003 ! Error(3, 2504, \"GoTo\", \"Collision\")",
            "1.2 < 00004 ClearAllErrors()",
            "1.3 > \\xFF\\xFE\\x00\\x1B[0m#!garbage\\x07",
            "1.4 # line alive again",
        ]);
        assert!(found.is_empty(), "{found:?}");
        assert_eq!(watch.fired()[&Kind::Collision], 1);
        assert_eq!(watch.fired()[&Kind::Garbage], 1);
        assert_eq!(watch.fired()[&Kind::Disconnect], 1);
        // Read on from where it stopped: a second collision with none armed is the station's own.
        let mut file = std::fs::OpenOptions::new()
            .append(true)
            .open(dir.path().join("t.log"))
            .unwrap();
        std::io::Write::write_all(
            &mut file,
            b"2.0 > 00009 ! Error(3, 2504, \"GoTo\", \"Collision\")\n2.1 < 00010 GoTo(X(1)",
        )
        .unwrap();
        let found = watch.read_on();
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].starts_with("a collision that no injected fault explains"));
        assert_eq!(watch.fired()[&Kind::Collision], 1);
        // The half-written line is read once it is whole.
        std::io::Write::write_all(&mut file, b")\n").unwrap();
        let found = watch.read_on();
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].contains("00010 GoTo(X(1))"), "{}", found[0]);
    }
}
