//! How a command ends for the shell, a script or a PLC: its exit code, and its error printed once. The codes are
//! listed in `zeroset --help` ([`EXIT_CODES`]) and in the README, which a test keeps identical.

use std::fmt;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

/// The exit codes, as `zeroset --help` lists them after the commands.
pub const EXIT_CODES: &str = "\
Exit codes:
  0    done; for teach and inspect: the job ran to its end and (inspect) the part is within its tolerance
  1    the command failed (the daemon refused it, a file could not be read, the daemon could not be reached)
  2    usage: an unknown command or option, or an option's value out of range
  3    configuration: the station file, a part file or a simulator file cannot be read or is invalid
  4    inspect: the part was measured and is outside its tolerance (the report is written)
  5    teach or inspect: the job was aborted (`zeroset abort`)
  6    teach or inspect: the job stopped on a fault and waits for `zeroset clear`; follow it with `zeroset watch`
  141  standard output was closed (`| head`): output stops quietly; fit, deviate, evaluate, mesh, sweep still write files";

const FAILED: u8 = 1;
const CONFIGURATION: u8 = 3;
const PART_FAILED: u8 = 4;
const ABORTED: u8 = 5;
const STOPPED: u8 = 6;
/// What a shell reports for a program killed by SIGPIPE (128 + 13): the code of every tool cut off by `| head`.
const OUTPUT_CLOSED: u8 = 141;

/// A followed job that did not end with a pass.
#[derive(Debug, thiserror::Error)]
pub enum JobEnded {
    /// The inspection ran to its end and the part is outside its tolerance.
    #[error("{0}")]
    PartFailed(String),
    #[error("job {0} was aborted")]
    Aborted(String),
    #[error("job {job} stopped: {reason}; next: {next_step} (`zeroset watch` follows it)")]
    Stopped {
        job: String,
        reason: String,
        next_step: String,
    },
}

/// Standard output was closed by its reader: not a fault of the command, which stops writing.
#[derive(Debug, thiserror::Error)]
#[error("standard output was closed")]
pub struct OutputClosed;

/// Writes to standard output; a closed pipe is [`OutputClosed`] (`println!` would panic on it).
pub(crate) fn write_out(text: fmt::Arguments) -> anyhow::Result<()> {
    match std::io::stdout().lock().write_fmt(text) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(OutputClosed.into()),
        Err(e) => Err(anyhow::Error::new(e).context("cannot write to standard output")),
    }
}

/// Set once a [`write_report`] found standard output closed.
static REPORT_CUT_OFF: AtomicBool = AtomicBool::new(false);

/// Writes a line of a command whose result is a file (a model, deviations, a mesh): a closed standard output does
/// not stop the work, which would lose the file (`zeroset fit ip ... | head -3`); [`report_cut_off`] ends the
/// command as cut off once its files are written.
pub(crate) fn write_report(text: fmt::Arguments) -> anyhow::Result<()> {
    match write_out(text) {
        Err(e) if e.is::<OutputClosed>() => {
            REPORT_CUT_OFF.store(true, Ordering::Relaxed);
            Ok(())
        }
        written => written,
    }
}

/// [`OutputClosed`] if a report line could not be written: the command's code is then 141, as for any tool whose
/// reader went away.
pub(crate) fn report_cut_off() -> anyhow::Result<()> {
    if REPORT_CUT_OFF.load(Ordering::Relaxed) {
        Err(OutputClosed.into())
    } else {
        Ok(())
    }
}

/// The exit code of a command that ended with `error`.
pub fn exit_code(error: &anyhow::Error) -> u8 {
    for cause in error.chain() {
        if cause.is::<OutputClosed>() {
            return OUTPUT_CLOSED;
        }
        if let Some(ended) = cause.downcast_ref::<JobEnded>() {
            return match ended {
                JobEnded::PartFailed(_) => PART_FAILED,
                JobEnded::Aborted(_) => ABORTED,
                JobEnded::Stopped { .. } => STOPPED,
            };
        }
        if cause.is::<crate::config::ConfigError>()
            || cause.is::<zeroset_sim::config::ConfigError>()
        {
            return CONFIGURATION;
        }
    }
    FAILED
}

