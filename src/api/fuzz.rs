//! The body of the fuzz target over the control API's request parser: cargo-fuzz's target
//! (`fuzz/fuzz_targets/control_request.rs`, nightly) and the stable mutation run (`tests/fuzz_targets.rs`)
//! both call it, so the two runs check the same things. It panics on a failed check, which is how a fuzzer
//! learns of it. Public (hidden from the docs) because both callers are outside the crate.

use tokio_util::bytes::BytesMut;
use tokio_util::codec::{Decoder, LinesCodec};

use super::{parse_line, to_line, Reply, ReplyLine, RequestLine};

/// Bytes from a client as the daemon's control socket reads them: split into lines by tokio-util's
/// `LinesCodec` (which the socket uses, with a 1 MiB limit no fuzz input reaches), each line read by
/// [`parse_line`]. A request that parses writes back as one line that parses to the same request. A line
/// that does not is answered with an error reply (as the socket does, also for a line that is not UTF-8):
/// that reply must be one JSON line that a CLI reads back as the same error, whatever the line held.
pub fn control_request(data: &[u8]) {
    let mut codec = LinesCodec::new();
    let mut buffer = BytesMut::from(data);
    loop {
        let line = match codec.decode_eof(&mut buffer) {
            Ok(Some(line)) => line,
            Ok(None) => return,
            // Not UTF-8: the socket answers with its own fixed message, which holds nothing of the line.
            Err(_) => continue,
        };
        match parse_line::<RequestLine>(&line) {
            Ok(request) => {
                let written = to_line(&request);
                assert_one_line(&written);
                let again = parse_line::<RequestLine>(written.trim_end())
                    .unwrap_or_else(|e| panic!("{request:?} writes as {written:?}, refused: {e}"));
                assert_eq!(again, request, "written as {written:?}");
            }
            Err(error) => {
                let message = error.to_string();
                assert!(!message.is_empty(), "an empty refusal of {line:?}");
                let reply = ReplyLine::new(Reply::Error { message });
                let written = to_line(&reply);
                assert_one_line(&written);
                let again = parse_line::<ReplyLine>(written.trim_end())
                    .unwrap_or_else(|e| panic!("the refusal {written:?} does not read back: {e}"));
                assert_eq!(again, reply, "written as {written:?}");
            }
        }
    }
}

/// A line of the API: one newline, at its end.
fn assert_one_line(written: &str) {
    assert!(
        written.ends_with('\n') && written.matches('\n').count() == 1,
        "not one line: {written:?}"
    );
}
