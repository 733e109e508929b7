//! Bytes on the daemon's control socket through its request parser.
//! See `zeroset::api::fuzz::control_request` for what it checks.

#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| zeroset::api::fuzz::control_request(data));
