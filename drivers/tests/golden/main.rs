//! The codec against NIST's I++ DME 1.4 test files (`shared/reference/ippdme-nist-1.4`): every message in
//! every .prg and .res file, and every protocol line of the client and server logs.

mod meant_to_fail;
mod nist_file;

use std::path::Path;

use bytes::BytesMut;
use futures_util::StreamExt;
use tokio_util::codec::{Decoder, FramedRead};
use zeroset_drivers::codec::{ClientCodec, ServerCodec};
use zeroset_drivers::wire::{Command, LineError, Response};

use meant_to_fail::{Layer, MeantToFail};
use nist_file::Direction;

/// Messages in the .prg and .res files, counted so that a test that reads nothing fails.
const NIST_MESSAGES: usize = 5226;
/// Of those, lines the codec must reject: the `rejected` rows of the tables.
const NIST_REJECTED: usize = 121;
/// Of those, lines NIST's parsers reject for reasons of the command layer: the `command` rows.
const NIST_COMMAND_LEVEL: usize = 283;
/// Protocol lines in the client and server logs.
const LOG_LINES: usize = 13_252;

/// What decoding one message gave: each line's text as the codec formats it back, or its error.
type Decoded = Vec<Result<String, LineError>>;

/// Decodes `bytes` as a whole stream.
fn decode<D, T>(mut codec: D, bytes: &[u8]) -> Decoded
where
    D: Decoder<Item = Result<T, LineError>, Error = std::io::Error>,
    T: ToString,
{
    let mut buf = BytesMut::from(bytes);
    let mut items = Vec::new();
    while let Some(item) = codec
        .decode_eof(&mut buf)
        .expect("decoding from memory does no I/O")
    {
        items.push(item.map(|value| value.to_string()));
    }
    items
}

/// Decodes a client-to-server message (a command) or a server-to-client one (a response).
fn decode_as(direction: Direction, bytes: &[u8]) -> Decoded {
    match direction {
        Direction::ClientToServer => decode(ServerCodec::default(), bytes),
        Direction::ServerToClient => decode(ClientCodec::default(), bytes),
    }
}

/// Checks one message against what is expected of it; `Err` says what went wrong.
/// `expected` is `None` for a line meant to be valid.
fn check(direction: Direction, bytes: &[u8], expected: Option<Layer>) -> Result<Layer, String> {
    let decoded = decode_as(direction, bytes);
    let valid = matches!(decoded.as_slice(), [Ok(_)]);
    match expected {
        None | Some(Layer::Command) if valid => {
            let Ok(text) = &decoded[0] else {
                unreachable!()
            };
            // The canonical form must read back as the same value.
            let again = decode_as(direction, format!("{text}\r\n").as_bytes());
            match again.as_slice() {
                [Ok(same)] if same == text => Ok(Layer::Command),
                other => Err(format!(
                    "formatted as {text:?}, which reads back as {other:?}"
                )),
            }
        }
        None | Some(Layer::Command) => {
            Err(format!("meant to be well-formed, decoded as {decoded:?}"))
        }
        Some(Layer::Wire(problem)) => {
            let found = decoded
                .iter()
                .filter_map(|item| item.as_ref().err())
                .find(|error| format!("{:?}", error.problem()).starts_with(problem));
            match found {
                Some(_) => Ok(Layer::Wire(problem)),
                None => Err(format!(
                    "meant to be rejected with {problem}, decoded as {decoded:?}"
                )),
            }
        }
    }
}

fn direction_of(path: &Path) -> Direction {
    if path.extension().is_some_and(|ext| ext == "prg") {
        Direction::ClientToServer
    } else {
        Direction::ServerToClient
    }
}

