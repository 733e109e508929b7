//! The line a machine is reached on: a pseudo-terminal in raw mode (CR LF pass untouched) or a loopback
//! TCP port. A client may go away and come back: the pty's master stays open, so its slave path can be
//! reopened, and the TCP listener accepts the next connection. [`PtyLinks`] gives the pseudo-terminals fixed
//! paths (`--link-dir`), whatever /dev/pts numbers they got.

use std::io;
use std::os::fd::{AsFd, OwnedFd};
use std::path::{Path, PathBuf};
use std::time::Duration;

use nix::fcntl::{fcntl, FcntlArg, OFlag};
use nix::poll::{poll, PollFd, PollFlags, PollTimeout};
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
use tokio::io::unix::AsyncFd;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

/// How often a pty without a client is checked for one: Linux reports a master whose slave is closed as
/// hung up until the slave is opened again, and there is no event for the reopening.
const PTY_CHECK: Duration = Duration::from_millis(10);

/// What a read gave.
pub enum Read {
    Bytes(usize),
    /// The client closed its end.
    Closed,
}

/// A machine's line.
pub enum Link {
    Pty(Pty),
    Tcp {
        listener: TcpListener,
        stream: Option<TcpStream>,
    },
}

/// The master side of a pseudo-terminal.
pub struct Pty {
    /// Always there; an Option only so that it can be registered anew (see [`Pty::reregister`]).
    master: Option<AsyncFd<OwnedFd>>,
    path: String,
}

impl Link {
    /// A new pseudo-terminal whose slave is in raw mode (no echo, no CR/LF translation, 8 bits).
    pub fn pty() -> io::Result<Self> {
        let pair = nix::pty::openpty(None, None)?;
        let mut termios = tcgetattr(&pair.slave)?;
        cfmakeraw(&mut termios);
        tcsetattr(&pair.slave, SetArg::TCSANOW, &termios)?;
        let path = nix::unistd::ttyname(&pair.slave)?
            .to_string_lossy()
            .into_owned();
        let flags = OFlag::from_bits_truncate(fcntl(&pair.master, FcntlArg::F_GETFL)?);
        fcntl(&pair.master, FcntlArg::F_SETFL(flags | OFlag::O_NONBLOCK))?;
        // The slave closes here; the settings stay with the terminal for the client that opens it.
        drop(pair.slave);
        // SAFETY: an OwnedFd is an open descriptor that stays open and the same until the AsyncFd that
        // owns it drops it.
        let master = unsafe { AsyncFd::register(pair.master)? };
        Ok(Link::Pty(Pty {
            master: Some(master),
            path,
        }))
    }

    /// A listener on 127.0.0.1 (`port` 0: any free port).
    pub async fn tcp(port: u16) -> io::Result<Self> {
        let listener = TcpListener::bind(("127.0.0.1", port)).await?;
        Ok(Link::Tcp {
            listener,
            stream: None,
        })
    }

    /// What a client opens: the pty's slave path, or `tcp:127.0.0.1:PORT`.
    pub fn address(&self) -> io::Result<String> {
        match self {
            Link::Pty(pty) => Ok(pty.path.clone()),
            Link::Tcp { listener, .. } => Ok(format!("tcp:{}", listener.local_addr()?)),
        }
    }

    /// Waits until a client is there.
    pub async fn connected(&mut self) -> io::Result<()> {
        match self {
            Link::Pty(pty) => loop {
                if !pty.hung_up()? {
                    return pty.reregister();
                }
                tokio::time::sleep(PTY_CHECK).await;
            },
            Link::Tcp { listener, stream } => {
                if stream.is_none() {
                    let (accepted, _) = listener.accept().await?;
                    accepted.set_nodelay(true)?;
                    *stream = Some(accepted);
                }
                Ok(())
            }
        }
    }

