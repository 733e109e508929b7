//! The bodies of the fuzz targets over this crate's parsers, one function per target. cargo-fuzz's targets
//! (`fuzz/fuzz_targets/`, nightly) and the stable mutation run of the test suite (`tests/fuzz_targets.rs` of
//! the root crate) both call these, so the two runs check the same things. Each panics on a failed check:
//! that is how a fuzzer learns of it.
//!
//! Public (hidden from the docs) because both callers are other crates and the parsers they reach behind
//! the public [`Response`] (the client's reply readers) are crate-private; a cargo feature would keep them
//! out of release builds but then the root crate's plain `cargo test` could not reach them.

use std::fmt::Debug;

use bytes::BytesMut;
use tokio_util::codec::{Decoder, Encoder};

use crate::client::replies;
use crate::codec::{ClientCodec, EncodeError, ServerCodec};
use crate::machine::Xyz;
use crate::wire::{LineError, Number, Response, ResponseKind};

/// Arbitrary bytes through both decoders, fed in chunks as a stream arrives: every line that decodes goes
/// back out through the other side's encoder as a line that decodes to the same value.
///
/// The first byte picks the chunk size, so that the fuzzer also explores lines split across reads.
pub fn codec(data: &[u8]) {
    let Some((&chunk, stream)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(chunk).max(1);
    // A client decodes responses, which the server's codec encodes; a server decodes commands, which the
    // client's codec encodes.
    decode_stream(ClientCodec::default(), stream, chunk, ServerCodec::default);
    decode_stream(ServerCodec::default(), stream, chunk, ClientCodec::default);
}

/// One response line (without its CR LF) as the client reads it: a line that parses formats to a line
/// that parses to the same response and formats the same again; an error's severity and code are in the
/// spec's ranges; and a data line goes through the client's reply readers of values (scan points, a
/// measured point, a position, a number), whose values must be finite, as the station's
/// geometry needs them.
pub fn response(line: &[u8]) {
    let Ok(response) = Response::parse(line) else {
        return;
    };
    let text = response.to_string();
    let again = Response::parse(text.as_bytes())
        .unwrap_or_else(|e| panic!("{response:?} formats to {text:?}, which does not parse: {e}"));
    assert_eq!(again, response, "{text:?} reads back as another response");
    assert_eq!(again.to_string(), text, "formatting is not stable");
    match response.kind() {
        ResponseKind::Error(error) => {
            assert!(error.severity() <= 9 && error.code() <= 9999, "{error:?}")
        }
        ResponseKind::Data(data) => read_replies(data),
        ResponseKind::Ack | ResponseKind::Complete => {}
    }
}

/// The client's reply readers on one data line; each value read must be finite.
fn read_replies(data: &crate::wire::Data) {
    let lines = std::slice::from_ref(data);
    if let Ok(points) = replies::scan_points(data) {
        for point in points {
            assert_finite(&[point.centre, point.normal], "scan point");
            assert!(point.quality.is_finite(), "scan quality {}", point.quality);
        }
    }
    if let Ok(point) = replies::measured_point(lines) {
        assert_finite(&[point.centre, point.normal], "measured point");
    }
    if let Ok(position) = replies::position(lines) {
        assert_finite(&[position], "position");
    }
    if let Ok(radius) = replies::number(lines, &["Tool.AvrRadius", "AvrRadius"]) {
        assert!(radius.is_finite(), "tool radius {radius}");
    }
}

fn assert_finite(values: &[Xyz], what: &str) {
    for v in values {
        assert!(
            v.x.is_finite() && v.y.is_finite() && v.z.is_finite(),
            "{what} {v:?} is not finite"
        );
        // What the station sends back to a machine goes through Number::from_f64: every value read must
        // be one that can be written again.
        for value in [v.x, v.y, v.z] {
            Number::from_f64(value)
                .unwrap_or_else(|e| panic!("{what}: {value} cannot be sent: {e}"));
        }
    }
}

/// Decodes `stream` in `chunk`-byte reads, then at its end; checks each valid item's round trip through
/// `encoder` (the peer's codec) and a fresh decoder.
fn decode_stream<D, E, T>(mut decoder: D, stream: &[u8], chunk: usize, encoder: fn() -> E)
where
    D: Decoder<Item = Result<T, LineError>, Error = std::io::Error> + Default,
    E: Encoder<T, Error = EncodeError>,
    T: Clone + Debug + PartialEq,
{
    let mut buf = BytesMut::new();
    for piece in stream.chunks(chunk) {
        buf.extend_from_slice(piece);
        while let Some(item) = decoder
            .decode(&mut buf)
            .expect("decoding from memory does no I/O")
        {
            check_round_trip::<D, E, T>(item, encoder);
        }
    }
    while let Some(item) = decoder
        .decode_eof(&mut buf)
        .expect("decoding from memory does no I/O")
    {
        check_round_trip::<D, E, T>(item, encoder);
    }
}

fn check_round_trip<D, E, T>(item: Result<T, LineError>, encoder: fn() -> E)
where
    D: Decoder<Item = Result<T, LineError>, Error = std::io::Error> + Default,
    E: Encoder<T, Error = EncodeError>,
    T: Clone + Debug + PartialEq,
{
    let Ok(value) = item else {
        return;
    };
    let mut line = BytesMut::new();
    match encoder().encode(value.clone(), &mut line) {
        Ok(()) => {}
        // The canonical form may be longer than what was read (numbers written out in full): refusing to
        // send an over-long line is the encoder's job, not a failure.
        Err(EncodeError::LineTooLong { .. }) => return,
        Err(EncodeError::Io(e)) => panic!("encoding into memory failed: {e}"),
    }
    let mut again = D::default();
    let decoded = again
        .decode_eof(&mut line)
        .expect("decoding from memory does no I/O");
    match decoded {
        Some(Ok(same)) => assert_eq!(
            same, value,
            "the formatted line reads back as another value"
        ),
        other => panic!("{value:?} formats to a line that reads back as {other:?}"),
    }
    assert!(line.is_empty(), "the formatted line is more than one line");
}
