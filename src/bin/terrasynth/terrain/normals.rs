//! `terrasynth normals`: a tangent-space normal map of a heightfield for
//! the UVs of `terrasynth mesh --uv` (see `terrasynth::mesh::normal_map`).

use crate::{CliResult, args::Input};
use std::path::PathBuf;
use terrasynth::io::write_atomic;
use terrasynth::masks::encode_png8;
use terrasynth::mesh::normal_map::{Convention, normal_map};

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum ConventionArg {
    /// Y+: green points north (up in the image): Blender, Unity, Godot, glTF.
    Opengl,
    /// Y-: green points south (down in the image): Unreal, 3ds Max.
    Directx,
}

#[derive(clap::Args)]
pub struct Args {
    /// Input heightfield (any readable format; no nodata).
    input: PathBuf,
    /// Output PNG (8-bit RGB: R east, G north or south, B up; flat is 128,128,255).
    #[arg(short, long, value_name = "PNG")]
    output: PathBuf,
    /// Which way the map's Y (green) points.
    #[arg(long, value_enum, default_value = "opengl")]
    convention: ConventionArg,
    /// Texture side in pixels [default: the heightfield's width].
    #[arg(long, value_name = "N")]
    size: Option<usize>,
    #[command(flatten)]
    read: Input,
}

pub fn run(a: Args) -> CliResult {
    crate::synthesis::synth::check_outputs(&[Some(&a.output)], &[&a.input])?;
    let hf = a.read.read(&a.input)?;
    let size = a.size.unwrap_or(hf.width());
    let convention = match a.convention {
        ConventionArg::Opengl => Convention::OpenGl,
        ConventionArg::Directx => Convention::DirectX,
    };
    let map =
        normal_map(&hf, size, convention).map_err(|e| format!("{}: {e}", a.input.display()))?;
    write_atomic(&a.output, &encode_png8(size, size, 3, map.as_flattened()))?;
    eprintln!(
        "wrote {} ({size} x {size}, {:?} convention)",
        a.output.display(),
        convention
    );
    Ok(())
}
