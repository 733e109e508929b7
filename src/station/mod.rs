//! The daemon: one task per machine owns its line (`worker`), one task per job analyses its points (`pipeline`),
//! one task serves the control socket (`control`), and one task owns the station's state (`daemon`, the shell
//! around `core`, which makes every decision with no I/O: which machine scans what next, when a job stops,
//! resumes, is aborted, or ends). Every scan's moves are planned once (`motion`), checked (`clearance`) and sent
//! as planned (`worker`). They talk only through channels.

pub mod clearance;
pub mod clock;
mod control;
mod core;
mod daemon;
mod escape;
mod finish;
mod gaps;
mod job;
mod journal;
mod motion;
mod not_found;
mod pipeline;
mod recorder;
mod verdicts;
mod worker;

use tokio::sync::{broadcast, mpsc, oneshot};

use crate::api::{Reply, Request};
use crate::config::StationConfig;

/// How many events a watcher may fall behind before it misses some: a whole inspection's points.
const EVENT_BACKLOG: usize = 1 << 16;

/// What the daemon's state task hears: a request from the control socket, with the channel its reply goes back
/// on, or one of the core's other inputs (from a worker, the recorder or the shell's own blocking work).
pub enum DaemonMsg {
    Request {
        request: Request,
        reply: oneshot::Sender<Reply>,
    },
    Input(core::Input),
}

/// Runs the daemon until SIGINT or SIGTERM: binds the control socket, starts a worker per machine, reopens a job
/// a previous daemon left open, and serves.
pub async fn run(config: StationConfig) -> anyhow::Result<()> {
    for folder in [
        &config.folders.data,
        &config.folders.reports,
        &config.folders.logs,
    ] {
        std::fs::create_dir_all(folder)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", folder.display()))?;
    }
    let listener = control::bind(&config.control.socket)?;
    let (to_daemon, inbox) = mpsc::channel(1024);
    let (events, _) = broadcast::channel(EVENT_BACKLOG);
    let workers = config
        .machines
        .iter()
        .map(|m| {
            worker::spawn(
                m.clone(),
                config.probe.clone(),
                config.safety.clone(),
                to_daemon.clone(),
            )
        })
        .collect();
    tokio::spawn(control::serve(listener, to_daemon.clone(), events.clone()));
    let socket = config.control.socket.clone();
    let state = daemon::Daemon::start(config, workers, events, to_daemon).await?;
    tracing::info!(socket = %socket.display(), "daemon ready");
    let result = tokio::select! {
        () = state.run(inbox) => Ok(()),
        signal = shutdown_signal() => signal,
    };
    let _ = std::fs::remove_file(&socket);
    result
}

async fn shutdown_signal() -> anyhow::Result<()> {
    use tokio::signal::unix::{signal, SignalKind};
    let mut terminate = signal(SignalKind::terminate())?;
    tokio::select! {
        _ = tokio::signal::ctrl_c() => {}
        _ = terminate.recv() => {}
    }
    tracing::info!("stopping on a signal; an open job resumes after `zeroset clear`");
    Ok(())
}
