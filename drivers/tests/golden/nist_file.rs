//! Reading NIST's I++ DME 1.4 test files.
//!
//! The README names the format documents (prg_file_spec, res_file_spec) but they are not in the shared
//! folder; the format below is what every file there follows. Each message is written as it goes on the
//! wire, its own line end included, and is followed by a line holding `\\`. Two lines holding `:` end
//! the file. A message may therefore contain a bare LF or more than one line: the parser tests use that
//! to send broken lines (`05401 GoTo(X(0.1))2` ends in LF alone).

use std::path::{Path, PathBuf};

/// The NIST test files: `shared/` sits beside the repository checkout.
pub fn nist_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/reference/ippdme-nist-1.4");
    assert!(
        dir.join("README").is_file(),
        "NIST I++ DME test files not found at {}: the `shared` folder must sit beside the repository checkout",
        dir.display()
    );
    dir
}

/// The files in `dir` whose names end in `suffix`, sorted.
pub fn files_ending(dir: &Path, suffix: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("reading {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.to_string_lossy().ends_with(suffix))
        .collect();
    files.sort();
    files
}

/// The messages of a .prg or .res file, each with its line end.
pub fn messages(path: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let separator = b"\\\\\r\n";
    let mut messages = Vec::new();
    let mut start = 0;
    let mut pos = 0;
    while pos + separator.len() <= bytes.len() {
        let at_line_start = pos == 0 || bytes[pos - 1] == b'\n';
        if at_line_start && bytes[pos..].starts_with(separator) {
            messages.push(bytes[start..pos].to_vec());
            pos += separator.len();
            start = pos;
        } else {
            pos += 1;
        }
    }
    let end_marker: Vec<&[u8]> = bytes[start..]
        .split(|&b| b == b'\r' || b == b'\n')
        .filter(|line| !line.is_empty())
        .collect();
    assert_eq!(
        end_marker,
        [b":", b":"],
        "{} must end with two `:` lines after its last `\\\\`",
        path.display()
    );
    messages
}

/// The message's first line, without line end: how the tables and the logs name it.
pub fn first_line(message: &[u8]) -> String {
    let end = message
        .iter()
        .position(|&b| b == b'\r' || b == b'\n')
        .unwrap_or(message.len());
    String::from_utf8_lossy(&message[..end]).into_owned()
}

/// Which way a logged line went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    ClientToServer,
    ServerToClient,
}

/// The protocol lines of a client or server log: `<time> Sent: <line>` and `<time> Received: <line>` (the
/// server writes `received:`); the other entries (session start and end, checker notes) are skipped.
pub fn log_lines(path: &Path) -> Vec<(Direction, String)> {
    let text = std::fs::read(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    let file_name = path.file_name().expect("a log file").to_string_lossy();
    let client_log = file_name.contains("Client");
    String::from_utf8_lossy(&text)
        .split("\r\n")
        .filter_map(|entry| {
            let (_time, rest) = entry.split_once(' ')?;
            let (verb, line) = rest.split_once(": ")?;
            let sent = match verb {
                "Sent" => true,
                "Received" | "received" => false,
                _ => return None,
            };
            let direction = if sent == client_log {
                Direction::ClientToServer
            } else {
                Direction::ServerToClient
            };
            Some((direction, line.trim_end_matches('\r').to_owned()))
        })
        .collect()
}
