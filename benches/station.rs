//! The station's figures, measured on the real programs: the simulator and the daemon over pseudo-terminals.
//!
//! - latency from a point's arrival on the line (its `received_unix_us`, stamped by the machine worker as the
//!   point comes off the I++ client) to its first deviation event at a subscriber of the control socket (its
//!   preview, or the point itself), and to its point event after the compensation's look-ahead: p50, p99, p99.9,
//!   max; the bench fails above 1 ms p99 for the first;
//! - the whole inspection plan (15 profiles) on one machine and on two;
//! - `status` answered over the control socket during a whole inspection, its set-up included, and `abort`
//!   mid-scan: p50, p99, max of the round trip on a connection of its own, as the CLI makes it.
//!
//! Run: `cargo bench --bench station` (needs the release binary: cargo builds it for benches).

use std::collections::HashSet;
use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use zeroset::api::{parse_line, to_line, Event, EventLine, Request, RequestLine};

/// Machine seconds per second: fast enough to bench, slow enough that the machines, not the computer, set the
/// pace (a scan's points arrive in blocks as they are measured).
const TIME_SCALE: f64 = 20.0;

struct Station {
    root: PathBuf,
    station: PathBuf,
    children: Vec<Child>,
}

impl Drop for Station {
    fn drop(&mut self) {
        for child in &mut self.children {
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = std::fs::remove_dir_all(&self.root);
    }
}

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn start(sim_config: &str) -> Station {
    let root = std::env::temp_dir().join(format!(
        "zeroset-bench-{}-{}",
        std::process::id(),
        sim_config.replace('.', "-")
    ));
    std::fs::create_dir_all(&root).unwrap();
    let ports = root.join("ports");
    let mut sim = Command::new(env!("CARGO_BIN_EXE_zeroset"))
        .args(["sim", "--config"])
        .arg(repo().join("config/sims").join(sim_config))
        .args(["--time-scale", &TIME_SCALE.to_string(), "--link-dir"])
        .arg(&ports)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("the simulator starts");
    let out = BufReader::new(sim.stdout.take().unwrap());
    let machines =
        zeroset::cli::demo::read_announcements(out, &repo().join("config/sims").join(sim_config))
            .expect("the simulator announces its machines");
    let text = zeroset::cli::demo::station_for_simulator(
        &repo().join("config/station.toml"),
        &machines,
        &ports,
        &root,
    )
    .unwrap();
    let station = root.join("station.toml");
    std::fs::write(&station, text).unwrap();
    let daemon = Command::new(env!("CARGO_BIN_EXE_zeroset"))
        .arg("daemon")
        .arg("--config")
        .arg(&station)
        .stderr(Stdio::null())
        .spawn()
        .expect("the daemon starts");
    zeroset::cli::demo::wait_for_socket(&root.join("zeroset.sock")).expect("the daemon serves");
    Station {
        root,
        station,
        children: vec![sim, daemon],
    }
}

fn cli(station: &Path, args: &[&str]) {
    let status = Command::new(env!("CARGO_BIN_EXE_zeroset"))
        .args(args)
        .arg("--config")
        .arg(station)
        .stdout(Stdio::null())
        .status()
        .unwrap();
    assert!(status.success(), "zeroset {args:?}");
}

fn now_us() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap()
        .as_micros() as u64
}

/// Each point's latency (us) from its arrival on the line to its events at a subscriber.
#[derive(Default)]
struct Latencies {
    /// To its first deviation event: the preview, or the point itself where it came at once.
    first: Vec<u64>,
    /// The same, with when each point arrived (unix us), in the order published.
    first_at: Vec<(u64, u64)>,
    /// To its point event, which waits for the compensation's look-ahead.
    measured: Vec<u64>,
}

/// Inspects a part while subscribed; returns each point's latencies and the plan's wall time.
fn inspect(station: &Station, serial: &str) -> (Latencies, Duration) {
    let socket = station.root.join("zeroset.sock");
    let mut events = UnixStream::connect(&socket).unwrap();
    events
        .write_all(to_line(&RequestLine::new(Request::Subscribe)).as_bytes())
        .unwrap();
    let mut lines = BufReader::new(events.try_clone().unwrap());
    let mut line = String::new();
    lines.read_line(&mut line).unwrap();
    let started = Instant::now();
    cli(
        &station.station,
        &["inspect", "propeller", "--serial", serial, "--detach"],
    );
    let mut latencies = Latencies::default();
    let mut previewed = HashSet::new();
    loop {
        line.clear();
        lines.read_line(&mut line).unwrap();
        let arrived = now_us();
        match parse_line::<EventLine>(line.trim()).unwrap().event {
            Event::PointPreview {
                scan,
                index,
                received_unix_us,
                ..
            } => {
                let latency = arrived.saturating_sub(received_unix_us);
                latencies.first.push(latency);
                latencies.first_at.push((received_unix_us, latency));
                previewed.insert((scan.instance, scan.profile, index));
            }
            Event::Point {
                scan,
                index,
                received_unix_us,
                ..
            } => {
                let latency = arrived.saturating_sub(received_unix_us);
                latencies.measured.push(latency);
                if !previewed.remove(&(scan.instance, scan.profile, index)) {
                    latencies.first.push(latency);
                    latencies.first_at.push((received_unix_us, latency));
                }
            }
            Event::JobFinished { .. } => return (latencies, started.elapsed()),
            Event::JobStopped { reason, .. } | Event::JobFailed { error: reason, .. } => {
                panic!("the inspection stopped: {reason}")
            }
            _ => {}
        }
    }
}