    /// Reads what the client sent.
    pub async fn read(&mut self, buf: &mut bytes::BytesMut) -> io::Result<Read> {
        match self {
            Link::Pty(pty) => pty.read(buf).await,
            Link::Tcp { stream, .. } => {
                let Some(socket) = stream else {
                    return Ok(Read::Closed);
                };
                match socket.read_buf(buf).await? {
                    0 => {
                        *stream = None;
                        Ok(Read::Closed)
                    }
                    n => Ok(Read::Bytes(n)),
                }
            }
        }
    }

    /// Writes to the client; `false` if it is gone.
    pub async fn write(&mut self, bytes: &[u8]) -> io::Result<bool> {
        match self {
            Link::Pty(pty) => pty.write(bytes).await,
            Link::Tcp { stream, .. } => {
                let Some(socket) = stream else {
                    return Ok(false);
                };
                match socket.write_all(bytes).await {
                    Ok(()) => Ok(true),
                    Err(_) => {
                        *stream = None;
                        Ok(false)
                    }
                }
            }
        }
    }

    /// Drops the client: closes a TCP connection. A pty cannot close its client's end, so the caller goes
    /// deaf and mute instead.
    pub fn hang_up(&mut self) {
        if let Link::Tcp { stream, .. } = self {
            *stream = None;
        }
    }
}

/// Symbolic links DIR/NAME to machines' pseudo-terminals, so that a station file can name a fixed path. The
/// links this made are removed when it is dropped, unless something else has replaced them since.
#[derive(Debug, Default)]
pub struct PtyLinks {
    /// Each link made, with the pty path it points at.
    made: Vec<(PathBuf, PathBuf)>,
}

impl PtyLinks {
    /// Links `dir/machine` to `pty`, creating `dir` if missing. A symbolic link already there is taken as
    /// stale (left by a simulator that was killed) and replaced; anything else there is refused rather than
    /// overwritten. Errors name the path.
    pub fn link(&mut self, dir: &Path, machine: &str, pty: &str) -> io::Result<PathBuf> {
        let named = |e: io::Error, path: &Path| {
            io::Error::new(e.kind(), format!("{}: {e}", path.display()))
        };
        if machine.is_empty() || machine.contains('/') || machine == "." || machine == ".." {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("the machine name {machine:?} cannot be a file name in --link-dir"),
            ));
        }
        std::fs::create_dir_all(dir).map_err(|e| named(e, dir))?;
        let link = dir.join(machine);
        let occupied =
            std::fs::symlink_metadata(&link).is_ok_and(|found| !found.file_type().is_symlink());
        if occupied {
            return Err(io::Error::new(
                io::ErrorKind::AlreadyExists,
                format!(
                    "{} exists and is not a symbolic link; move it away",
                    link.display()
                ),
            ));
        }
        // Made beside it and renamed over it, so that a client never finds the path missing or half made.
        let fresh = dir.join(format!(".{machine}.link-{}", std::process::id()));
        let _ = std::fs::remove_file(&fresh);
        std::os::unix::fs::symlink(pty, &fresh).map_err(|e| named(e, &fresh))?;
        if let Err(e) = std::fs::rename(&fresh, &link) {
            let _ = std::fs::remove_file(&fresh);
            return Err(named(e, &link));
        }
        self.made.push((link.clone(), PathBuf::from(pty)));
        Ok(link)
    }
}

impl Drop for PtyLinks {
    fn drop(&mut self) {
        for (link, pty) in &self.made {
            // Best effort on the way out; a link another simulator has made since is its own.
            if std::fs::read_link(link).is_ok_and(|target| target == *pty) {
                let _ = std::fs::remove_file(link);
            }
        }
    }
}

impl Pty {
    fn master(&self) -> &AsyncFd<OwnedFd> {
        self.master.as_ref().expect("registered")
    }

    /// Registers the master with the reactor anew. Tokio keeps a hang-up it has seen as final ("read
    /// closed" stays ready), but a pty's hang-up ends when a client reopens the slave; without this the
    /// reads of the next client would spin.
    fn reregister(&mut self) -> io::Result<()> {
        let fd = self.master.take().expect("registered").into_inner();
        // SAFETY: as in `Link::pty`: the OwnedFd stays open and the same while the AsyncFd owns it.
        self.master = Some(unsafe { AsyncFd::register(fd)? });
        Ok(())
    }

