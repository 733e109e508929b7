//! What a command means to the client's bookkeeping, from its name (spec 6.3).

use crate::wire::{Arg, Call, Tag};

/// How a command affects the client's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    /// Moves the machine: refused while motion is locked out.
    Motion,
    /// `ClearAllErrors`, and `StartSession` which "implicitly executes ClearAllErrors()": success lifts
    /// the lockout.
    ClearsErrors,
    /// `AbortE`: nothing else may be sent until it completes, and motion is locked out after it.
    Abort,
    /// `OnMoveReportE`: after completing, its tag keeps carrying data lines.
    StartsDaemon,
    /// `StopDaemon(tag)`: the daemon's data stops after this completes.
    StopsDaemon(Tag),
    /// `EndSession`: stops every daemon.
    EndsSession,
    Other,
}

impl Role {
    pub(crate) fn of(call: &Call) -> Role {
        match call.name.as_str() {
            // Spec 6.3.2.4: the commands that move the machine (and so imply DisableUser).
            "Home" | "GoTo" | "PtMeas" | "ChangeTool" | "AlignTool" | "AlignPart"
            | "CenterPart" | "TiltPart" | "TiltCenterPart" | "ScanOnCircle" | "ScanOnLine"
            | "ScanOnCurve" => Role::Motion,
            name if name.starts_with("ScanIn") => Role::Motion,
            "ClearAllErrors" | "StartSession" => Role::ClearsErrors,
            "AbortE" => Role::Abort,
            "OnMoveReportE" => Role::StartsDaemon,
            "StopDaemon" => match call.args[..] {
                [Arg::EventTag(daemon)] => Role::StopsDaemon(Tag::Event(daemon)),
                _ => Role::Other,
            },
            "EndSession" => Role::EndsSession,
            _ => Role::Other,
        }
    }
}

/// Fast-queue commands (names ending in `E`, spec 6.2.1) take event tags and jump the queue.
pub(crate) fn is_fast(call: &Call) -> bool {
    call.name.as_str().ends_with('E')
}
