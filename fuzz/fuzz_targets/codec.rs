//! Arbitrary bytes through both I++ decoders, in chunks, and back through the encoders.
//! See `zeroset_drivers::fuzz::codec` for what it checks.

#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| zeroset_drivers::fuzz::codec(data));
