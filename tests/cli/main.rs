//! End-to-end tests of the `zeroset` binary: one test binary, shared helpers, the real executable.

mod errors;
mod fit_and_deviate;
mod readme;
mod support;
