//! The links a client runs over. All carry the same bytes; [`crate::client::Client::new`] takes any of
//! them.

use std::io;

use tokio::net::{TcpStream, ToSocketAddrs};
use tokio_serial::{DataBits, FlowControl, Parity, SerialPortBuilderExt, SerialStream, StopBits};

/// The TCP port I++ DME servers listen on (spec 9.2).
pub const IPP_DME_PORT: u16 = 1294;

/// A serial line to a controller.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SerialConfig {
    /// The device, e.g. `/dev/ttyUSB0`.
    pub path: String,
    /// Bits per second, e.g. 115200.
    pub baud: u32,
}

/// Connects to an I++ server, e.g. `("cmm1.local", IPP_DME_PORT)`.
pub async fn connect_tcp(address: impl ToSocketAddrs) -> io::Result<TcpStream> {
    let stream = TcpStream::connect(address).await?;
    // Commands are short lines that each wait for an answer; Nagle's delay would only add latency.
    stream.set_nodelay(true)?;
    Ok(stream)
}

/// Opens a serial line: 8 data bits, no parity, 1 stop bit, no flow control, raw mode, and exclusive,
/// so that no other program interleaves bytes on the line.
pub fn open_serial(config: &SerialConfig) -> io::Result<SerialStream> {
    open(&config.path, config.baud, true)
}

/// Opens the slave side of a pseudo-terminal (`/dev/pts/N`, as the simulator prints it) as a serial
/// line in raw mode, so that CR LF pass untouched. Not exclusive: TIOCEXCL would outlive this client
/// while the simulator holds the terminal open, and a reconnect to the same path would then fail.
pub fn open_pty(path: &str) -> io::Result<SerialStream> {
    // A pseudo-terminal ignores the baud rate, but the termios call needs one.
    open(path, 115_200, false)
}

fn open(path: &str, baud: u32, exclusive: bool) -> io::Result<SerialStream> {
    let port = tokio_serial::new(path, baud)
        .data_bits(DataBits::Eight)
        .parity(Parity::None)
        .stop_bits(StopBits::One)
        .flow_control(FlowControl::None)
        .exclusive(exclusive)
        .open_native_async()?;
    Ok(port)
}
