//! zeroset-drivers: the I++ DME protocol codec, the `Machine` trait and the serial and TCP transports.
//!
//! - [`wire`]: the typed lines of I++ DME 1.4.3 (commands and responses) with their exact text form;
//! - [`codec`]: frames them on a byte stream for tokio;
//! - [`machine`]: the [`Machine`](machine::Machine) trait the station drives, its values and errors;
//! - [`client`]: the I++ client implementing it over any byte stream;
//! - [`transport`]: opening TCP, serial and pseudo-terminal links.
//!
//! `fuzz` holds the bodies of the fuzz targets (hidden; see its comment).

pub mod client;
pub mod codec;
#[doc(hidden)]
pub mod fuzz;
pub mod machine;
pub mod transport;
pub mod wire;