/// What to print on standard error for `error` (nothing when standard output was closed): one line, each cause
/// once. Errors whose message already shows their source (`"{path}: {source}"`) would otherwise print the source
/// twice, as anyhow's `{:#}` appends every source.
pub fn error_text(error: &anyhow::Error) -> Option<String> {
    if error.chain().any(|c| c.is::<OutputClosed>()) {
        return None;
    }
    let mut text = String::new();
    for cause in error.chain() {
        let part = cause.to_string();
        if text.contains(&part) {
            continue;
        }
        if !text.is_empty() {
            text.push_str(": ");
        }
        text.push_str(&part);
    }
    // A failing part is the inspection's result, not an error of the command.
    let result = error
        .chain()
        .any(|c| matches!(c.downcast_ref(), Some(JobEnded::PartFailed(_))));
    Some(if result {
        text
    } else {
        format!("error: {text}")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_configuration_error_prints_toml_s_report_once_and_exits_3() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("station.toml");
        std::fs::write(&path, "bogus = 1\n").unwrap();
        let error = anyhow::Error::new(crate::config::StationConfig::load(&path).unwrap_err());
        let text = error_text(&error).unwrap();
        assert_eq!(text.matches("unknown field `bogus`").count(), 1, "{text}");
        assert!(text.starts_with(&format!("error: {}: TOML parse error", path.display())));
        assert_eq!(exit_code(&error), CONFIGURATION);
        // Under a context the configuration error still decides the code, and each part shows once.
        let missing =
            crate::config::StationConfig::load(&dir.path().join("none.toml")).unwrap_err();
        let error = anyhow::Error::new(missing).context("starting the daemon");
        let text = error_text(&error).unwrap();
        assert_eq!(text.matches("No such file").count(), 1, "{text}");
        assert!(text.starts_with("error: starting the daemon: "), "{text}");
        assert_eq!(exit_code(&error), CONFIGURATION);
    }

    #[test]
    fn each_ending_has_its_code() {
        let code = |e: JobEnded| exit_code(&anyhow::Error::new(e));
        assert_eq!(code(JobEnded::PartFailed("p".into())), PART_FAILED);
        assert_eq!(code(JobEnded::Aborted("j".into())), ABORTED);
        let stopped = JobEnded::Stopped {
            job: "j".into(),
            reason: "r".into(),
            next_step: "n".into(),
        };
        assert_eq!(code(stopped), STOPPED);
        assert_eq!(exit_code(&anyhow::anyhow!("no daemon")), FAILED);
        let closed = anyhow::Error::new(OutputClosed).context("writing the trend");
        assert_eq!(exit_code(&closed), OUTPUT_CLOSED);
        assert_eq!(error_text(&closed), None);
        // The part's verdict is printed as it is; every other ending as an error.
        let failed = anyhow::Error::new(JobEnded::PartFailed("part p FAILS".into()));
        assert_eq!(error_text(&failed).unwrap(), "part p FAILS");
        let aborted = anyhow::Error::new(JobEnded::Aborted("j".into()));
        assert_eq!(error_text(&aborted).unwrap(), "error: job j was aborted");
    }

    #[test]
    fn the_listed_codes_are_the_codes() {
        for code in [
            0,
            FAILED,
            2, // usage errors: clap exits with it before a command runs
            CONFIGURATION,
            PART_FAILED,
            ABORTED,
            STOPPED,
            OUTPUT_CLOSED,
        ] {
            let listed = format!("\n  {code:<4} ");
            assert!(EXIT_CODES.contains(&listed), "code {code} is not listed");
        }
    }
}
