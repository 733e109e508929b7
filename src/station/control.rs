//! The control socket: a Unix domain socket that only the operators' group may use (mode 0660), one task per
//! connection. Requests go to the daemon's state task and their replies come back; a subscription turns the
//! connection into a stream of events, and a watcher that falls behind is told how many it missed rather than
//! slowing the station down. A request line is read up to [`MAX_REQUEST_LINE_BYTES`]: a longer one, or one that
//! is not UTF-8, is answered with an error and skipped, and the connection goes on with the next line.

use std::os::unix::fs::PermissionsExt;
use std::path::Path;

use tokio::io::{AsyncRead, AsyncReadExt, AsyncWriteExt};
use tokio::net::{UnixListener, UnixStream};
use tokio::sync::{broadcast, mpsc, oneshot};
use tokio_util::bytes::BytesMut;
use tokio_util::codec::{Decoder, LinesCodec, LinesCodecError};

use super::DaemonMsg;
use crate::api::{parse_line, to_line, Event, EventLine, Reply, ReplyLine, Request, RequestLine};

/// Binds the socket, refusing to take over one that another daemon still answers on.
pub fn bind(path: &Path) -> anyhow::Result<UnixListener> {
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", parent.display()))?;
    }
    if path.exists() {
        if std::os::unix::net::UnixStream::connect(path).is_ok() {
            anyhow::bail!(
                "another zeroset daemon is listening on {}; stop it first (one daemon drives a station's machines)",
                path.display()
            );
        }
        // Left by a daemon that was killed: nobody answers on it.
        std::fs::remove_file(path).map_err(|e| {
            anyhow::anyhow!("cannot remove the stale socket {}: {e}", path.display())
        })?;
    }
    let listener = UnixListener::bind(path)
        .map_err(|e| anyhow::anyhow!("cannot listen on {}: {e}", path.display()))?;
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o660))
        .map_err(|e| anyhow::anyhow!("cannot set the mode of {}: {e}", path.display()))?;
    Ok(listener)
}

pub async fn serve(
    listener: UnixListener,
    daemon: mpsc::Sender<DaemonMsg>,
    events: broadcast::Sender<Event>,
) {
    loop {
        match listener.accept().await {
            Ok((stream, _)) => {
                tokio::spawn(connection(stream, daemon.clone(), events.clone()));
            }
            Err(error) => tracing::warn!(%error, "control socket accept failed"),
        }
    }
}

async fn connection(
    stream: UnixStream,
    daemon: mpsc::Sender<DaemonMsg>,
    events: broadcast::Sender<Event>,
) {
    let (read, mut write) = stream.into_split();
    let mut lines = RequestLines::new(read);
    while let Some(line) = lines.next().await {
        let parsed = match line {
            Ok(line) => parse_line::<RequestLine>(&line).map_err(|error| error.to_string()),
            Err(refused) => Err(refused.to_string()),
        };
        let request = match parsed {
            Ok(line) => line.request,
            Err(message) => {
                let reply = Reply::Error { message };
                if send(&mut write, &ReplyLine::new(reply)).await.is_err() {
                    return;
                }
                continue;
            }
        };
        if request == Request::Subscribe {
            // Subscribed before answering, so nothing that happens after the answer is missed.
            let receiver = events.subscribe();
            if send(&mut write, &ReplyLine::new(Reply::Subscribed))
                .await
                .is_ok()
            {
                stream_events(receiver, &mut write).await;
            }
            return;
        }
        let (reply, answer) = oneshot::channel();
        if daemon
            .send(DaemonMsg::Request { request, reply })
            .await
            .is_err()
        {
            return;
        }
        let reply = answer.await.unwrap_or(Reply::Error {
            message: "the daemon is stopping".into(),
        });
        if send(&mut write, &ReplyLine::new(reply)).await.is_err() {
            return;
        }
    }
}

/// The longest request line read, in bytes without its newline. A request is a few hundred bytes; a line
/// longer than this comes from a broken or hostile client, and read whole it would sit in memory (a 100 MB line
/// once took the daemon to 580 MB).
pub(crate) const MAX_REQUEST_LINE_BYTES: usize = 1 << 20;

