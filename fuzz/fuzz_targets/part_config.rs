//! A part file's text through the part config loader.
//! See `zeroset::config::fuzz::part_config` for what it checks.

#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| zeroset::config::fuzz::part_config(data));
