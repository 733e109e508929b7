//! Scan points per second through a real pseudo-terminal between the simulator (`zeroset sim`) and the station's
//! I++ client, unpaced and paced at 115 200 baud, and the share of the line's bytes that carry point data.
//!
//!     cargo bench --bench scan_link

use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use futures::StreamExt;
use nalgebra::Point2;
use zeroset_drivers::client::{Client, ClientConfig};
use zeroset_drivers::machine::{InPlaneScan, InPlaneSpacing, Machine, Speeds, Xyz};
use zeroset_drivers::transport::open_pty;
use zeroset_sim::config::{PartSpec, SimConfig};
use zeroset_sim::part::curve::SampledCurve;
use zeroset_sim::part::propeller::Propeller;
use zeroset_sim::simulator::parse_announcement;

/// The top of blade A's section at radius 200 mm, from the simulator's own ground truth.
fn top_of_blade_a() -> Xyz {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = SimConfig::load(&repo.join("config/sims/propeller.toml")).expect("the config");
    let PartSpec::Propeller(spec) = &config.parts["propeller"] else {
        panic!("propeller.toml holds a propeller");
    };
    let truth = Propeller::new(spec.clone()).expect("a propeller");
    let frame = truth.section_frame(0, 200.0);
    let top = SampledCurve::new(truth.section_curve(0, 200.0))
        .nearest(&Point2::new(0.0, 100.0))
        .on_curve
        .point;
    let top = frame.world(top.x, top.y, 0.0);
    Xyz::new(top.x, top.y, top.z)
}

/// Starts `zeroset sim` on a copy of config/sims/propeller.toml with the given extra machine settings.
fn start_sim(dir: &Path, extra: &str, time_scale: f64) -> (Child, String) {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base =
        std::fs::read_to_string(repo.join("config/sims/propeller.toml")).expect("the config");
    let config = dir.join("sim.toml");
    std::fs::write(&config, format!("{base}{extra}\n")).expect("a temporary config");
    let mut child = Command::new(env!("CARGO_BIN_EXE_zeroset"))
        .args([
            "sim",
            "--config",
            config.to_str().unwrap(),
            "--time-scale",
            &time_scale.to_string(),
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("zeroset sim");
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .expect("machine line");
    let (_, path) = parse_announcement(&line).expect("machine NAME PATH");
    (child, path)
}

async fn ready(path: &str) -> Client {
    let config = ClientConfig {
        ack_timeout: Duration::from_secs(10),
        reply_timeout: Duration::from_secs(60),
    };
    let client = Client::new("cmm1", open_pty(path).expect("pty"), config);
    client.start_session().await.expect("session");
    client.home().await.expect("home");
    client.change_tool("Probe1").await.expect("tool");
    client
        .set_speeds(Speeds {
            travel: 500.0,
            probing: 50.0,
            scanning: 100.0,
        })
        .await
        .expect("speeds");
    client
}

/// One closed scan of the section, 0.5 mm steps at 100 mm/s: 200 points per machine second, more than a
/// 115 200-baud line can carry. Returns the number of points.
async fn scan(client: &Client, top: Xyz) -> usize {
    client
        .go_to(Xyz::new(top.x, top.y, top.z + 20.0))
        .await
        .expect("above the blade");
    let plan = InPlaneScan {
        start: top,
        start_normal: Xyz::new(0.0, 0.0, 1.0),
        plane_normal: Xyz::new(1.0, 0.0, 0.0),
        direction: Xyz::new(top.x, top.y + 10.0, top.z),
        spacing: InPlaneSpacing::Step(0.5),
        end: Xyz::new(top.x, top.y, top.z + 1.0),
        stop_diameter: 3.0,
        passes: 1,
        end_normal: Xyz::new(0.0, 0.0, 1.0),
    };
    let stream = client
        .scanning()
        .expect("scans")
        .scan_in_plane(plan)
        .await
        .expect("scan");
    stream.map(|p| p.expect("a point")).count().await
}

/// Bytes the simulator sent while scanning, from its transcript: all of them, and those of point data (the
/// values of `#` lines, separators included; tags, markers, CR LF and other lines are overhead).
fn scan_bytes(transcript: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(transcript).expect("the transcript");
    let mut total = 0;
    let mut data = 0;
    for line in text.lines() {
        let mut fields = line.splitn(3, ' ');
        let (_, direction, content) = (fields.next(), fields.next(), fields.next().unwrap_or(""));
        if direction != Some(">") {
            continue;
        }
        let on_the_wire = content.len() + 2;
        total += on_the_wire;
        if let Some(values) = content.get(6..).and_then(|rest| rest.strip_prefix("# ")) {
            if values.starts_with(|c: char| c == '-' || c.is_ascii_digit()) {
                data += values.len();
            }
        }
    }
    (total, data)
}

fn scan_link(c: &mut Criterion) {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("runtime");
    let top = top_of_blade_a();
    let mut group = c.benchmark_group("scan through a pty");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    for (name, extra, time_scale) in [
        ("unpaced", "", 1000.0),
        // Paced at 115 200 baud of machine time; the simulator runs 10x fast, so wall rates are 10x the
        // machine's: divide by 10.
        ("115200 baud, time scale 10", "baud = 115200", 10.0),
    ] {
        let dir = tempfile::tempdir().expect("temp dir");
        let transcript = dir.path().join("cmm1.log");
        let extra = format!("{extra}\ntranscript = \"{}\"", transcript.display());
        let (mut sim, path) = start_sim(dir.path(), &extra, time_scale);
        let client = runtime.block_on(ready(&path));
        let points = runtime.block_on(scan(&client, top));
        std::fs::write(&transcript, "").expect("reset the transcript");
        runtime.block_on(scan(&client, top));
        let (total, data) = scan_bytes(&transcript);
        println!(
            "{name}: {points} points per scan; point data {data} of {total} bytes sent = {:.1}%",
            100.0 * data as f64 / total as f64
        );
        group.throughput(Throughput::Elements(points as u64));
        group.bench_function(name, |b| {
            b.iter_custom(|iterations| {
                let started = Instant::now();
                for _ in 0..iterations {
                    runtime.block_on(scan(&client, top));
                }
                started.elapsed()
            })
        });
        let _ = sim.stdin.take().map(|mut s| s.write_all(b""));
        let _ = sim.kill();
        let _ = sim.wait();
    }
    group.finish();
}

criterion_group!(benches, scan_link);
criterion_main!(benches);