/// Why a line read from the socket is not a request, said without echoing it.
#[derive(Debug, thiserror::Error)]
enum LineRefused {
    #[error(
        "request line refused: longer than {MAX_REQUEST_LINE_BYTES} bytes (1 MiB); its rest is skipped up to \
         the next newline. Send each request as one line of JSON"
    )]
    TooLong,
    #[error("request line refused: it is not UTF-8 text. Send each request as one line of JSON")]
    NotUtf8,
}

/// A connection's request lines, each at most [`MAX_REQUEST_LINE_BYTES`] long.
///
/// A longer line is refused once the limit is passed, and what follows of it is dropped as it arrives up to its
/// newline; the connection then reads on. Skipping rather than closing keeps one reply per line sent, so a
/// client that sent requests after the bad line still gets their answers in order, and the skipped bytes are
/// never held: memory stays within the limit and one read.
struct RequestLines<R> {
    read: R,
    codec: LinesCodec,
    buffer: BytesMut,
    eof: bool,
}

/// Bytes asked of the socket per read.
const READ_CHUNK: usize = 8 * 1024;

impl<R: AsyncRead + Unpin> RequestLines<R> {
    fn new(read: R) -> Self {
        RequestLines {
            read,
            codec: LinesCodec::new_with_max_length(MAX_REQUEST_LINE_BYTES),
            buffer: BytesMut::new(),
            eof: false,
        }
    }

    /// The next line, or why it was refused; `None` once the client closed its end or the socket failed.
    async fn next(&mut self) -> Option<Result<String, LineRefused>> {
        loop {
            let decoded = if self.eof {
                self.codec.decode_eof(&mut self.buffer)
            } else {
                self.codec.decode(&mut self.buffer)
            };
            match decoded {
                Ok(Some(line)) => return Some(Ok(line)),
                Ok(None) if self.eof => return None,
                Ok(None) => {}
                Err(LinesCodecError::MaxLineLengthExceeded) => {
                    return Some(Err(LineRefused::TooLong))
                }
                // The codec reads nothing itself: its only I/O error is a line that is not UTF-8, already
                // taken out of the buffer.
                Err(LinesCodecError::Io(_)) => return Some(Err(LineRefused::NotUtf8)),
            }
            self.buffer.reserve(READ_CHUNK);
            match self.read.read_buf(&mut self.buffer).await {
                Ok(0) => self.eof = true,
                Ok(_) => {}
                Err(_) => return None,
            }
        }
    }
}

async fn stream_events(
    mut receiver: broadcast::Receiver<Event>,
    write: &mut tokio::net::unix::OwnedWriteHalf,
) {
    loop {
        let event = match receiver.recv().await {
            Ok(event) => event,
            Err(broadcast::error::RecvError::Lagged(missed)) => Event::Lagged { missed },
            Err(broadcast::error::RecvError::Closed) => return,
        };
        if send(write, &EventLine::new(event)).await.is_err() {
            return;
        }
    }
}

async fn send<T: serde::Serialize>(
    write: &mut tokio::net::unix::OwnedWriteHalf,
    line: &T,
) -> std::io::Result<()> {
    write.write_all(to_line(line).as_bytes()).await
}

#[cfg(test)]
mod tests {
    use tokio::io::{AsyncBufReadExt, BufReader};

    use super::*;

    /// A request line of `bytes` bytes, newline included: valid JSON that is too long.
    fn long_line(bytes: usize) -> Vec<u8> {
        let head = br#"{"version":1,"request":"status","pad":""#;
        let tail = b"\"}\n";
        let mut line = head.to_vec();
        line.resize(bytes - tail.len(), b'x');
        line.extend_from_slice(tail);
        line
    }

