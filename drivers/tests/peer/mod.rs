//! A scripted I++ server for client tests: it checks each command the client writes, word for word,
//! and answers with the lines the test gives.

// Each test crate that includes this module uses a different part of it.
#![allow(dead_code)]

use std::time::Duration;

use futures_util::{SinkExt, StreamExt};
use tokio::io::{AsyncRead, AsyncWrite, AsyncWriteExt, DuplexStream};
use tokio::time::timeout;
use tokio_util::codec::Framed;
use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::codec::ServerCodec;
use zeroset_drivers::wire::Response;

/// How long the peer waits for a command it expects, or listens to check that none comes. Under
/// paused time this costs nothing, and it is well under the client's timeouts in these tests.
const PATIENCE: Duration = Duration::from_millis(500);

pub struct Peer<T> {
    link: Framed<T, ServerCodec>,
}

/// A client for machine `name` and the peer on the other end of an in-memory pipe.
pub fn pair(name: &str, config: ClientConfig) -> (Client, Peer<DuplexStream>) {
    let (client_end, peer_end) = tokio::io::duplex(64 * 1024);
    (Client::new(name, client_end, config), Peer::new(peer_end))
}

impl<T: AsyncRead + AsyncWrite + Unpin> Peer<T> {
    pub fn new(transport: T) -> Self {
        Peer {
            link: Framed::new(transport, ServerCodec::default()),
        }
    }

    /// Waits for the next command and checks its text, tag included.
    pub async fn expect(&mut self, line: &str) {
        let command = timeout(PATIENCE, self.link.next())
            .await
            .unwrap_or_else(|_| panic!("expected `{line}`, the client wrote nothing"))
            .expect("the client closed the link")
            .expect("I/O error")
            .expect("the client wrote an invalid line");
        assert_eq!(command.to_string(), line);
    }

    /// Checks that the client writes nothing for a while.
    pub async fn expect_silence(&mut self) {
        if let Ok(line) = timeout(PATIENCE, self.link.next()).await {
            panic!("expected silence, the client wrote {line:?}");
        }
    }

    /// Sends response lines.
    pub async fn reply(&mut self, lines: &[&str]) {
        for line in lines {
            let response: Response = line.parse().expect("a valid response in the script");
            self.link
                .send(response)
                .await
                .expect("the client is reading");
        }
    }

    /// Sends raw bytes, such as line noise.
    pub async fn send_raw(&mut self, bytes: &[u8]) {
        self.link.get_mut().write_all(bytes).await.unwrap();
    }

    /// A `&` and a `%` for `tag`.
    pub async fn ack_and_complete(&mut self, tag: &str) {
        self.reply(&[&format!("{tag} &"), &format!("{tag} %")])
            .await;
    }
}
