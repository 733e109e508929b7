//! The `zeroset` command line: argument parsing and one module per command. Library errors are turned into one
//! line an operator can act on: which file, which line, what is wrong.

mod deviate;
mod fit;

use clap::{Parser, Subcommand, ValueEnum};

use crate::geometry::distance::DistanceMethod;
use crate::geometry::fit3l::FitMethod;

#[derive(Parser)]
#[command(
    name = "zeroset",
    version,
    about = "Inspection-station controller: reference models from master scans and deviations of measured points (mm)"
)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Fit a reference model to measured points.
    #[command(subcommand)]
    Fit(FitCommand),
    /// Signed deviations (mm, positive outside the material) of measured points from a reference model.
    Deviate(deviate::DeviateArgs),
    /// Run the simulated CMMs of a simulator configuration (the same as the zeroset-sim binary).
    ///
    /// Prints `machine NAME PATH` per machine when ready, then runs until SIGINT, SIGTERM or the end of
    /// standard input. Lines `fault MACHINE KIND [ARG]` on standard input inject faults: garbage, drop-lines N,
    /// delay MS, disconnect MS, estop, collision, no-touch, surface-not-found.
    Sim(zeroset_sim::cli::SimArgs),
}

#[derive(Subcommand)]
enum FitCommand {
    /// Fit an implicit polynomial (a profile from y,z points; a surface, or a stack of profiles, from x,y,z).
    Ip(fit::FitIpArgs),
}

/// Fitting methods as the command line names them.
#[derive(Clone, Copy, ValueEnum)]
pub enum MethodArg {
    /// Plain 3L, as in seed 003 (the level sets are varied and the most accurate fit kept).
    #[value(name = "3l")]
    ThreeL,
    /// Ridge-regularised 3L (Tasdizen, Tarel, Cooper).
    Ridge,
    /// Ridge-regularised 3L refined by orthogonal distances: the most accurate.
    Odr,
}

impl From<MethodArg> for FitMethod {
    fn from(m: MethodArg) -> Self {
        match m {
            MethodArg::ThreeL => Self::ThreeL,
            MethodArg::Ridge => Self::Ridge,
            MethodArg::Odr => Self::Orthogonal,
        }
    }
}

#[derive(Clone, Copy, ValueEnum)]
pub enum DistanceArg {
    /// The exact orthogonal distance.
    Exact,
    /// The approximation of seed 003 (fails near edges, and says so per point).
    Paper,
    /// Taubin's first-order estimate F/|grad F|.
    Taubin,
}

impl From<DistanceArg> for DistanceMethod {
    fn from(d: DistanceArg) -> Self {
        match d {
            DistanceArg::Exact => Self::Exact,
            DistanceArg::Paper => Self::Paper,
            DistanceArg::Taubin => Self::Taubin,
        }
    }
}

/// Runs the command line; the error is one line for the operator.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Fit(FitCommand::Ip(args)) => fit::run(&args),
        Command::Deviate(args) => deviate::run(&args),
        Command::Sim(args) => zeroset_sim::cli::run(&args),
    }
}

/// "FILE: lines 2-N" for problems of a whole point set (the header is line 1).
fn all_rows(path: &std::path::Path, count: usize) -> String {
    format!("{}: lines 2-{}", path.display(), count + 1)
}