#[test]
fn every_nist_file_parses_or_fails_as_nist_meant() {
    let dir = nist_file::nist_dir();
    let files: Vec<_> = nist_file::files_ending(&dir, ".prg")
        .into_iter()
        .chain(nist_file::files_ending(&dir, ".res"))
        .collect();
    let (mut messages, mut rejected, mut command_level) = (0, 0, 0);
    let mut failures = Vec::new();
    for path in &files {
        let name = path
            .file_name()
            .expect("a file name")
            .to_string_lossy()
            .into_owned();
        let (table, every_line_fails) = meant_to_fail::table(&name);
        let mut used = vec![false; table.len()];
        for message in nist_file::messages(path) {
            messages += 1;
            let first_line = nist_file::first_line(&message);
            let index = table.iter().position(|entry| entry.line == first_line);
            if let Some(index) = index {
                assert!(
                    !used[index],
                    "{name}: `{first_line}` appears twice; the table cannot tell them apart"
                );
                used[index] = true;
            } else if every_line_fails {
                failures.push(format!(
                    "{name}: `{first_line}` is missing from the table of lines meant to fail"
                ));
            }
            match check(
                direction_of(path),
                &message,
                index.map(|index| table[index].layer),
            ) {
                Ok(Layer::Wire(_)) => rejected += 1,
                Ok(Layer::Command) if index.is_some() => command_level += 1,
                Ok(Layer::Command) => {}
                Err(why) => failures.push(format!("{name}: `{first_line}`: {why}")),
            }
        }
        for (entry, used) in table.iter().zip(used) {
            if !used {
                failures.push(format!(
                    "{name}: table line `{}` ({}) is not in the file",
                    entry.line, entry.nist_says
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} problems:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert_eq!(files.len(), 137, "number of .prg and .res files");
    assert_eq!(
        (messages, rejected, command_level),
        (NIST_MESSAGES, NIST_REJECTED, NIST_COMMAND_LEVEL)
    );
}

#[test]
fn every_logged_line_parses_or_fails_as_nist_meant() {
    let logs = nist_file::files_ending(&nist_file::nist_dir().join("ClientServerLogs"), ".log");
    assert_eq!(logs.len(), 128, "number of logs");
    // The logs are sessions that ran the .prg files, so a logged line NIST meant to fail is in a table.
    let tables: Vec<&MeantToFail> = [
        "parserCmdErrors.prg",
        "numbersErrorCmd.prg",
        "checkerCmdErrors.prg",
    ]
    .iter()
    .flat_map(|file| meant_to_fail::table(file).0)
    .collect();
    let mut lines = 0;
    let mut failures = Vec::new();
    for log in &logs {
        for (direction, line) in nist_file::log_lines(log) {
            lines += 1;
            let expected = match direction {
                Direction::ClientToServer => tables
                    .iter()
                    .find(|entry| entry.line == line)
                    .map(|entry| entry.layer),
                Direction::ServerToClient => None,
            };
            // A log ends every line with CR LF, so a line whose fault in its file was the line end
            // (`05401 GoTo(X(0.1))2` + LF) fails here for another reason: only check that it fails.
            let expected = expected.map(|layer| match layer {
                Layer::Wire(_) => Layer::Wire(""),
                Layer::Command => Layer::Command,
            });
            if let Err(why) = check(direction, format!("{line}\r\n").as_bytes(), expected) {
                failures.push(format!("{}: `{line}`: {why}", log.display()));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} problems:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert_eq!(lines, LOG_LINES);
}

/// A whole response file through `FramedRead` over an `AsyncRead`, as a client would read a server.
#[tokio::test]
async fn a_response_file_streams_through_framed_read() {
    let path = nist_file::nist_dir().join("DCXpart.res");
    let bytes: Vec<u8> = nist_file::messages(&path).concat();
    let responses: Vec<Result<Response, LineError>> =
        FramedRead::new(bytes.as_slice(), ClientCodec::default())
            .map(|item| item.expect("no I/O error"))
            .collect()
            .await;
    assert_eq!(responses.len(), 478);
    assert!(
        responses.iter().all(Result::is_ok),
        "{:?}",
        responses.iter().find(|r| r.is_err())
    );
}

/// parserCmdErrors.prg as one stream, as a server would read a client that sends all of it: the bad lines
/// come out as errors between the good ones, and the stream goes on to the end.
#[tokio::test]
async fn a_command_stream_with_bad_lines_goes_on_to_the_end() {
    let path = nist_file::nist_dir().join("parserCmdErrors.prg");
    let bytes: Vec<u8> = nist_file::messages(&path).concat();
    let commands: Vec<Result<Command, LineError>> =
        FramedRead::new(bytes.as_slice(), ServerCodec::default())
            .map(|item| item.expect("no I/O error"))
            .collect()
            .await;
    let last = commands
        .last()
        .expect("some lines")
        .as_ref()
        .expect("the last line is valid");
    assert_eq!(last.to_string(), "09999 EndSession()");
    // `05401 GoTo(X(0.1))2` ends in LF alone, so it and the ClearAllErrors after it are one bad line.
    assert_eq!(commands.len(), 527);
    assert_eq!(
        commands.iter().filter(|command| command.is_err()).count(),
        53
    );
}
