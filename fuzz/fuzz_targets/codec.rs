//! Arbitrary bytes through both decoders, fed in chunks as a stream arrives: no panic, and every line
//! that decodes goes back out through the other side's encoder as a line that decodes to the same value.
//!
//! The first byte picks the chunk size, so that the fuzzer also explores lines split across reads.

#![no_main]

use std::fmt::Debug;

use bytes::BytesMut;
use libfuzzer_sys::fuzz_target;
use tokio_util::codec::{Decoder, Encoder};
use zeroset_drivers::codec::{ClientCodec, EncodeError, ServerCodec};
use zeroset_drivers::wire::LineError;

fuzz_target!(|data: &[u8]| {
    let Some((&chunk, stream)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(chunk).max(1);
    // A client decodes responses, which the server's codec encodes; a server decodes commands, which the
    // client's codec encodes.
    decode_stream(ClientCodec::default(), stream, chunk, ServerCodec::default);
    decode_stream(ServerCodec::default(), stream, chunk, ClientCodec::default);
});

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
