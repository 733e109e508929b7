//! The `zeroset` command line: argument parsing and one module per command. Library errors are turned into one
//! line an operator can act on: which file, which line, what is wrong.

/// `println!` for a command's results: a reader that closes standard output (`| head`) ends the command quietly
/// ([`exit::OutputClosed`]) instead of panicking. Returns `anyhow::Result<()>`.
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::cli::exit::write_out(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// `println!` for the lines of a command whose result is a file: a closed standard output ends it with code 141 only
/// after its work is done and its files written ([`exit::write_report`]). Returns `anyhow::Result<()>`.
macro_rules! reportln {
    ($($arg:tt)*) => {
        $crate::cli::exit::write_report(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// [`outln!`] without the newline.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::exit::write_out(format_args!($($arg)*))
    };
}

mod control;
pub mod demo;
mod deviate;
mod evaluate;
pub mod exit;
mod fit;
mod fit_supershape;
mod mesh;
mod station;
mod sweep;
mod watch;

use clap::{Parser, Subcommand, ValueEnum};

use crate::api::Request;
use crate::geometry::distance::DistanceMethod;
use crate::geometry::fit3l::FitMethod;

#[derive(Parser)]
#[command(
    name = "zeroset",
    version,
    about = "Inspection-station controller: reference models from master scans and deviations of measured points (mm)",
    after_help = exit::EXIT_CODES
)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run the whole station on simulated machines: teach the propeller's blade A, inspect blades A, B, C live.
    Demo(demo::DemoArgs),
    /// Run the station daemon: it drives the machines and serves the operator commands below.
    Daemon(station::StationFile),
    /// Scan the master instance of a part and fit its reference model (shown live).
    Teach(station::TeachArgs),
    /// Scan every instance of a part and report its deviations (shown live); writes the part's report.
    Inspect(station::InspectArgs),
    /// Show the current job live: progress per instance and running deviation statistics (mm).
    Watch(station::WatchArgs),
    /// The machines and the current job.
    Status(station::StatusArgs),
    /// Stop all motion now and end the current job (its scans so far stay on disk).
    Abort(station::StationFile),
    /// Clear the machines' errors after the cause is removed, and continue a stopped job from its last complete
    /// profile.
    Clear(station::StationFile),
    /// Print the newest report of a part serial number.
    Report(station::ReportArgs),
    /// Fit a reference model to measured points.
    #[command(subcommand)]
    Fit(FitCommand),
    /// Signed deviations (mm, positive outside the material) of measured points from a reference model.
    Deviate(deviate::DeviateArgs),
    /// Where a measured section lies against its nominal profile model (shift along the chord and the thickness,
    /// twist, in mm and deg) and its form error after a least-squares or minimum-zone best fit.
    Evaluate(evaluate::EvaluateArgs),
    /// Polygonise a supershape model into a closed mesh (STL, PLY or OBJ by the file's extension).
    Mesh(mesh::MeshArgs),
    /// The clearance of every move of a taught part's inspection (mm) and the silhouette of the swept ball (SVG).
    Sweep(sweep::SweepArgs),
    /// Run the simulated CMMs of a simulator configuration (the same as the zeroset-sim binary).
    ///
    /// Prints `machine NAME PATH` per machine when ready, then runs until SIGINT or SIGTERM (the end of standard
    /// input does not stop it, so it can run in the background). Lines `fault MACHINE KIND [ARG]` on standard
    /// input inject faults: garbage, drop-lines N, delay MS, disconnect MS, estop, collision, no-touch,
    /// surface-not-found.
    Sim(zeroset_sim::cli::SimArgs),
}

#[derive(Subcommand)]
enum FitCommand {
    /// Fit an implicit polynomial (a profile from y,z points; a surface, or a stack of profiles, from x,y,z).
    Ip(fit::FitIpArgs),
    /// Recover a supershape model (seed 001) from x,y,z points over a part's surface: the envelope with its symmetry
    /// numbers, truncated by the points' bounding box, minus the holes found; distances in mm.
    Supershape(fit_supershape::FitSupershapeArgs),
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
    let ran = match cli.command {
        Command::Fit(FitCommand::Ip(args)) => fit::run(&args),
        Command::Fit(FitCommand::Supershape(args)) => fit_supershape::run(&args),
        Command::Deviate(args) => deviate::run(&args),
        Command::Evaluate(args) => evaluate::run(&args),
        Command::Mesh(args) => mesh::run(&args),
        Command::Sweep(args) => sweep::run(&args),
        Command::Sim(args) => zeroset_sim::cli::run(&args),
        Command::Demo(args) => demo::run(&args),
        Command::Daemon(station) => station::daemon(&station),
        Command::Teach(args) => {
            station::run_job(&args.job, Request::Teach { part: args.part }).map(drop)
        }
        Command::Inspect(args) => {
            let verdict = station::run_job(
                &args.job,
                Request::Inspect {
                    part: args.part.clone(),
                    serial: args.serial.clone(),
                },
            )?;
            station::judge(&args.part, &args.serial, verdict)
        }
        Command::Watch(args) => station::watch(&args),
        Command::Status(args) => station::status(&args),
        Command::Abort(station) => station::simple(&station, Request::Abort),
        Command::Clear(station) => station::simple(&station, Request::Clear),
        Command::Report(args) => station::report(&args),
    };
    ran.and_then(|()| exit::report_cut_off())
}

/// "FILE: lines 402-801" for a problem of some of a point file's points: `indices` (ascending) into the file's
/// points, `lines` each point's line in the file. Runs of consecutive points are named by their first and last
/// lines, the first three runs and how many more.
fn rows_of(
    path: &std::path::Path,
    lines: &[u64],
    indices: impl IntoIterator<Item = usize>,
) -> String {
    const RUNS_NAMED: usize = 3;
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for i in indices {
        match runs.last_mut() {
            Some((_, last)) if *last + 1 == i => *last = i,
            _ => runs.push((i, i)),
        }
    }
    let mut named: Vec<String> = runs
        .iter()
        .take(RUNS_NAMED)
        .map(|&(first, last)| match (lines[first], lines[last]) {
            (a, b) if a == b => a.to_string(),
            (a, b) => format!("{a}-{b}"),
        })
        .collect();
    match runs.len().saturating_sub(RUNS_NAMED) {
        0 => {}
        1 => named.push("and 1 more run".to_string()),
        more => named.push(format!("and {more} more runs")),
    }
    let word = if runs.len() == 1 && runs[0].0 == runs[0].1 {
        "line"
    } else {
        "lines"
    };
    format!("{}: {word} {}", path.display(), named.join(", "))
}

#[cfg(test)]
mod tests {
    use super::rows_of;
    use std::path::Path;

    #[test]
    fn rows_are_named_by_their_own_lines_run_by_run() {
        let path = Path::new("stack.csv");
        // A comment on line 5 moves every later point down a line.
        let lines: Vec<u64> = (2..5).chain(6..12).collect();
        assert_eq!(rows_of(path, &lines, 0..9), "stack.csv: lines 2-11");
        assert_eq!(rows_of(path, &lines, 3..9), "stack.csv: lines 6-11");
        assert_eq!(rows_of(path, &lines, [4]), "stack.csv: line 7");
        assert_eq!(
            rows_of(path, &lines, [0, 2, 4, 6, 8]),
            "stack.csv: lines 2, 4, 7, and 2 more runs"
        );
        assert_eq!(
            rows_of(path, &lines, [0, 2, 3, 5, 7, 8]),
            "stack.csv: lines 2, 4-6, 8, and 1 more run"
        );
    }
}
