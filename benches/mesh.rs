//! Meshing time of the brake hub of seed 000 fig. 5 (54 supershapes and cuboids, 53 Booleans) at
//! two cell sizes, with the mesh's vertex and triangle counts printed once per size, and beside it, in the same
//! run, the peer: Fidget 0.5.1 meshing an equivalent CSG (benches/peers/fidget_hub, its own crate, built here by
//! cargo into target/fidget_hub; skipped with a note when it cannot be built).
//!
//!     cargo bench --bench mesh

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, Criterion};
use zeroset::geometry::supershape::csg::Solid;
use zeroset::geometry::supershape::mesh::hub::brake_hub;
use zeroset::geometry::supershape::mesh::{polygonise, MeshParams};

const CELLS_MM: [f64; 2] = [1.0, 0.5];

fn mesh_hub(c: &mut Criterion) {
    let hub = brake_hub();
    let mut group = c.benchmark_group("mesh brake hub");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    for cell in CELLS_MM {
        let params = MeshParams::with_cell(cell);
        let mesh = polygonise(&hub, &params).expect("the hub meshes");
        let worst = mesh
            .vertices
            .iter()
            .map(|v| hub.value(v).abs())
            .fold(0.0, f64::max);
        println!(
            "cell {cell} mm: {} vertices, {} triangles, closed {}, volume {:.0} mm^3, largest |F| at a vertex {worst:.1e}",
            mesh.vertices.len(),
            mesh.triangles.len(),
            mesh.is_closed(),
            mesh.volume()
        );
        group.bench_function(format!("cell {cell} mm"), |b| {
            b.iter(|| polygonise(&hub, &params).expect("the hub meshes"))
        });
    }
    group.finish();
    fidget_peer(&hub);
}

/// Builds and runs the Fidget peer at each cell size, printing what it measured (its median of five meshings,
/// octree and dual walk, JIT compilation included; the largest distance of its vertices off its surface), and
/// our median of five beside it, timed the same way, with the ratio. Issue 19's goal is at least Fidget's speed
/// at an equal cell size: the bench fails its own assertion, once both sizes are printed, where we are slower.
fn fidget_peer(hub: &Solid) {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/peers/fidget_hub");
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/fidget_hub");
    let built = Command::new(env!("CARGO"))
        .args(["build", "--release", "--quiet", "--manifest-path"])
        .arg(manifest.join("Cargo.toml"))
        .env("CARGO_TARGET_DIR", &target)
        .status();
    if !matches!(built, Ok(status) if status.success()) {
        println!(
            "peer: the Fidget peer could not be built ({built:?}); no peer figure in this run"
        );
        return;
    }
    let mut slower = Vec::new();
    for cell in CELLS_MM {
        let run = Command::new(target.join("release/fidget_hub"))
            .arg(cell.to_string())
            .output()
            .expect("the Fidget peer runs");
        let printed = String::from_utf8_lossy(&run.stdout);
        for line in printed.lines().filter(|l| !l.starts_with("fidget: depth")) {
            println!("peer, cell {cell} mm: {line}");
        }
        let peer_seconds = printed
            .lines()
            .find_map(|l| l.strip_prefix("fidget: median of 5: "))
            .and_then(|rest| rest.trim_end_matches(" s").parse::<f64>().ok());
        let ours = median_seconds(5, || {
            polygonise(hub, &MeshParams::with_cell(cell)).expect("the hub meshes");
        });
        match peer_seconds {
            Some(peer) => {
                println!(
                    "cell {cell} mm: zeroset median of 5: {ours:.3} s, Fidget {peer:.3} s: zeroset takes {:.2}x Fidget's time",
                    ours / peer
                );
                if ours > peer {
                    slower.push(format!("{cell} mm: {:.2}x", ours / peer));
                }
            }
            None => println!(
                "cell {cell} mm: zeroset median of 5: {ours:.3} s; the peer printed no median"
            ),
        }
    }
    assert!(
        slower.is_empty(),
        "meshing slower than Fidget at an equal cell size ({}): the goal is at least its speed",
        slower.join(", ")
    );
}

fn median_seconds(runs: usize, mut work: impl FnMut()) -> f64 {
    let mut seconds: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            work();
            start.elapsed().as_secs_f64()
        })
        .collect();
    seconds.sort_by(f64::total_cmp);
    seconds[runs / 2]
}

criterion_group!(benches, mesh_hub);
criterion_main!(benches);
