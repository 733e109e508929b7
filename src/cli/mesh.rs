//! `zeroset mesh --model M --out FILE`: a supershape model polygonised (seed 000 section 4) and written as STL,
//! PLY or OBJ by the output's extension.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use crate::fsutil::write_atomically;
use crate::geometry::supershape::mesh::{polygonise, MeshFormat, MeshParams};
use crate::model_file::{ModelFile, ReferenceModel};

/// Cells along the model's bounding-box diagonal when no cell is given.
const CELLS_PER_DIAGONAL: f64 = 100.0;

#[derive(Debug, Args)]
pub struct MeshArgs {
    /// A supershape model file (from `zeroset fit supershape`, or a taught supershape reference's model).
    #[arg(long)]
    pub model: PathBuf,
    /// The mesh file: .stl, .ply or .obj.
    #[arg(long)]
    pub out: PathBuf,
    /// Grid cell (mm), about the mesh's edge length; by default 1/100 of the model's size. It must resolve the
    /// thinnest wall and smallest hole.
    #[arg(long)]
    pub cell_mm: Option<f64>,
    /// Largest |F| allowed at a vertex (seed 000's epsilon).
    #[arg(long, default_value_t = 1e-6)]
    pub epsilon: f64,
}

pub fn run(args: &MeshArgs) -> anyhow::Result<()> {
    let started = Instant::now();
    let format = MeshFormat::from_path(&args.out)?;
    let file = ModelFile::load(&args.model)?;
    let ReferenceModel::Supershape { solid, .. } = &file.model else {
        anyhow::bail!(
            "{}: not a supershape model; `zeroset mesh` polygonises supershape solids",
            args.model.display()
        );
    };
    let cell = args
        .cell_mm
        .unwrap_or(solid.bounds().diagonal() / CELLS_PER_DIAGONAL);
    let params = MeshParams {
        epsilon: args.epsilon,
        ..MeshParams::with_cell(cell)
    };
    let mesh = polygonise(solid, &params)?;
    let mut bytes = Vec::new();
    mesh.write_to(&mut bytes, format)?;
    // Atomically, so that a reader (a slicer, a viewer) never sees half a mesh.
    write_atomically(&args.out, &bytes)?;
    reportln!(
        "wrote {}: {} vertices, {} triangles, {}, volume {:.3} mm^3, area {:.3} mm^2, cell {cell:.3} mm, every vertex \
         within |F| < {:e} ({:.2} s)",
        args.out.display(),
        mesh.vertices.len(),
        mesh.triangles.len(),
        if mesh.is_closed() { "closed" } else { "NOT closed" },
        mesh.volume(),
        mesh.area(),
        args.epsilon,
        started.elapsed().as_secs_f64()
    )?;
    Ok(())
}