    /// Whether no client has the slave open.
    fn hung_up(&self) -> io::Result<bool> {
        let mut fds = [PollFd::new(
            self.master().get_ref().as_fd(),
            PollFlags::POLLIN,
        )];
        poll(&mut fds, PollTimeout::ZERO)?;
        Ok(fds[0]
            .revents()
            .is_some_and(|events| events.contains(PollFlags::POLLHUP)))
    }

    async fn read(&mut self, buf: &mut bytes::BytesMut) -> io::Result<Read> {
        let mut chunk = [0u8; 4096];
        loop {
            let mut guard = self.master().readable().await?;
            // A hang-up seen by the reactor while the slave is open again means the client closed the
            // line and reopened it before this read: that is a disconnect too.
            if guard.ready().is_read_closed() {
                return Ok(Read::Closed);
            }
            match guard.try_io(|fd| Ok(nix::unistd::read(fd.get_ref(), &mut chunk)?)) {
                Ok(Ok(0)) => return Ok(Read::Closed),
                Ok(Ok(n)) => {
                    buf.extend_from_slice(&chunk[..n]);
                    return Ok(Read::Bytes(n));
                }
                // Linux: EIO once the last client closed the slave.
                Ok(Err(e)) if e.raw_os_error() == Some(nix::libc::EIO) => return Ok(Read::Closed),
                Ok(Err(e)) => return Err(e),
                Err(_would_block) => continue,
            }
        }
    }

    async fn write(&mut self, mut bytes: &[u8]) -> io::Result<bool> {
        while !bytes.is_empty() {
            let mut guard = self.master().writable().await?;
            match guard.try_io(|fd| Ok(nix::unistd::write(fd.get_ref(), bytes)?)) {
                Ok(Ok(n)) => bytes = &bytes[n..],
                Ok(Err(e)) if e.raw_os_error() == Some(nix::libc::EIO) => return Ok(false),
                Ok(Err(e)) => return Err(e),
                Err(_would_block) => continue,
            }
        }
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_link_replaces_a_stale_one_and_goes_when_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let ports = dir.path().join("ports");
        std::fs::create_dir(&ports).unwrap();
        std::os::unix::fs::symlink("/dev/pts/no-such-terminal", ports.join("cmm1")).unwrap();
        let mut links = PtyLinks::default();
        let link = links.link(&ports, "cmm1", "/dev/null").unwrap();
        assert_eq!(link, ports.join("cmm1"));
        assert_eq!(
            std::fs::read_link(&link).unwrap(),
            PathBuf::from("/dev/null")
        );
        let names: Vec<_> = std::fs::read_dir(&ports)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["cmm1"], "no temporary link left behind");
        drop(links);
        assert!(
            std::fs::symlink_metadata(&link).is_err(),
            "the link is removed"
        );
    }

    #[test]
    fn the_folder_is_made_and_a_link_made_since_by_another_is_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let ports = dir.path().join("a/b");
        let mut links = PtyLinks::default();
        let link = links.link(&ports, "cmm2", "/dev/null").unwrap();
        std::fs::remove_file(&link).unwrap();
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        drop(links);
        assert_eq!(
            std::fs::read_link(&link).unwrap(),
            PathBuf::from("/dev/zero")
        );
    }

    #[test]
    fn a_file_in_the_way_and_a_name_with_a_slash_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("cmm1"), "notes").unwrap();
        let mut links = PtyLinks::default();
        let error = links
            .link(dir.path(), "cmm1", "/dev/null")
            .unwrap_err()
            .to_string();
        assert!(error.contains("is not a symbolic link"), "{error}");
        assert_eq!(
            std::fs::read_to_string(dir.path().join("cmm1")).unwrap(),
            "notes"
        );
        let error = links
            .link(dir.path(), "../cmm1", "/dev/null")
            .unwrap_err()
            .to_string();
        assert!(error.contains("cannot be a file name"), "{error}");
    }
}
