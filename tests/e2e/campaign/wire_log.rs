//! The daemon's side of the line, from its log (the drivers log every line they send and read at debug level):
//! what the station knew when it sent a command. An error the machine sends can cross on the wire a command the
//! station had already sent; the machine refuses that command, and the station cannot have known. A motion is
//! the station's fault only when it sent it after reading the error.

use std::io::{Read, Seek, SeekFrom};
use std::path::PathBuf;
use std::time::UNIX_EPOCH;

/// How much earlier than the machine's own stamp the daemon's stamp of reading a line may be (the two read the
/// same clock at different moments round one write).
const CLOCK_SLACK_S: f64 = 0.001;

/// One line of the wire, in the order the daemon's link task logged it.
struct Entry {
    at: f64,
    sent: bool,
    /// The line as the simulator's transcript shows it, cut as [`super::transcript::shorten`] cuts.
    text: String,
}

pub(crate) struct WireLog {
    path: PathBuf,
    machine: String,
    offset: u64,
    partial: String,
    entries: Vec<Entry>,
}

impl WireLog {
    pub(crate) fn new(path: PathBuf, machine: &str) -> WireLog {
        WireLog {
            path,
            machine: machine.to_string(),
            offset: 0,
            partial: String::new(),
            entries: Vec::new(),
        }
    }

    /// Reads what the daemons logged since the last call (a missing log is one not written yet).
    pub(crate) fn read_on(&mut self) {
        let Ok(mut file) = std::fs::File::open(&self.path) else {
            return;
        };
        let mut bytes = Vec::new();
        if file.seek(SeekFrom::Start(self.offset)).is_err() || file.read_to_end(&mut bytes).is_err()
        {
            return;
        }
        self.offset += bytes.len() as u64;
        let mut text = std::mem::take(&mut self.partial);
        text.push_str(&String::from_utf8_lossy(&bytes));
        let complete = text.rfind('\n').map_or(0, |end| end + 1);
        self.partial = text[complete..].to_string();
        for line in text[..complete].lines() {
            if let Some(entry) = self.entry(line) {
                self.entries.push(entry);
            }
        }
    }

    fn entry(&self, line: &str) -> Option<Entry> {
        let value: serde_json::Value = serde_json::from_str(line).ok()?;
        let fields = &value["fields"];
        if fields["machine"].as_str()? != self.machine {
            return None;
        }
        let (sent, text) = match fields["message"].as_str()?.split_at_checked(2)? {
            ("> ", text) => (true, text),
            ("< ", text) => (false, text),
            _ => return None,
        };
        let at = humantime::parse_rfc3339_weak(value["timestamp"].as_str()?).ok()?;
        Some(Entry {
            at: at.duration_since(UNIX_EPOCH).ok()?.as_secs_f64(),
            sent,
            text: super::transcript::shorten(text),
        })
    }

    /// Why the daemon knew of `error` (a line the machine sent at `error_at`) when it sent `motion`, or None when
    /// it did not: it sent the motion before it read the error. Both texts as the transcript cuts them.
    pub(crate) fn knew(&self, error: &str, error_at: f64, motion: &str) -> Option<String> {
        let Some(send) = self
            .entries
            .iter()
            .rposition(|e| e.sent && e.text == motion)
        else {
            return Some("the daemon's log has no such command sent".into());
        };
        let read = self
            .entries
            .iter()
            .position(|e| !e.sent && e.text == error && e.at >= error_at - CLOCK_SLACK_S);
        match read {
            Some(read) if read > send => None,
            Some(_) => Some("the daemon had read the error before it sent the motion".into()),
            None => Some("the daemon's log shows the error never read".into()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log_line(at: &str, message: &str) -> String {
        serde_json::json!({
            "timestamp": at,
            "level": "DEBUG",
            "fields": { "message": message, "machine": "cmm1" },
            "target": "zeroset_drivers::client::actor",
        })
        .to_string()
    }

    #[test]
    fn a_motion_sent_before_the_error_was_read_crossed_it_and_one_sent_after_did_not() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("zeroset-daemon.jsonl");
        let estop = "E0000 ! Error(3, 0500, \"EmergencyStop\", \"Emergency stop\")";
        let lines = [
            // An earlier emergency stop, read and cleared: not this error's read.
            log_line("2026-12-02T10:00:00.000000Z", &format!("< {estop}")),
            log_line("2026-12-02T10:00:00.100000Z", "> 00020 ClearAllErrors()"),
            log_line("2026-12-02T10:00:01.000000Z", "> 00021 GoTo(X(1))"),
            log_line("2026-12-02T10:00:01.000300Z", &format!("< {estop}")),
            log_line("2026-12-02T10:00:01.000400Z", "> 00022 GoTo(X(2))"),
            // Another machine's lines are not this one's.
            log_line("2026-12-02T10:00:01.000500Z", "> 00023 GoTo(X(3))").replace("cmm1", "cmm2"),
        ];
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
        let mut log = WireLog::new(path, "cmm1");
        log.read_on();
        // The machine sent the stop at 10:00:01.000100, just after the first GoTo left the daemon.
        let error_at = 1_796_205_601.0 + 100e-6;
        assert_eq!(log.knew(estop, error_at, "00021 GoTo(X(1))"), None);
        assert!(log.knew(estop, error_at, "00022 GoTo(X(2))").is_some());
        assert!(log.knew(estop, error_at, "00023 GoTo(X(3))").is_some());
        // An error the daemon never read (it died first, or the line was lost) excuses nothing.
        assert!(log
            .knew(estop, error_at + 5.0, "00021 GoTo(X(1))")
            .is_some());
    }
}
