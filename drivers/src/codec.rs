//! Framing I++ DME lines on a byte stream, for tokio's `FramedRead`, `FramedWrite` and `Framed` over any
//! `AsyncRead`/`AsyncWrite` (TCP, a serial line, a pseudo-terminal).
//!
//! A line that is not valid (garbage bytes, bad syntax, too long) is yielded as an `Err` item and the
//! decoder carries on at the next CR LF, so one bad line does not end the stream: tokio-util ends a
//! framed stream after the decoder's first `Err`, so the decoder itself only fails on I/O errors.

use std::borrow::Borrow;
use std::io;

use bytes::{BufMut, BytesMut};
use tokio_util::codec::{Decoder, Encoder};

use crate::wire::{Command, LineError, Response, WireError};

/// The longest line, CR LF not counted: the spec's "The maximum number of characters in a line should
/// not exceed 65536" (6.2). It also bounds the memory one connection can make the decoder buffer.
pub const MAX_LINE_LEN: usize = 65_536;

/// Client side: decodes responses, encodes commands.
#[derive(Debug, Default)]
pub struct ClientCodec {
    lines: LineFramer,
}

/// Server side (the simulator): decodes commands, encodes responses.
#[derive(Debug, Default)]
pub struct ServerCodec {
    lines: LineFramer,
}

/// Why a line could not be written.
#[derive(Debug, thiserror::Error)]
pub enum EncodeError {
    #[error("line of {len} bytes is over the {MAX_LINE_LEN}-byte limit; the peer would reject it")]
    LineTooLong { len: usize },
    #[error(transparent)]
    Io(#[from] io::Error),
}

impl Decoder for ClientCodec {
    type Item = Result<Response, LineError>;
    type Error = io::Error;

    fn decode(&mut self, buf: &mut BytesMut) -> io::Result<Option<Self::Item>> {
        Ok(self
            .lines
            .next_line(buf)
            .map(|line| Response::parse(&line?)))
    }

    fn decode_eof(&mut self, buf: &mut BytesMut) -> io::Result<Option<Self::Item>> {
        Ok(self
            .lines
            .next_line_at_eof(buf)
            .map(|line| Response::parse(&line?)))
    }
}

impl Decoder for ServerCodec {
    type Item = Result<Command, LineError>;
    type Error = io::Error;

    fn decode(&mut self, buf: &mut BytesMut) -> io::Result<Option<Self::Item>> {
        Ok(self.lines.next_line(buf).map(|line| Command::parse(&line?)))
    }

    fn decode_eof(&mut self, buf: &mut BytesMut) -> io::Result<Option<Self::Item>> {
        Ok(self
            .lines
            .next_line_at_eof(buf)
            .map(|line| Command::parse(&line?)))
    }
}

impl<C: Borrow<Command>> Encoder<C> for ClientCodec {
    type Error = EncodeError;

    fn encode(&mut self, command: C, buf: &mut BytesMut) -> Result<(), EncodeError> {
        write_line(&command.borrow().to_string(), buf)
    }
}

impl<R: Borrow<Response>> Encoder<R> for ServerCodec {
    type Error = EncodeError;

    fn encode(&mut self, response: R, buf: &mut BytesMut) -> Result<(), EncodeError> {
        write_line(&response.borrow().to_string(), buf)
    }
}

fn write_line(line: &str, buf: &mut BytesMut) -> Result<(), EncodeError> {
    if line.len() > MAX_LINE_LEN {
        return Err(EncodeError::LineTooLong { len: line.len() });
    }
    buf.reserve(line.len() + 2);
    buf.put_slice(line.as_bytes());
    buf.put_slice(b"\r\n");
    Ok(())
}

/// Splits the byte stream at CR LF, without interpreting the lines.
#[derive(Debug, Default)]
struct LineFramer {
    /// Inside a line already reported as too long: drop bytes up to its CR LF.
    discarding: bool,
    /// Bytes at the front of the buffer already searched for CR LF, so a long line is scanned once.
    searched: usize,
}

impl LineFramer {
    /// The next complete line without its CR LF, or its problem; `None` until one is complete.
    fn next_line(&mut self, buf: &mut BytesMut) -> Option<Result<BytesMut, LineError>> {
        loop {
            let Some(end) = find_crlf(buf, self.searched) else {
                return self.wait_for_more(buf);
            };
            let mut line = buf.split_to(end + 2);
            line.truncate(end);
            self.searched = 0;
            if std::mem::take(&mut self.discarding) {
                continue;
            }
            if line.len() > MAX_LINE_LEN {
                return Some(Err(too_long(&line)));
            }
            return Some(Ok(line));
        }
    }

