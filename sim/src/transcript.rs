//! A machine's transcript: both directions of its line with timestamps, and the faults and connection
//! events between them, one entry per line: `SECONDS.MICROS DIR TEXT` with DIR `<` for received, `>` for
//! sent and `#` for events. Bytes outside printable ASCII are written `\xNN`, so garbage shows as garbage.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};

pub struct Transcript {
    out: BufWriter<File>,
}

impl Transcript {
    pub fn create(path: &Path) -> io::Result<Self> {
        Ok(Transcript {
            out: BufWriter::new(File::create(path)?),
        })
    }

    /// The default path: zeroset-sim-MACHINE-PID.log in the system's temp dir.
    pub fn default_path(machine: &str) -> PathBuf {
        std::env::temp_dir().join(format!("zeroset-sim-{machine}-{}.log", std::process::id()))
    }

    pub fn received(&mut self, bytes: &[u8]) {
        self.entry('<', bytes);
    }

    pub fn sent(&mut self, bytes: &[u8]) {
        self.entry('>', bytes);
    }

    pub fn event(&mut self, text: &str) {
        self.entry('#', text.as_bytes());
    }

    /// Writes and flushes at once: a transcript is for finding out what happened before a crash too. A
    /// transcript that cannot be written must not stop the machine, so errors are dropped.
    fn entry(&mut self, direction: char, bytes: &[u8]) {
        let since_epoch = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .unwrap_or_default();
        let mut line = format!(
            "{}.{:06} {direction} ",
            since_epoch.as_secs(),
            since_epoch.subsec_micros()
        );
        let bytes = bytes.strip_suffix(b"\r\n").unwrap_or(bytes);
        for &byte in bytes {
            if (b' '..=b'~').contains(&byte) {
                line.push(char::from(byte));
            } else {
                let _ = write!(line, "\\x{byte:02X}");
            }
        }
        line.push('\n');
        let _ = self
            .out
            .write_all(line.as_bytes())
            .and_then(|()| self.out.flush());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_both_directions_with_timestamps_and_escapes() {
        let path = std::env::temp_dir().join(format!("transcript-test-{}.log", std::process::id()));
        let mut transcript = Transcript::create(&path).unwrap();
        transcript.received(b"00001 StartSession()\r\n");
        transcript.sent(b"\xFF\x00garbage\r\n");
        transcript.event("fault garbage");
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(
            lines[0].ends_with(" < 00001 StartSession()"),
            "{}",
            lines[0]
        );
        assert!(lines[1].ends_with(" > \\xFF\\x00garbage"), "{}", lines[1]);
        assert!(lines[2].ends_with(" # fault garbage"));
        let stamp: f64 = lines[0].split(' ').next().unwrap().parse().unwrap();
        assert!(stamp > 1.6e9);
    }
}