    #[tokio::test]
    async fn a_line_over_the_limit_is_skipped_with_its_memory_bounded_and_reading_goes_on() {
        let mut input = long_line(16 * MAX_REQUEST_LINE_BYTES);
        input.extend_from_slice(b"next\n\xff\xfe\nlast");
        let mut lines = RequestLines::new(&input[..]);
        assert!(matches!(
            lines.next().await,
            Some(Err(LineRefused::TooLong))
        ));
        // Refused once the limit is passed, before the rest of the line is read.
        assert!(lines.buffer.capacity() <= 3 * MAX_REQUEST_LINE_BYTES);
        assert_eq!(lines.next().await.unwrap().unwrap(), "next");
        assert!(
            lines.buffer.capacity() <= 3 * MAX_REQUEST_LINE_BYTES,
            "{}",
            lines.buffer.capacity()
        );
        assert!(matches!(
            lines.next().await,
            Some(Err(LineRefused::NotUtf8))
        ));
        // The last line needs no newline, as before.
        assert_eq!(lines.next().await.unwrap().unwrap(), "last");
        assert!(lines.next().await.is_none());
    }

    #[tokio::test]
    async fn a_line_at_the_limit_is_read() {
        let input = long_line(MAX_REQUEST_LINE_BYTES + 1);
        let mut lines = RequestLines::new(&input[..]);
        let line = lines.next().await.unwrap().unwrap();
        assert_eq!(line.len(), MAX_REQUEST_LINE_BYTES);
    }

    /// Sends `input` on a connection to the control socket, then a subscription; returns the replies up to and
    /// including the one that answers it (the subscription is answered by the connection, not the daemon).
    async fn replies_to(input: Vec<u8>) -> Vec<Reply> {
        let (client, server) = UnixStream::pair().unwrap();
        let (daemon, _daemon_inbox) = mpsc::channel(1);
        let (events, _) = broadcast::channel(1);
        tokio::spawn(connection(server, daemon, events));
        let (read, mut write) = client.into_split();
        tokio::spawn(async move {
            write.write_all(&input).await.unwrap();
            let subscribe = to_line(&RequestLine::new(Request::Subscribe));
            write.write_all(subscribe.as_bytes()).await.unwrap();
            // Held open: the connection must answer before the client closes.
            std::future::pending::<()>().await;
        });
        let mut lines = BufReader::new(read).lines();
        let mut replies = Vec::new();
        let read_replies = async {
            while let Some(line) = lines.next_line().await.unwrap() {
                let reply = parse_line::<ReplyLine>(&line).unwrap().reply;
                let subscribed = reply == Reply::Subscribed;
                replies.push(reply);
                if subscribed {
                    break;
                }
            }
        };
        // The test's daemon never answers: a line taken for a request waits for ever.
        if tokio::time::timeout(std::time::Duration::from_secs(10), read_replies)
            .await
            .is_err()
        {
            panic!("no reply within 10 s; replies so far: {replies:?}");
        }
        replies
    }

    fn error_message(reply: &Reply) -> &str {
        match reply {
            Reply::Error { message } => message,
            other => panic!("expected an error reply, got {other:?}"),
        }
    }

    #[tokio::test]
    async fn a_2_mib_line_gets_a_short_error_naming_the_limit_and_the_next_request_is_served() {
        let replies = replies_to(long_line(2 * MAX_REQUEST_LINE_BYTES)).await;
        assert_eq!(replies.len(), 2, "{replies:?}");
        let message = error_message(&replies[0]);
        assert!(message.contains("longer than 1048576 bytes"), "{message}");
        assert!(!message.contains("xxx") && message.len() < 200, "{message}");
        assert_eq!(replies[1], Reply::Subscribed);
    }

    #[tokio::test]
    async fn a_line_that_is_not_utf8_gets_an_error_and_the_next_request_is_served() {
        let replies = replies_to(b"{\"version\":1,\"request\":\"st\xffatus\"}\n".to_vec()).await;
        assert_eq!(replies.len(), 2, "{replies:?}");
        let message = error_message(&replies[0]);
        assert!(message.contains("not UTF-8"), "{message}");
        assert_eq!(replies[1], Reply::Subscribed);
    }
}
