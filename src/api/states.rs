//! The states of machines and jobs as the daemon holds them and the CLI shows them: typed, so that no reader
//! compares free text, and a fault keeps its kind (a lost link is not a collision) all the way to the operator.

use std::fmt;

use serde::{Deserialize, Serialize};

use super::ScanRef;

/// Where a machine is, as the daemon sees it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "state", rename_all = "snake_case")]
pub enum MachineState {
    /// The daemon has not yet opened its line and read its state: until it has, it is not called idle (an
    /// emergency stop pressed before the daemon opened the line is cleared by the session's start, as the I++
    /// spec's StartSession clears all errors, so "idle" before a look would be a guess). A job may start; its
    /// scans wait for the look.
    Unseen,
    /// Ready for the next scan.
    Idle,
    Scanning {
        scan: ScanRef,
    },
    /// `zeroset clear` is clearing its errors and taking the probe clear of the part.
    Clearing,
    /// Motion is locked out until an operator's `zeroset clear` succeeds.
    LockedOut {
        fault: MachineFault,
    },
}

/// Why a machine stopped: its kind, and the whole message for the operator (machine, command, what to do).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MachineFault {
    pub kind: FaultKind,
    pub message: String,
}

/// The kinds of fault, kept apart because each calls for a different action.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FaultKind {
    /// The machine reported an error (an emergency stop is 0500, a collision 2504, no touch 1003).
    Device { severity: u8, code: u16 },
    /// The link failed: timeout, garbled or missing replies, a closed line.
    Transport,
    /// The machine's port cannot be opened: missing, or held by another program.
    PortMissing,
    /// The driver refused to send motion while the machine was in an error state.
    LockedOut,
    /// The operator aborted: motion was stopped on purpose.
    Aborted,
    /// The station refused to move: it cannot prove the move safe (no known way out, a tool it does not accept).
    Refused,
    /// The job's analysis or recording stopped under the scan.
    Station,
    /// The scan ended well but has a hole (a line of points lost on the way): not a fault of the machine, which
    /// stays ready; the profile is scanned again.
    Gap,
}

/// Where a job is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "phase", rename_all = "snake_case")]
pub enum JobPhase {
    /// Its machines are scanning.
    Running,
    /// Stopped by a fault; waits for `zeroset clear`.
    Stopped {
        machine: Option<String>,
        scan: Option<ScanRef>,
        reason: String,
        next_step: String,
    },
    /// The operator aborted: waiting for the scanning machines to stop.
    Aborting,
    /// Every profile is on disk: fitting the reference or writing the report.
    Finishing,
    Finished,
    Aborted,
    Failed {
        error: String,
    },
}

impl JobPhase {
    /// Finished, aborted or failed: nothing more happens to the job.
    pub fn is_over(&self) -> bool {
        matches!(self, Self::Finished | Self::Aborted | Self::Failed { .. })
    }
}

impl fmt::Display for JobPhase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Running => f.write_str("running"),
            Self::Stopped {
                reason, next_step, ..
            } => write!(f, "stopped: {reason}; {next_step}"),
            Self::Aborting => f.write_str("aborting"),
            Self::Finishing => f.write_str("finishing"),
            Self::Finished => f.write_str("finished"),
            Self::Aborted => f.write_str("aborted"),
            Self::Failed { error } => write!(f, "failed: {error}"),
        }
    }
}

impl fmt::Display for MachineState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Unseen => f.write_str("not seen yet (opening its line and reading its state)"),
            Self::Idle => f.write_str("idle"),
            Self::Scanning { scan } => {
                write!(
                    f,
                    "scanning instance {}, profile {}",
                    scan.instance, scan.profile
                )
            }
            Self::Clearing => f.write_str("clearing"),
            Self::LockedOut { fault } => write!(
                f,
                "locked out ({}): {}; remove the cause, then run `zeroset clear`",
                fault.kind, fault.message
            ),
        }
    }
}

impl fmt::Display for FaultKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Device { severity, code } => match code {
                500 => f.write_str("emergency stop"),
                2504 => f.write_str("collision"),
                _ => write!(f, "alarm {code:04}, severity {severity}"),
            },
            Self::Transport => f.write_str("disconnected"),
            Self::PortMissing => f.write_str("port missing"),
            Self::LockedOut => f.write_str("motion locked out"),
            Self::Aborted => f.write_str("aborted by the operator"),
            Self::Refused => f.write_str("the station refused to move"),
            Self::Station => f.write_str("station fault"),
            Self::Gap => f.write_str("a gap in the scan"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn states_are_tagged_and_round_trip() {
        let state = MachineState::LockedOut {
            fault: MachineFault {
                kind: FaultKind::Device {
                    severity: 3,
                    code: 500,
                },
                message: "machine cmm1: emergency stop".into(),
            },
        };
        let text = serde_json::to_string(&state).unwrap();
        assert_eq!(
            text,
            r#"{"state":"locked_out","fault":{"kind":{"kind":"device","severity":3,"code":500},"message":"machine cmm1: emergency stop"}}"#
        );
        assert_eq!(serde_json::from_str::<MachineState>(&text).unwrap(), state);
        assert!(state.to_string().starts_with("locked out (emergency stop)"));
        let phase = JobPhase::Failed {
            error: "no fit".into(),
        };
        let text = serde_json::to_string(&phase).unwrap();
        assert_eq!(text, r#"{"phase":"failed","error":"no fit"}"#);
        assert!(phase.is_over() && !JobPhase::Finishing.is_over());
    }
}
