//! One I++ response line through the parser and the client's reply readers.
//! See `zeroset_drivers::fuzz::response` for what it checks.

#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| zeroset_drivers::fuzz::response(data));
