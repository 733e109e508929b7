//! Wall-clock times as the station records them: RFC 3339 for people and files, Unix micro- and milliseconds
//! for events, so that a watcher on the same host can measure how long an event took to reach it.

use std::time::{SystemTime, UNIX_EPOCH};

/// Now, as RFC 3339 UTC to the second.
pub fn now_rfc3339() -> String {
    humantime::format_rfc3339_seconds(SystemTime::now()).to_string()
}

pub fn unix_us() -> u64 {
    since_epoch().as_micros() as u64
}

pub fn unix_ms() -> u64 {
    since_epoch().as_millis() as u64
}

fn since_epoch() -> std::time::Duration {
    // A clock set before 1970 is a broken host; zero keeps the station running and the times obviously wrong.
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default()
}
