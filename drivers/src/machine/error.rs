//! Why a machine operation failed. The three causes are kept apart because they call for different
//! actions: the machine refused or failed (read its error, clear it), the link failed (check the cable or
//! the server, reconnect), or this client refused to send motion while the machine is in an error state.

use std::fmt;
use std::io;
use std::sync::Arc;
use std::time::Duration;

use crate::wire::{DeviceError, LineError, WireError};

/// A failed operation: which machine, which command, and why.
#[derive(Debug, Clone, thiserror::Error)]
#[error("machine {machine}: {command}: {kind}")]
pub struct Error {
    machine: Arc<str>,
    command: String,
    kind: ErrorKind,
}

/// Why an operation failed.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ErrorKind {
    /// The machine answered with an `!` error line of severity 2 or more.
    #[error("the machine reported {}", Reported(.0))]
    Device(DeviceError),
    /// The link to the machine failed; the machine may not have seen or answered the command.
    #[error(transparent)]
    Transport(TransportError),
    /// Not sent: motion is refused after an error of severity 2 or more, an emergency stop or an
    /// abort, until `ClearAllErrors` succeeds.
    #[error(
        "not sent: motion is locked out since {cause}; remove the cause, then clear all errors"
    )]
    LockedOut { cause: String },
    /// An argument cannot be written on the wire (not finite, an empty or non-ASCII tool name).
    #[error("cannot be sent: {0}")]
    InvalidArgument(WireError),
}

/// A fault of the link rather than of the machine.
#[derive(Debug, Clone, thiserror::Error)]
pub enum TransportError {
    #[error("I/O error on the link: {0}")]
    Io(Arc<io::Error>),
    #[error("no {awaited} within {}s; check that the machine is powered and connected", .after.as_secs_f64())]
    Timeout {
        awaited: &'static str,
        after: Duration,
    },
    #[error("garbled line from the machine, so its replies cannot be trusted: {0}")]
    BadLine(LineError),
    #[error("reply not as the protocol defines it: {0}")]
    BadReply(String),
    #[error("the link to the machine is closed")]
    Disconnected,
}

impl Error {
    /// An error of `machine`'s `command`: public so that drivers behind the trait, and fakes of it in tests, say
    /// what failed the same way the I++ client does.
    pub fn new(machine: Arc<str>, command: String, kind: ErrorKind) -> Self {
        Error {
            machine,
            command,
            kind,
        }
    }

    /// The machine's name, as given to the client.
    pub fn machine(&self) -> &str {
        &self.machine
    }

    /// The command that failed, without its tag (long argument lists shortened).
    pub fn command(&self) -> &str {
        &self.command
    }

    /// Why it failed.
    pub fn kind(&self) -> &ErrorKind {
        &self.kind
    }

    /// The machine's own error, if that is why it failed.
    pub fn device_error(&self) -> Option<&DeviceError> {
        match &self.kind {
            ErrorKind::Device(error) => Some(error),
            _ => None,
        }
    }

    /// The link fault, if that is why it failed.
    pub fn transport_error(&self) -> Option<&TransportError> {
        match &self.kind {
            ErrorKind::Transport(error) => Some(error),
            _ => None,
        }
    }
}

impl From<io::Error> for TransportError {
    fn from(error: io::Error) -> Self {
        TransportError::Io(Arc::new(error))
    }
}

/// A device error as an operator reads it: code, severity, the spec's text, and the next step.
struct Reported<'a>(&'a DeviceError);

impl fmt::Display for Reported<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Only errors of severity 2 or more fail an operation, and all of them lock out motion.
        let error = self.0;
        write!(
            f,
            "error {:04} (severity {}): {}; motion stays locked out until clear all errors succeeds",
            error.code(),
            error.severity(),
            error.text()
        )
    }
}
