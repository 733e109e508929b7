//! The operator's commands: run the daemon, teach, inspect, watch, status, abort, clear, report. Each talks to the
//! daemon over the control socket named in the station file.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;

use super::control::{accepted, Control};
use super::exit::JobEnded;
use super::watch::{JobEnd, Watch};
use crate::api::{JobKind, JobPhase, Reply, Request, StationStatus, Verdict};
use crate::config::{PartConfig, StationConfig};

/// The station file, shared by every station command.
#[derive(Debug, Args, Clone)]
pub struct StationFile {
    /// The station's configuration (machines, probe, safety, folders, control socket).
    #[arg(long, default_value = "config/station.toml")]
    pub config: PathBuf,
}

#[derive(Debug, Args)]
pub struct JobArgs {
    #[command(flatten)]
    pub station: StationFile,
    /// Return once the job has started instead of following it to its end.
    #[arg(long)]
    pub detach: bool,
}

#[derive(Debug, Args)]
pub struct TeachArgs {
    /// The part, as named by its file in the station's parts folder (e.g. propeller).
    pub part: String,
    #[command(flatten)]
    pub job: JobArgs,
}

#[derive(Debug, Args)]
pub struct InspectArgs {
    /// The part, as named by its file in the station's parts folder (e.g. propeller).
    pub part: String,
    /// The part's serial number; it names the report's folder.
    #[arg(long)]
    pub serial: String,
    #[command(flatten)]
    pub job: JobArgs,
}

#[derive(Debug, Args)]
pub struct WatchArgs {
    #[command(flatten)]
    pub station: StationFile,
    /// Write each event as the JSON line the daemon sent, instead of the display.
    #[arg(long)]
    pub events: bool,
    /// Keep watching after the current job ends.
    #[arg(long)]
    pub follow: bool,
}

#[derive(Debug, Args)]
pub struct StatusArgs {
    #[command(flatten)]
    pub station: StationFile,
    /// Write the status as JSON.
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The part's serial number: prints its newest report's summary and folder.
    #[arg(required_unless_present_any = ["trend", "export"])]
    pub serial: Option<String>,
    /// Per profile of each instance, over the last parts: the worst + and worst - deviations and the form (mm),
    /// Cp and Cpk of those against the tolerance, and the individuals-chart signals; per blade parameter (chord,
    /// thicknesses, camber, chord angle, pitch, angular spacing) its deviation's mean and spread, and Cp and Cpk
    /// against its tolerance; trend.html beside it.
    #[arg(long, conflicts_with = "serial")]
    pub trend: bool,
    /// The inspection history as CSV on standard output, for spreadsheets.
    #[arg(long, value_enum, conflicts_with = "serial")]
    pub export: Option<ExportFormat>,
    /// The part type of the trend or the export (a part file's name).
    #[arg(long, default_value = "propeller")]
    pub part_type: String,
    /// How many of the newest inspections the trend or the export covers (at least 1).
    #[arg(long, default_value_t = 50, value_parser = at_least_one)]
    pub last: usize,
    #[command(flatten)]
    pub station: StationFile,
}

#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum ExportFormat {
    Csv,
}

/// `--last`: a count of inspections, so 0 is a usage error rather than an empty history.
fn at_least_one(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(0) => Err("must be at least 1 (the number of newest inspections to cover)".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!(
            "{e}; give a whole number of inspections, at least 1"
        )),
    }
}

/// The control socket of a station file.
pub fn socket_of(station: &StationFile) -> anyhow::Result<PathBuf> {
    let config = StationConfig::load(&station.config)?;
    Ok(config.control.socket)
}

fn connect(station: &StationFile) -> anyhow::Result<Control> {
    Control::connect(&socket_of(station)?)
}

/// `zeroset daemon`: logs as JSON lines in the log folder (and a short form on stderr), then serves.
pub fn daemon(station: &StationFile) -> anyhow::Result<()> {
    let config = StationConfig::load(&station.config)?;
    init_logging(&config.folders.logs)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .context("starting the async runtime")?;
    runtime.block_on(crate::station::run(config))
}

fn init_logging(folder: &Path) -> anyhow::Result<()> {
    use tracing_subscriber::layer::SubscriberExt;
    use tracing_subscriber::util::SubscriberInitExt;
    use tracing_subscriber::{fmt, EnvFilter, Layer};
    std::fs::create_dir_all(folder)
        .with_context(|| format!("cannot create {}", folder.display()))?;
    let path = folder.join("zeroset-daemon.jsonl");
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("cannot open the log {}", path.display()))?;
    let filter =
        || EnvFilter::try_from_env("ZEROSET_LOG").unwrap_or_else(|_| EnvFilter::new("info"));
    tracing_subscriber::registry()
        .with(
            fmt::layer()
                .json()
                .with_writer(std::sync::Mutex::new(file))
                .with_filter(filter()),
        )
        .with(
            // Colours only for a person at a terminal: a log file or a pipe gets plain text.
            fmt::layer()
                .compact()
                .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
                .with_writer(std::io::stderr)
                .with_filter(filter()),
        )
        .try_init()
        .context("starting the log")?;
    Ok(())
}