    /// No CR LF in `buf`: keep waiting, unless the line is already too long, which is reported once and
    /// then dropped as it arrives. A trailing CR is kept since it may be half of the CR LF.
    fn wait_for_more(&mut self, buf: &mut BytesMut) -> Option<Result<BytesMut, LineError>> {
        let keep_from = if buf.last() == Some(&b'\r') {
            buf.len() - 1
        } else {
            buf.len()
        };
        if self.discarding {
            let _ = buf.split_to(keep_from);
            self.searched = 0;
            return None;
        }
        // MAX_LINE_LEN bytes and a CR can still become a valid line; one more byte cannot.
        if buf.len() > MAX_LINE_LEN + 1 {
            let error = too_long(buf);
            let _ = buf.split_to(keep_from);
            self.searched = 0;
            self.discarding = true;
            return Some(Err(error));
        }
        self.searched = buf.len().saturating_sub(1);
        None
    }

    /// At the end of the stream: the remaining lines, then any unterminated rest as an error.
    fn next_line_at_eof(&mut self, buf: &mut BytesMut) -> Option<Result<BytesMut, LineError>> {
        if let Some(line) = self.next_line(buf) {
            return Some(line);
        }
        let rest = buf.split();
        self.searched = 0;
        if std::mem::take(&mut self.discarding) || rest.is_empty() {
            return None;
        }
        Some(Err(LineError::new(
            WireError::UnterminatedLine,
            &rest,
            rest.len() + 1,
        )))
    }
}

fn find_crlf(buf: &[u8], from: usize) -> Option<usize> {
    buf.get(from..)?
        .windows(2)
        .position(|pair| pair == b"\r\n")
        .map(|pos| from + pos)
}

/// The error for an over-long line, pointing at its start: the tag says more in a log than byte 65537.
fn too_long(line: &[u8]) -> LineError {
    let problem = WireError::LineTooLong {
        len: line.len(),
        max: MAX_LINE_LEN,
    };
    LineError::new(problem, line, 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `chunks` one by one, as reads would deliver them, then ends the stream; returns every item.
    fn decode_all<D: Decoder<Error = io::Error>>(codec: &mut D, chunks: &[&[u8]]) -> Vec<D::Item> {
        let mut buf = BytesMut::new();
        let mut items = Vec::new();
        for chunk in chunks {
            buf.extend_from_slice(chunk);
            while let Some(item) = codec.decode(&mut buf).unwrap() {
                items.push(item);
            }
        }
        while let Some(item) = codec.decode_eof(&mut buf).unwrap() {
            items.push(item);
        }
        items
    }

    fn problems<T>(items: &[Result<T, LineError>]) -> Vec<Option<WireError>> {
        items
            .iter()
            .map(|item| item.as_ref().err().map(|error| error.problem().clone()))
            .collect()
    }

    #[test]
    fn splits_lines_across_reads() {
        let items = decode_all(
            &mut ServerCodec::default(),
            &[b"00001 Sta", b"rtSession()\r", b"\n00002 Ho", b"me()\r\n"],
        );
        let names: Vec<_> = items
            .iter()
            .map(|item| item.as_ref().unwrap().name().as_str())
            .collect();
        assert_eq!(names, ["StartSession", "Home"]);
    }

    #[test]
    fn resynchronises_after_garbage() {
        let items = decode_all(
            &mut ClientCodec::default(),
            &[b"00001 &\r\n\xFF\x00garbage\x1B[0m\r\n00001 # X(1)\r\nnonsense\r\n00001 %\r\n"],
        );
        assert_eq!(
            problems(&items),
            [
                None,
                Some(WireError::IllegalCharacter(0xFF)),
                None,
                Some(WireError::BadTag),
                None
            ]
        );
    }

    #[test]
    fn bare_lf_or_cr_is_part_of_the_line_and_illegal() {
        // Spec 6.1.1: CR and LF only as a pair at the end; elsewhere they are illegal characters.
        let items = decode_all(
            &mut ServerCodec::default(),
            &[b"00001 Home()\n00002 Home()\r\n00003 Ho\rme()\r\n"],
        );
        assert_eq!(
            problems(&items),
            [
                Some(WireError::IllegalCharacter(b'\n')),
                Some(WireError::IllegalCharacter(b'\r'))
            ]
        );
    }

    #[test]
    fn reports_an_over_long_line_once_and_recovers() {
        let long = vec![b'9'; MAX_LINE_LEN + 100];
        let items = decode_all(
            &mut ServerCodec::default(),
            &[
                b"00001 Home()\r\n00002 Get(X(",
                &long,
                &long,
                b"))\r\n00003 Home()\r\n",
            ],
        );
        let too_long = WireError::LineTooLong {
            len: "00002 Get(X(".len() + long.len(),
            max: MAX_LINE_LEN,
        };
        assert_eq!(problems(&items), [None, Some(too_long), None]);
        assert_eq!(items[2].as_ref().unwrap().to_string(), "00003 Home()");
    }

    #[test]
    fn over_long_line_in_one_read_is_reported_too() {
        let mut codec = ClientCodec::default();
        let mut buf = BytesMut::from(&b"00001 # "[..]);
        buf.extend_from_slice(&vec![b'1'; MAX_LINE_LEN]);
        buf.extend_from_slice(b"\r\n00001 %\r\n");
        let first = codec.decode(&mut buf).unwrap().unwrap().unwrap_err();
        assert_eq!(
            first.problem(),
            &WireError::LineTooLong {
                len: MAX_LINE_LEN + 8,
                max: MAX_LINE_LEN
            }
        );
        let excerpt = first.excerpt();
        assert!(
            excerpt.starts_with("00001 # 111") && excerpt.len() < 100,
            "{excerpt}"
        );
        assert!(codec.decode(&mut buf).unwrap().unwrap().is_ok());
    }

    #[test]
    fn a_line_of_exactly_the_limit_is_accepted() {
        let prefix = b"00001 # ";
        let digits = "1,".repeat((MAX_LINE_LEN - prefix.len()) / 2);
        let line = [&prefix[..], &digits.as_bytes()[..digits.len() - 1], b"1"].concat();
        assert_eq!(line.len(), MAX_LINE_LEN);
        let items = decode_all(&mut ClientCodec::default(), &[&line, b"\r", b"\n"]);
        assert_eq!(problems(&items), [None]);
    }

    #[test]
    fn an_unterminated_line_at_the_end_is_an_error() {
        let items = decode_all(
            &mut ServerCodec::default(),
            &[b"00001 Home()\r\n00002 Home()"],
        );
        assert_eq!(problems(&items), [None, Some(WireError::UnterminatedLine)]);
    }

    #[test]
    fn encodes_with_crlf_and_refuses_over_long_lines() {
        let mut buf = BytesMut::new();
        let command: Command = "E0001 AbortE()".parse().unwrap();
        ClientCodec::default().encode(&command, &mut buf).unwrap();
        let response: Response = "E0000 ! Error(3, 0500, \"Stop\", \"Emergency stop\")"
            .parse()
            .unwrap();
        ServerCodec::default().encode(response, &mut buf).unwrap();
        assert_eq!(
            &buf[..],
            b"E0001 AbortE()\r\nE0000 ! Error(3, 0500, \"Stop\", \"Emergency stop\")\r\n"
        );

        let numbers = "1, ".repeat(MAX_LINE_LEN / 3);
        let huge: Response = format!("00001 # {}1", numbers).parse().unwrap();
        let error = ServerCodec::default().encode(&huge, &mut buf).unwrap_err();
        assert!(matches!(error, EncodeError::LineTooLong { .. }), "{error}");
    }
}
