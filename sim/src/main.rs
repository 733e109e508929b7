//! `zeroset-sim --config config/sims/NAME.toml`: the simulated CMMs, one per configured machine.

use clap::Parser;
use zeroset_sim::cli::{run, SimArgs};

#[derive(Debug, Parser)]
#[command(name = "zeroset-sim", version)]
struct Cli {
    #[command(flatten)]
    args: SimArgs,
}

fn main() -> anyhow::Result<()> {
    run(&Cli::parse().args)
}
