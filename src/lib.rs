//! zeroset: the controller of a CMM inspection station. This library holds the geometry kernel, the model and
//! point files, and the command-line interface; the `zeroset` binary is a thin wrapper over [`cli::run`].

pub mod analysis;
pub mod api;
pub mod cli;
pub mod config;
pub mod fsutil;
pub mod geometry;
pub mod model_file;
pub mod plan;
pub mod points;
pub mod report;
pub mod station;
