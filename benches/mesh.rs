//! Meshing time of the brake hub of seed 000 fig. 5 (54 supershapes and cuboids, 53 Booleans) at
//! two cell sizes, with the mesh's vertex and triangle counts printed once per size.
//!
//!     cargo bench --bench mesh

use criterion::{criterion_group, criterion_main, Criterion};
use std::time::Duration;
use zeroset::geometry::supershape::mesh::hub::brake_hub;
use zeroset::geometry::supershape::mesh::{polygonise, MeshParams};

fn mesh_hub(c: &mut Criterion) {
    let hub = brake_hub();
    let mut group = c.benchmark_group("mesh brake hub");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(30));
    for cell in [1.0, 0.5] {
        let params = MeshParams::with_cell(cell);
        let mesh = polygonise(&hub, &params).expect("the hub meshes");
        println!(
            "cell {cell} mm: {} vertices, {} triangles, closed {}, volume {:.0} mm^3",
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
}

criterion_group!(benches, mesh_hub);
criterion_main!(benches);