/// `zeroset teach` and `zeroset inspect`: starts the job and, unless detached, shows it live to its end. Returns
/// the inspection's verdict (`None` for a teach or a detached job); an abort or a stop is [`JobEnded`].
pub fn run_job(job: &JobArgs, request: Request) -> anyhow::Result<Option<Verdict>> {
    if let Request::Teach { part } | Request::Inspect { part, .. } = &request {
        // The daemon reads the part file too; reading it here first makes a broken one the configuration error
        // it is (exit code 3, with the file's own message), before anything is asked of the station.
        let config = StationConfig::load(&job.station.config)?;
        PartConfig::load(&config.part_path(part))?;
    }
    // Subscribed before the job starts, so that none of its events are missed.
    let events = if job.detach {
        None
    } else {
        Some(connect(&job.station)?.subscribe()?)
    };
    let reply = accepted(connect(&job.station)?.request(request)?)?;
    let Reply::Started { job: info } = reply else {
        anyhow::bail!("unexpected reply from the daemon: {reply:?}");
    };
    let Some(events) = events else {
        outln!("job {} started; follow it with `zeroset watch`", info.id)?;
        return Ok(None);
    };
    let end = follow(events, Some(info.id), false, Following::ToItsStop)?;
    ended(end)
}

/// An inspection's verdict as the command's outcome: a failing part is [`JobEnded::PartFailed`] (exit code 4).
pub fn judge(part: &str, serial: &str, verdict: Option<Verdict>) -> anyhow::Result<()> {
    match verdict {
        Some(failed @ Verdict::Fail { .. }) => Err(JobEnded::PartFailed(format!(
            "part {part} serial {serial}: FAIL, {}",
            failed.what_failed().unwrap_or_default()
        ))
        .into()),
        Some(Verdict::Pass) => outln!("part {part} serial {serial}: PASS"),
        None => Ok(()),
    }
}

/// `zeroset watch`.
pub fn watch(args: &WatchArgs) -> anyhow::Result<()> {
    let mut control = connect(&args.station)?;
    let status = match accepted(control.request(Request::Status)?)? {
        Reply::Status(status) => status,
        other => anyhow::bail!("unexpected reply from the daemon: {other:?}"),
    };
    let events = control.subscribe()?;
    if !args.events {
        print_status(&status)?;
    }
    let job = status.job.filter(|j| !j.state.is_over()).map(|j| j.job.id);
    if job.is_none() {
        let waiting = "no job is running; waiting for the next one (Ctrl-C to stop)";
        // With --events standard output holds event lines only.
        if args.events {
            eprintln!("{waiting}");
        } else {
            outln!("{waiting}")?;
        }
    }
    let following = if args.follow {
        Following::Forever
    } else {
        Following::ToItsEnd
    };
    follow(events, job, args.events, following).map(drop)
}

/// How long a command follows the daemon's events.
#[derive(Clone, Copy, PartialEq)]
enum Following {
    /// Until the job ends or stops on a fault: teach and inspect, whose exit code tells a script how it went.
    ToItsStop,
    /// Until the job ends, through stops and resumes: an operator watching clears a stop and keeps watching.
    ToItsEnd,
    /// Job after job (`watch --follow`).
    Forever,
}

fn follow(
    mut events: super::control::Events,
    job: Option<String>,
    raw: bool,
    following: Following,
) -> anyhow::Result<JobEnd> {
    let mut watch = Watch::new(job, raw);
    loop {
        let (event, line) = events.next()?;
        if raw {
            out!("{line}")?;
        }
        let end = match watch.show(&event)? {
            Some(JobEnd::Stopped { .. }) if following != Following::ToItsStop => None,
            end => end,
        };
        if let Some(end) = end {
            if following != Following::Forever {
                return Ok(end);
            }
        }
    }
}

fn ended(end: JobEnd) -> anyhow::Result<Option<Verdict>> {
    match end {
        JobEnd::Finished { verdict } => Ok(verdict),
        JobEnd::Aborted { job } => Err(JobEnded::Aborted(job).into()),
        JobEnd::Stopped {
            job,
            reason,
            next_step,
        } => Err(JobEnded::Stopped {
            job,
            reason,
            next_step,
        }
        .into()),
        JobEnd::Failed(error) => anyhow::bail!("the job failed: {error}"),
    }
}

