//! What a machine reports outside the commands' results.

use crate::wire::{Data, DeviceError, LineError, Response};

use super::TransportError;

/// Something the operator or the station should know about, published to every subscriber.
#[derive(Debug, Clone)]
pub enum Event {
    /// An unsolicited error (`E0000 !`), such as an emergency stop (0500). From severity 2 up, motion
    /// is locked out until clear all errors succeeds.
    Unsolicited(DeviceError),
    /// Unsolicited data (`E0000 #`), such as a key pressed on the machine's panel.
    UnsolicitedData(Data),
    /// An info or warning (`!` of severity 0 or 1, e.g. 0504 "Argument out of range"); the command
    /// goes on.
    Warning { command: String, error: DeviceError },
    /// A garbled line; every transaction in progress failed with `TransportError::BadLine`.
    BadLine(LineError),
    /// A reply that belongs to no transaction the client knows of.
    Stray(Response),
    /// The link failed or closed; this client can send nothing more.
    Disconnected(TransportError),
}
