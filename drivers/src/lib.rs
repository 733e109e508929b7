//! zeroset-drivers: the I++ DME protocol codec, the `Machine` trait and the serial and TCP transports.
//!
//! So far the wire layer: [`wire`] holds the typed lines of I++ DME 1.4.3 (commands and responses) with
//! their exact text form, and [`codec`] frames them on a byte stream for tokio.

pub mod codec;
pub mod wire;
