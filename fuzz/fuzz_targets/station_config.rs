//! A station file's text through the station config loader.
//! See `zeroset::config::fuzz::station_config` for what it checks.

#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| zeroset::config::fuzz::station_config(data));
