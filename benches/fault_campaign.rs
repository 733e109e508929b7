//! The seeded fault campaign against the real programs (the simulator and the daemon over a pseudo-terminal,
//! the CLI as the operator): every fault kind the simulator injects and `kill -9` of the daemon, at seeded
//! moments of inspections, cleared as an operator would; every job checked (points per profile, no point
//! twice, no motion after an error before ClearAllErrors, the history, no rescan of a complete profile, the
//! daemon alive). Prints the counts per fault kind and the violations; exits non-zero on any violation.
//!
//! Run: `cargo bench --bench fault_campaign -- --faults 1000 --seed 7` (cargo builds the release binary). The
//! e2e suite runs the same code with 100 faults (`cargo test --test e2e fault_campaign`).

// The e2e suite's station, simulator and campaign, shared as they are: this program uses part of their helpers,
// and cargo builds a bench with cfg(test) but without the test harness, so their test modules come without tests.
#[allow(dead_code, unused_imports)]
#[path = "../tests/e2e/campaign/mod.rs"]
mod campaign;
#[allow(dead_code)]
#[path = "../tests/e2e/daemon.rs"]
mod daemon;
#[allow(dead_code)]
#[path = "../tests/e2e/sim.rs"]
mod sim;
#[allow(dead_code)]
#[path = "../tests/e2e/support.rs"]
mod support;

use clap::Parser;

#[derive(Parser)]
#[command(about = "A seeded fault campaign against the real zeroset simulator, daemon and CLI")]
struct Args {
    /// How many faults to inject.
    #[arg(long, default_value_t = 1000)]
    faults: usize,
    /// The seed of the faults, their arguments and their moments.
    #[arg(long, default_value_t = 7)]
    seed: u64,
    /// Passed by `cargo bench` to every bench program.
    #[arg(long, hide = true)]
    bench: bool,
}

fn main() -> std::process::ExitCode {
    let args = Args::parse();
    let tally = campaign::run(&campaign::Options {
        faults: args.faults,
        seed: args.seed,
    });
    println!("{}", tally.summary());
    if tally.violations.is_empty() {
        std::process::ExitCode::SUCCESS
    } else {
        std::process::ExitCode::FAILURE
    }
}
