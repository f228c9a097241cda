//! `terrasynth mesh`: a heightfield as a triangle mesh for engines and DCC
//! tools (see `terrasynth::mesh`).

use crate::{CliResult, args::Input};
use std::path::PathBuf;
use std::time::Instant;
use terrasynth::mesh::{self, Detail, Options, measure};

const ABOUT: &str = "\
The mesh: Y up, X east, Z south, in metres (cell size × column and row,
heights as read); triangles counter-clockwise seen from above. Without
--max-error or --triangles every sample is a vertex (two triangles a cell).
Levels of detail and tiles are separate meshes and nodes named
terrain[_xI_yJ][_LODk]; tiles share their border vertices exactly.

Examples:
  terrasynth mesh alps.png -o alps.glb --max-error 2 --normals --uv
  terrasynth mesh alps.png -o alps.gltf --max-error 1 --lods 4 --tile 256 --skirt 20
  terrasynth mesh alps.png -o alps.obj --triangles 200000";

#[derive(clap::Args)]
#[command(after_help = ABOUT)]
pub struct Args {
    /// Input heightfield (any readable format; no nodata).
    input: PathBuf,
    /// Output mesh: .glb, .gltf (with NAME.bin beside it) or .obj.
    #[arg(short, long)]
    output: PathBuf,
    /// Adaptive: as few triangles as keep every sample within M metres of
    /// the surface (measured, and printed).
    #[arg(long, value_name = "M", conflicts_with = "triangles")]
    max_error: Option<f32>,
    /// Adaptive: the smallest error that needs at most N triangles.
    #[arg(long, value_name = "N")]
    triangles: Option<usize>,
    /// Levels of detail (1..=8): level k keeps every 2^k-th sample of a
    /// regular mesh, or allows 2^k times the error (¼^k of --triangles).
    #[arg(long, value_name = "K", default_value_t = 1)]
    lods: usize,
    /// Write vertex normals (from the heightfield's slopes).
    #[arg(long)]
    normals: bool,
    /// Write texture coordinates (0..1 over the whole grid, v down).
    #[arg(long)]
    uv: bool,
    /// Hang a skirt M metres deep below every tile's edge.
    #[arg(long, value_name = "M")]
    skirt: Option<f32>,
    /// Tiles of N cells a side (a power of two for adaptive meshes).
    #[arg(long, value_name = "N")]
    tile: Option<usize>,
    #[command(flatten)]
    read: Input,
}

pub fn run(a: Args) -> CliResult {
    let bin = a.output.with_extension("bin");
    crate::synthesis::synth::check_outputs(&[Some(&a.output), Some(&bin)], &[&a.input])?;
    let hf = a.read.read(&a.input)?;
    let opts = Options {
        detail: match (a.max_error, a.triangles) {
            (Some(e), _) => Detail::MaxError(e),
            (None, Some(n)) => Detail::Triangles(n),
            (None, None) => Detail::Regular,
        },
        lods: a.lods,
        normals: a.normals,
        uvs: a.uv,
        skirt: a.skirt,
        tile: a.tile,
    };
    let named = |e: mesh::MeshError| format!("{}: {e}", a.input.display());
    let t = Instant::now();
    let built = mesh::build(&hf, &opts).map_err(named)?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let per_level = built.tiles.0 * built.tiles.1;
    for (l, bound) in built.bounds.iter().enumerate() {
        let pieces = &built.triangulations[l * per_level..(l + 1) * per_level];
        let m = measure::max_vertical_error(&hf, pieces);
        let tris: usize = pieces.iter().map(|p| p.triangles.len()).sum();
        let verts: usize = pieces.iter().map(|p| p.vertices.len()).sum();
        eprintln!(
            "level {l}: {verts} vertices, {tris} triangles, max vertical error {:.3} m (bound {bound:.3} m)",
            m.max_error
        );
    }
    // Io and Format errors name the output already.
    mesh::write(&a.output, &built.meshes).map_err(|e| match e {
        mesh::MeshError::TooLarge { .. } => format!("{}: {e}", a.output.display()),
        e => e.to_string(),
    })?;
    eprintln!(
        "wrote {} ({} meshes; {} x {} samples, meshed in {ms:.0} ms)",
        a.output.display(),
        built.meshes.len(),
        hf.width(),
        hf.height()
    );
    Ok(())
}
