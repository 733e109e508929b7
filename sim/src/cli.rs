//! The simulator's command line, shared by the `zeroset-sim` binary and `zeroset sim`.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;

use crate::config::SimConfig;

/// Simulated coordinate measuring machines speaking I++ DME on pseudo-terminals or loopback TCP.
///
/// Prints `machine NAME PATH` per machine when ready, then runs until SIGINT or SIGTERM (the end of standard
/// input does not stop it, so it can run in the background). Lines `fault MACHINE KIND [ARG]` on standard input
/// inject faults: garbage, drop-lines N, delay MS, disconnect MS, estop, collision, no-touch, surface-not-found.
#[derive(Debug, Args)]
pub struct SimArgs {
    /// The simulator's configuration, e.g. config/sims/propeller.toml.
    #[arg(long)]
    pub config: PathBuf,
    /// Machine seconds per wall-clock second, overriding the file's time_scale (100 = 100x faster).
    #[arg(long)]
    pub time_scale: Option<f64>,
    /// Also link DIR/NAME to each pseudo-terminal machine's path (DIR is created if missing; a stale link
    /// is replaced), so that a station can name a fixed port. The links are removed on exit.
    #[arg(long, value_name = "DIR")]
    pub link_dir: Option<PathBuf>,
}

/// Loads the configuration and serves its machines until stopped.
pub fn run(args: &SimArgs) -> anyhow::Result<()> {
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
    let served = runtime.block_on(crate::simulator::run(
        config,
        args.time_scale,
        args.link_dir.as_deref(),
    ));
    // Standard input, while open, is read on a blocking thread that no signal interrupts: waiting for it (what
    // dropping the runtime does) would keep a simulator told to stop by SIGTERM alive until its stdin closes.
    runtime.shutdown_background();
    served?;
    Ok(())
}
