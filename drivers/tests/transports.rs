//! The client over real links: a pseudo-terminal, as it talks to the simulator (the client opens the
//! slave path `/dev/pts/N` as a serial port, a scripted server holds the master side), and TCP, as it
//! talks to an I++ server.

mod peer;

use futures_util::StreamExt;
use nix::pty::openpty;
use nix::sys::termios::{cfmakeraw, tcgetattr, tcsetattr, SetArg};
use peer::Peer;
use tokio::net::TcpListener;
use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::machine::{InPlaneScan, InPlaneSpacing, Machine, Xyz};
use zeroset_drivers::transport::{connect_tcp, open_pty};

#[tokio::test]
async fn a_session_and_a_scan_cross_a_raw_pseudo_terminal() {
    let pty = openpty(None, None).expect("a pseudo-terminal pair");
    // Raw mode, as the simulator sets it: no CR/LF translation, no echo, no line buffering.
    let mut termios = tcgetattr(&pty.slave).unwrap();
    cfmakeraw(&mut termios);
    tcsetattr(&pty.slave, SetArg::TCSANOW, &termios).unwrap();
    let path = nix::unistd::ttyname(&pty.slave).unwrap();
    let path = path.to_str().unwrap();
    assert!(path.starts_with("/dev/pts/"), "{path}");

    let client = Client::new("pty-cmm", open_pty(path).unwrap(), ClientConfig::default());
    let master = tokio::fs::File::from_std(std::fs::File::from(pty.master));
    let mut peer = Peer::new(master);

    let session = tokio::spawn({
        let client = client.clone();
        async move { client.start_session().await }
    });
    peer.expect("00001 StartSession()").await;
    peer.ack_and_complete("00001").await;
    session.await.unwrap().unwrap();

    let scanning = client.scanning().unwrap();
    let plan = InPlaneScan {
        start: Xyz::new(200.0, 0.0, 10.0),
        start_normal: Xyz::new(0.0, 0.0, 1.0),
        plane_normal: Xyz::new(1.0, 0.0, 0.0),
        direction: Xyz::new(200.0, 1.0, 10.0),
        spacing: InPlaneSpacing::Step(0.5),
        end: Xyz::new(200.0, 0.0, 10.0),
        stop_diameter: 1.0,
        passes: 1,
        end_normal: Xyz::new(0.0, 0.0, 1.0),
    };
    let started = tokio::spawn(async move { scanning.scan_in_plane(plan).await });
    peer.expect("00002 OnScanReport(X(), Y(), Z(), IJK(), Q())")
        .await;
    peer.ack_and_complete("00002").await;
    peer.expect(
        "00003 ScanInPlaneEndIsSphere(200, 0, 10, 0, 0, 1, 1, 0, 0, 200, 1, 10, 0.5, 200, 0, 10, 1, 1, 0, 0, 1)",
    )
    .await;
    peer.reply(&["00003 &", "00003 # 200,0.5,11.5,0,0,1,0"])
        .await;
    let mut points = started.await.unwrap().unwrap();
    let first = points.next().await.unwrap().unwrap();
    assert_eq!(first.centre, Xyz::new(200.0, 0.5, 11.5));
    peer.reply(&[
        "00003 # 200,1,11.5,0,0,1,0,200,1.5,11.5,0,0.6,0.8,2",
        "00003 %",
    ])
    .await;
    let rest: Vec<_> = points.map(Result::unwrap).collect().await;
    assert_eq!(rest.len(), 2);
    assert_eq!(rest[1].normal, Xyz::new(0.0, 0.6, 0.8));
    assert_eq!(rest[1].quality, 2.0);

    // The same path opens again after the first client is gone: a reconnect. The client's task has
    // ended when its event channel closes.
    let mut events = client.events();
    drop(client);
    while events.recv().await.is_ok() {}
    let again = Client::new("pty-cmm", open_pty(path).unwrap(), ClientConfig::default());
    let homed = tokio::spawn(async move { again.is_homed().await });
    peer.expect("00001 IsHomed()").await;
    peer.reply(&["00001 &", "00001 # IsHomed(1)", "00001 %"])
        .await;
    assert!(homed.await.unwrap().unwrap());
}

#[tokio::test]
async fn a_transaction_crosses_tcp() {
    let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let address = listener.local_addr().unwrap();
    let client = Client::new(
        "tcp-cmm",
        connect_tcp(address).await.unwrap(),
        ClientConfig::default(),
    );
    let (server_end, _) = listener.accept().await.unwrap();
    let mut peer = Peer::new(server_end);
    let homed = tokio::spawn(async move { client.is_homed().await });
    peer.expect("00001 IsHomed()").await;
    peer.reply(&["00001 &", "00001 # IsHomed(0)", "00001 %"])
        .await;
    assert!(!homed.await.unwrap().unwrap());
}
