//! The CLI's side of the control socket: a blocking client, since each command does one thing at a time.

use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};

use anyhow::Context;

use crate::api::{parse_line, to_line, Event, EventLine, Reply, ReplyLine, Request, RequestLine};

/// A connection to the daemon.
pub struct Control {
    socket: PathBuf,
    write: UnixStream,
    read: BufReader<UnixStream>,
}

impl Control {
    pub fn connect(socket: &Path) -> anyhow::Result<Control> {
        let write = UnixStream::connect(socket).with_context(|| {
            format!(
                "cannot reach the zeroset daemon at {}; start it with `zeroset daemon --config FILE` (the same station file)",
                socket.display()
            )
        })?;
        let read = BufReader::new(write.try_clone()?);
        Ok(Control {
            socket: socket.to_path_buf(),
            write,
            read,
        })
    }

    /// Sends a request and reads its reply.
    pub fn request(&mut self, request: Request) -> anyhow::Result<Reply> {
        self.write
            .write_all(to_line(&RequestLine::new(request)).as_bytes())
            .with_context(|| format!("the daemon at {} hung up", self.socket.display()))?;
        let line = self.next_line()?;
        Ok(parse_line::<ReplyLine>(&line)?.reply)
    }

    /// Turns this connection into the daemon's event stream.
    pub fn subscribe(mut self) -> anyhow::Result<Events> {
        match self.request(Request::Subscribe)? {
            Reply::Subscribed => Ok(Events { control: self }),
            other => anyhow::bail!("the daemon refused to stream events: {other:?}"),
        }
    }

    fn next_line(&mut self) -> anyhow::Result<String> {
        let mut line = String::new();
        let read = self
            .read
            .read_line(&mut line)
            .with_context(|| format!("reading from the daemon at {}", self.socket.display()))?;
        anyhow::ensure!(
            read > 0,
            "the daemon at {} closed the connection (it stopped?); check its log",
            self.socket.display()
        );
        Ok(line)
    }
}

/// The daemon's events, as they happen.
pub struct Events {
    control: Control,
}

impl Events {
    /// The next event, and the line it came as.
    pub fn next(&mut self) -> anyhow::Result<(Event, String)> {
        let line = self.control.next_line()?;
        let event = parse_line::<EventLine>(&line)?.event;
        Ok((event, line))
    }
}

/// The reply's error as an error of the command, anything else as it is.
pub fn accepted(reply: Reply) -> anyhow::Result<Reply> {
    match reply {
        Reply::Error { message } => anyhow::bail!("{message}"),
        other => Ok(other),
    }
}
