//! A seeded fault campaign against the real station: the simulator (`zeroset sim`) and the daemon (`zeroset
//! daemon`) on a pseudo-terminal, driven by the CLI as an operator would. It inspects the propeller again and
//! again, injects every fault the simulator knows (and `kill -9` of the daemon) at seeded moments, clears after
//! each stop, and checks every job: the points per profile of an uninterrupted inspection, no point twice, no
//! motion after an error before ClearAllErrors (from the simulator's transcript; a motion that crossed the
//! error on the line, sent before the daemon read it, excused by the daemon's log), each inspection once in the
//! history, no rescan of a complete profile, the daemon alive, and a job that cannot go on saying where and what
//! to do. Shared by the e2e test (100 faults) and `cargo bench --bench fault_campaign` (1000).

pub(crate) mod checks;
mod plan;
mod run;
mod tally;
mod transcript;
mod wire_log;

pub(crate) use plan::Kind;
pub(crate) use run::{run, Options};
