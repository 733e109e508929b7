//! Meshing time of the brake hub of seed 000 fig. 5 (54 supershapes and cuboids, 53 Booleans) at
//! two cell sizes, with the mesh's vertex and triangle counts printed once per size, and beside it, in the same
//! run, the peer: Fidget 0.5.1 meshing an equivalent CSG (benches/peers/fidget_hub, its own crate, built here by
//! cargo into target/fidget_hub; skipped with a note when it cannot be built).
//!
//!     cargo bench --bench mesh

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
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
    fidget_peer();
}

/// Builds and runs the Fidget peer at each cell size, printing what it measured (its median of five meshings,
/// octree and dual walk, JIT compilation included; the largest distance of its vertices off its surface).
fn fidget_peer() {
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
    for cell in CELLS_MM {
        let run = Command::new(target.join("release/fidget_hub"))
            .arg(cell.to_string())
            .output()
            .expect("the Fidget peer runs");
        let printed = String::from_utf8_lossy(&run.stdout);
        for line in printed.lines().filter(|l| !l.starts_with("fidget: depth")) {
            println!("peer, cell {cell} mm: {line}");
        }
    }
}

criterion_group!(benches, mesh_hub);
criterion_main!(benches);