/// p50, p99, p99.9 and max of `us`, sorted in place.
fn spread(us: &mut [u64]) -> String {
    us.sort_unstable();
    format!(
        "{} points, p50 {} us, p99 {} us, p99.9 {} us, max {} us",
        us.len(),
        percentile(us, 0.5),
        percentile(us, 0.99),
        percentile(us, 0.999),
        us.last().unwrap()
    )
}

/// One request on a connection of its own; the round trip in microseconds.
fn ask(socket: &Path, request: Request) -> u64 {
    let started = Instant::now();
    let mut stream = UnixStream::connect(socket).unwrap();
    stream
        .write_all(to_line(&RequestLine::new(request)).as_bytes())
        .unwrap();
    let mut line = String::new();
    BufReader::new(&stream).read_line(&mut line).unwrap();
    started.elapsed().as_micros() as u64
}

/// Asks `status` every 5 ms until told to stop; the round trips (us).
fn poll_status(socket: PathBuf, stop: std::sync::Arc<std::sync::atomic::AtomicBool>) -> Vec<u64> {
    let mut times = Vec::new();
    while !stop.load(std::sync::atomic::Ordering::Relaxed) {
        times.push(ask(&socket, Request::Status));
        std::thread::sleep(Duration::from_millis(5));
    }
    times
}

/// The first deviation event's latency by a point's place in its burst: the points that came off the line within
/// 2 ms of the burst's first (a machine's data line carries several).
fn by_place_in_burst(first_at: &[(u64, u64)]) -> String {
    let mut places: Vec<Vec<u64>> = Vec::new();
    let mut burst_start = 0;
    let mut place = 0;
    for &(received, latency) in first_at {
        if received > burst_start + 2_000 || received < burst_start {
            burst_start = received;
            place = 0;
        }
        if places.len() <= place {
            places.push(Vec::new());
        }
        places[place].push(latency);
        place += 1;
    }
    let mut text =
        "first deviation event by place in the burst of points off the line:".to_string();
    for (place, us) in places.iter_mut().enumerate() {
        us.sort_unstable();
        text += &format!(
            "\n  {place}: {} points, p50 {} us, p99 {} us, max {} us",
            us.len(),
            percentile(us, 0.5),
            percentile(us, 0.99),
            us.last().unwrap()
        );
    }
    text
}

fn percentile(sorted: &[u64], p: f64) -> u64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    // Criterion's harness flags (`--bench`) are ignored: this bench runs the station once per configuration.
    let one = start("propeller.toml");
    cli(&one.station, &["teach", "propeller"]);
    let socket = one.root.join("zeroset.sock");
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let poller = {
        let (socket, stop) = (socket.clone(), stop.clone());
        std::thread::spawn(move || poll_status(socket, stop))
    };
    let (mut latencies, one_machine) = inspect(&one, "BENCH-1");
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let mut status = poller.join().unwrap();
    status.sort_unstable();
    cli(
        &one.station,
        &[
            "inspect",
            "propeller",
            "--serial",
            "BENCH-ABORT",
            "--detach",
        ],
    );
    std::thread::sleep(Duration::from_secs(3));
    let abort = ask(&socket, Request::Abort);
    drop(one);
    println!(
        "status during an inspection (set-up included): {} asks, p50 {} us, p99 {} us, max {} us; abort mid-scan {} us",
        status.len(),
        percentile(&status, 0.5),
        percentile(&status, 0.99),
        status.last().unwrap(),
        abort
    );
    println!(
        "point -> its first deviation event at a subscriber (preview, or the point where it came at once): {}",
        spread(&mut latencies.first)
    );
    println!(
        "point -> its point event (after the compensation's look-ahead of {} points): {}",
        zeroset::geometry::sweep::compensation::LOOK_AHEAD,
        spread(&mut latencies.measured)
    );
    println!("{}", by_place_in_burst(&latencies.first_at));
    let p99 = percentile(&latencies.first, 0.99);
    assert!(
        p99 <= 1_000,
        "point -> deviation event p99 {p99} us: the goal is 1 ms"
    );

    let two = start("two-machines.toml");
    cli(&two.station, &["teach", "propeller"]);
    let (_, two_machines) = inspect(&two, "BENCH-2");
    drop(two);
    let ratio = two_machines.as_secs_f64() / (one_machine.as_secs_f64() / 2.0);
    println!(
        "inspection plan (3 blades x 5 profiles, time scale {TIME_SCALE}): one machine {:.2} s, two machines {:.2} s = {ratio:.3} x half of one machine's",
        one_machine.as_secs_f64(),
        two_machines.as_secs_f64()
    );
}