pub fn status(args: &StatusArgs) -> anyhow::Result<()> {
    match accepted(connect(&args.station)?.request(Request::Status)?)? {
        Reply::Status(status) if args.json => {
            outln!("{}", serde_json::to_string_pretty(&status)?)
        }
        Reply::Status(status) => print_status(&status),
        other => anyhow::bail!("unexpected reply from the daemon: {other:?}"),
    }
}

fn kind_name(kind: JobKind) -> &'static str {
    match kind {
        JobKind::Teach => "teach",
        JobKind::Inspect => "inspect",
    }
}

fn print_status(status: &StationStatus) -> anyhow::Result<()> {
    outln!("station {}", status.station)?;
    for machine in &status.machines {
        outln!("  machine {}: {}", machine.name, machine.state)?;
    }
    if let Some(preparing) = &status.preparing {
        outln!(
            "  setting up: {} {}{}",
            kind_name(preparing.kind),
            preparing.part,
            preparing
                .serial
                .as_ref()
                .map_or(String::new(), |s| format!(" serial {s}"))
        )?;
    }
    match &status.job {
        Some(job) => {
            let phase = match &job.state {
                JobPhase::Stopped { .. } => "stopped".to_string(),
                JobPhase::Failed { .. } => "failed".to_string(),
                other => other.to_string(),
            };
            outln!(
                "  job {} ({} {}): {phase}, {}/{} profiles done",
                job.job.id,
                kind_name(job.job.kind),
                job.job.part,
                job.profiles_done,
                job.profiles_total
            )?;
            match &job.state {
                JobPhase::Stopped {
                    reason, next_step, ..
                } => outln!("  stopped: {reason}; {next_step}"),
                JobPhase::Failed { error } => outln!("  failed: {error}"),
                _ => Ok(()),
            }
        }
        None => outln!("  no job"),
    }
}

/// `zeroset abort` and `zeroset clear`: one request, its answer printed.
pub fn simple(station: &StationFile, request: Request) -> anyhow::Result<()> {
    match accepted(connect(station)?.request(request)?)? {
        Reply::Done { message } => outln!("{message}"),
        other => anyhow::bail!("unexpected reply from the daemon: {other:?}"),
    }
}

pub fn report(args: &ReportArgs) -> anyhow::Result<()> {
    let Some(serial) = &args.serial else {
        return history(args);
    };
    let request = Request::Report {
        serial: serial.clone(),
    };
    match accepted(connect(&args.station)?.request(request)?)? {
        Reply::Report { dir, summary } => {
            outln!("{summary}")?;
            outln!("report folder: {}", dir.display())?;
            for file in [
                crate::report::HTML_FILE,
                crate::report::QIF_FILE,
                crate::report::REPORT_FILE,
            ] {
                outln!("  {}", dir.join(file).display())?;
            }
            Ok(())
        }
        other => anyhow::bail!("unexpected reply from the daemon: {other:?}"),
    }
}

/// `--trend` and `--export`: read from the history's database directly (no daemon needed).
fn history(args: &ReportArgs) -> anyhow::Result<()> {
    use crate::report::{
        history_csv, parameter_trend, parameter_trend_text, trend, trend_text, write_trend_html,
        Store, STORE_FILE,
    };
    let config = StationConfig::load(&args.station.config)?;
    let store = Store::open(&config.folders.data.join(STORE_FILE))?;
    let history = store.profile_history(&args.part_type, args.last)?;
    anyhow::ensure!(
        !history.is_empty(),
        "no inspection of part type {} in the history yet; inspect parts with `zeroset inspect {} --serial SN`",
        args.part_type,
        args.part_type
    );
    if args.export.is_some() {
        return out!("{}", history_csv(&history));
    }
    let newest = history.last().expect("not empty");
    let (lower, upper) = (newest.lower_mm, newest.upper_mm);
    let parts = history
        .iter()
        .map(|r| (&r.serial, &r.finished))
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    outln!(
        "{} trend: the last {parts} {}",
        args.part_type,
        if parts == 1 {
            "inspection"
        } else {
            "inspections"
        }
    )?;
    let rows = trend(&history, lower, upper);
    out!("{}", trend_text(&rows, lower, upper))?;
    let parameters = parameter_trend(&store.parameter_history(&args.part_type, args.last)?);
    if !parameters.is_empty() {
        out!("{}", parameter_trend_text(&parameters))?;
    }
    let folder = config.folders.reports.join(&args.part_type);
    std::fs::create_dir_all(&folder)
        .with_context(|| format!("cannot create {}", folder.display()))?;
    let chart = write_trend_html(&folder, &args.part_type, &rows, &parameters, lower, upper)?;
    outln!("trend report, open in a browser: {}", chart.display())
}
