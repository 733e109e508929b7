//! The two codecs talking over an in-memory pipe, as the client and the simulator will over a serial line.

use futures_util::{SinkExt, StreamExt};
use tokio_util::codec::Framed;
use zeroset_drivers::codec::{ClientCodec, ServerCodec};
use zeroset_drivers::wire::{Command, Response};

#[tokio::test]
async fn a_transaction_and_an_unsolicited_event_cross_a_pipe() {
    let (client_end, server_end) = tokio::io::duplex(4096);
    let mut client = Framed::new(client_end, ClientCodec::default());
    let mut server = Framed::new(server_end, ServerCodec::default());

    let goto: Command = "00002 GoTo(X(100), Y(-0.5), Z(12.25))".parse().unwrap();
    client.send(&goto).await.unwrap();
    let received = server
        .next()
        .await
        .expect("a line")
        .expect("no I/O error")
        .expect("a valid command");
    assert_eq!(received, goto);

    let replies: Vec<Response> = [
        "00002 &",
        "E0000 ! Error(3, 0500, \"HealthCheck\", \"Emergency stop\")",
        "00002 # X(100), Y(-0.5), Z(12.25)",
        "00002 %",
    ]
    .iter()
    .map(|line| line.parse().unwrap())
    .collect();
    for reply in &replies {
        server.send(reply).await.unwrap();
    }
    drop(server);
    let read: Vec<Response> = client
        .map(|item| item.expect("no I/O error").expect("a valid response"))
        .collect()
        .await;
    assert_eq!(read, replies);
}
