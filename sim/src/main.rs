//! `zeroset-sim --config config/sims/NAME.toml`: the simulated CMMs, one per configured machine.

use std::path::PathBuf;

use anyhow::Context;
use clap::Parser;
use zeroset_sim::config::SimConfig;

/// Simulated coordinate measuring machines speaking I++ DME on pseudo-terminals or loopback TCP.
///
/// Prints `machine NAME PATH` per machine when ready, then runs until SIGINT, SIGTERM or the end of standard
/// input. Lines `fault MACHINE KIND [ARG]` on standard input inject faults: garbage, drop-lines N, delay MS,
/// disconnect MS, estop, collision, no-touch, surface-not-found.
#[derive(Debug, Parser)]
#[command(name = "zeroset-sim", version)]
struct Args {
    /// The simulator's configuration, e.g. config/sims/propeller.toml.
    #[arg(long)]
    config: PathBuf,
    /// Machine seconds per wall-clock second, overriding the file's time_scale (100 = 100x faster).
    #[arg(long)]
    time_scale: Option<f64>,
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    let config = SimConfig::load(&args.config)?;
    if let Some(scale) = args.time_scale {
        anyhow::ensure!(
            scale > 0.0 && scale.is_finite(),
            "--time-scale {scale} must be above zero"
        );
    }
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .context("starting the async runtime")?;
    let result = runtime.block_on(zeroset_sim::simulator::run(config, args.time_scale));
    // A read of standard input may still be blocked in tokio's blocking pool after a signal; waiting
    // for it would keep the process alive until the input closes.
    runtime.shutdown_background();
    Ok(result?)
}
