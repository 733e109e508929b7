//! End-to-end tests of the `zeroset` binary: one test binary, shared helpers, the real executables. The
//! simulator runs as `zeroset sim` on pseudo-terminals and the station's I++ client talks to it through them.

mod blade_errors;
mod campaign;
mod daemon;
mod errors;
mod evaluate;
mod fault_campaign;
mod fit_and_deviate;
mod fit_sanity;
mod lockout;
mod lost_points;
mod machine_link;
mod machine_state;
mod nut;
mod operator;
mod readme;
mod responsive;
mod sim;
mod station;
mod support;
mod sweep;
