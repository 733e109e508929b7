//! The control socket: a Unix domain socket that only the operators' group may use (mode 0660), one task per
//! connection. Requests go to the daemon's state task and their replies come back; a subscription turns the
//! connection into a stream of events, and a watcher that falls behind is told how many it missed rather than
//! slowing the station down.

use std::os::unix::fs::PermissionsExt;
use std::path::Path;

use tokio::io::{AsyncBufReadExt, AsyncWriteExt, BufReader};
use tokio::net::{UnixListener, UnixStream};
use tokio::sync::{broadcast, mpsc, oneshot};

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
    let mut lines = BufReader::new(read).lines();
    while let Ok(Some(line)) = lines.next_line().await {
        let request = match parse_line::<RequestLine>(&line) {
            Ok(line) => line.request,
            Err(error) => {
                let reply = Reply::Error {
                    message: error.to_string(),
                };
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
