//! `zeroset demo`: the whole station on one machine. It starts the simulator and a daemon (the real programs, over
//! pseudo-terminals) in a fresh folder, teaches the simulated propeller's blade A, inspects blades A, B and C live,
//! prints the per-blade table and the report's folder, and stops both.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::Context;
use clap::Args;

use super::station::{run_job, JobArgs, StationFile};
use crate::api::Request;

#[derive(Debug, Args)]
pub struct DemoArgs {
    /// The simulator's configuration.
    #[arg(long, default_value = "config/sims/propeller.toml")]
    pub sim: PathBuf,
    /// The station file to start from; its machines, folders and socket are replaced by the demo's own.
    #[arg(long, default_value = "config/station.toml")]
    pub station: PathBuf,
    /// Machine seconds per wall-clock second in the simulator.
    #[arg(long, default_value_t = 25.0)]
    pub time_scale: f64,
    /// The serial number of the inspected propeller.
    #[arg(long, default_value = "SN-DEMO-0001")]
    pub serial: String,
    /// The part to teach and inspect (a file in the station's parts folder).
    #[arg(long, default_value = "propeller")]
    pub part: String,
}

/// A child process stopped when dropped.
struct Running(Child);

impl Drop for Running {
    fn drop(&mut self) {
        // SIGTERM first, so the daemon removes its socket; then make sure.
        let _ = Command::new("kill").arg(self.0.id().to_string()).status();
        let deadline = Instant::now() + Duration::from_secs(3);
        while Instant::now() < deadline {
            if let Ok(Some(_)) = self.0.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

pub fn run(args: &DemoArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let root =
        std::env::temp_dir().join(format!("zeroset-demo-{}", crate::station::clock::unix_ms()));
    std::fs::create_dir_all(&root).with_context(|| format!("cannot create {}", root.display()))?;
    reportln!(
        "zeroset demo: simulator and daemon in {} (all lengths in mm)",
        root.display()
    )?;
    let exe = std::env::current_exe().context("locating the zeroset binary")?;

    let ports = root.join("ports");
    let mut sim = Command::new(&exe)
        .arg("sim")
        .arg("--config")
        .arg(&args.sim)
        .arg("--time-scale")
        .arg(args.time_scale.to_string())
        .arg("--link-dir")
        .arg(&ports)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .context("starting the simulator")?;
    let announced = BufReader::new(sim.stdout.take().expect("piped"));
    let sim = Running(sim);
    let machines = read_announcements(announced, &args.sim)?;

    let station_file = root.join("station.toml");
    let text = station_for_simulator(&args.station, &machines, &ports, &root)?;
    crate::fsutil::write_atomically(&station_file, text.as_bytes())?;
    let daemon = Command::new(&exe)
        .arg("daemon")
        .arg("--config")
        .arg(&station_file)
        .stderr(std::fs::File::create(root.join("daemon.stderr"))?)
        .spawn()
        .context("starting the daemon")?;
    let daemon = Running(daemon);
    wait_for_socket(&root.join("zeroset.sock"))?;

    let job = JobArgs {
        station: StationFile {
            config: station_file,
        },
        detach: false,
    };
    reportln!("\n== teach: scanning the master blade A and fitting its reference ==")?;
    run_job(
        &job,
        Request::Teach {
            part: args.part.clone(),
        },
    )?;
    reportln!(
        "\n== inspect {}: blades A, B and C, deviations live ==",
        args.serial
    )?;
    run_job(
        &job,
        Request::Inspect {
            part: args.part.clone(),
            serial: args.serial.clone(),
        },
    )?;
    drop(daemon);
    drop(sim);
    reportln!(
        "\ndemo done in {:.1} s; daemon log in {}",
        started.elapsed().as_secs_f64(),
        root.join("logs").display()
    )?;
    Ok(())
}

/// The simulator's `machine NAME PATH` lines, one per configured machine (the demo, the tests and the bench
/// start it alike).
pub fn read_announcements(
    mut out: BufReader<std::process::ChildStdout>,
    config: &Path,
) -> anyhow::Result<Vec<String>> {
    let expected = zeroset_sim::config::SimConfig::load(config)?.machines.len();
    let mut names = Vec::new();
    while names.len() < expected {
        let mut line = String::new();
        anyhow::ensure!(
            out.read_line(&mut line)? > 0,
            "the simulator stopped before announcing its machines"
        );
        if let Some((name, _)) = zeroset_sim::simulator::parse_announcement(&line) {
            names.push(name);
        }
    }
    // The simulator keeps writing answers to its control lines; nobody reads them in the demo.
    std::thread::spawn(move || std::io::copy(&mut out, &mut std::io::sink()));
    Ok(names)
}

/// A station file for simulated machines: `template` with its machines on the links in `ports`, and its
/// folders and control socket under `root`. Used by the demo and the end-to-end tests.
pub fn station_for_simulator(
    template: &Path,
    machines: &[String],
    ports: &Path,
    root: &Path,
) -> anyhow::Result<String> {
    let text = std::fs::read_to_string(template)
        .with_context(|| format!("cannot read {}", template.display()))?;
    let mut table: toml::Table =
        toml::from_str(&text).with_context(|| format!("{} is not TOML", template.display()))?;
    let folder = template
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let folder = folder
        .canonicalize()
        .with_context(|| format!("cannot resolve {}", folder.display()))?;
    let parts = table
        .get("parts")
        .and_then(|v| v.as_str())
        .context("the station file has no `parts` folder")?;
    let parts = folder.join(parts);
    let machine = table
        .get("machines")
        .and_then(|m| m.as_array())
        .and_then(|m| m.first())
        .cloned()
        .context("the station file has no [[machines]]")?;
    let machines: Vec<toml::Value> = machines
        .iter()
        .map(|name| {
            let mut entry = machine.clone();
            if let Some(entry) = entry.as_table_mut() {
                entry.insert("name".into(), name.clone().into());
                entry.insert("port".into(), path_value(&ports.join(name)));
                entry.remove("baud");
            }
            entry
        })
        .collect();
    table.insert("machines".into(), machines.into());
    table.insert("parts".into(), path_value(&parts));
    let mut folders = toml::Table::new();
    for name in ["data", "reports", "logs"] {
        folders.insert(name.into(), path_value(&root.join(name)));
    }
    table.insert("folders".into(), folders.into());
    let mut control = toml::Table::new();
    control.insert("socket".into(), path_value(&root.join("zeroset.sock")));
    table.insert("control".into(), control.into());
    Ok(toml::to_string(&table)?)
}

fn path_value(path: &Path) -> toml::Value {
    path.display().to_string().into()
}

/// How long a daemon may take to open its control socket: headroom for a loaded CI machine.
const DAEMON_START: Duration = Duration::from_secs(30);

/// Waits until a daemon answers on its control socket.
pub fn wait_for_socket(socket: &Path) -> anyhow::Result<()> {
    let deadline = Instant::now() + DAEMON_START;
    while Instant::now() < deadline {
        if std::os::unix::net::UnixStream::connect(socket).is_ok() {
            return Ok(());
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    anyhow::bail!(
        "the daemon did not open {} within {} s; see its standard error",
        socket.display(),
        DAEMON_START.as_secs()
    )
}
