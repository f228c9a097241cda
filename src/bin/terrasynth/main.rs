//! The `terrasynth` command-line tool: one file per subcommand, grouped by
//! family (`synthesis/`, `editing/`, `terrain/`, `data/`, `measure/`);
//! `args.rs` holds the argument pieces several share.

mod args;
mod data;
mod editing;
mod measure;
mod progress;
mod synthesis;
mod terrain;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Example-based terrain synthesis from real elevation data.
///
/// Heightfields are read and written by file extension: .png (16-bit + JSON
/// sidecar), and more formats listed under `convert --help`.
#[derive(Parser)]
#[command(name = "terrasynth", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a heightfield's size, cell size, height range and nodata count.
    Info(data::info::Args),
    /// Convert a heightfield between formats (chosen by extension).
    Convert(data::convert::Args),
    /// Write slope, flow accumulation, terrain-type and splat masks of a heightfield.
    Masks(terrain::masks::Args),
    /// Write a triangle mesh (glTF, GLB or OBJ) of a heightfield: regular
    /// or adaptive (error-bounded), with LODs, tiles, skirts, normals, UVs.
    Mesh(terrain::mesh::Args),
    /// Write a tangent-space normal map (PNG, OpenGL or DirectX Y) of a
    /// heightfield, for the UVs of `mesh --uv`.
    Normals(terrain::normals::Args),
    /// Fill depressions and route water: filled surface, lakes (water
    /// depth), flow accumulation, rivers (raster and GeoJSON lines).
    Water(terrain::water::Args),
    /// Erode a heightfield: a few local steps of stream-power incision and
    /// hillslope creep (windows of a world erode like crops of it).
    Erode(terrain::erode::Args),
    /// Time synthesis: median ms per size, level and stage, and memory per pixel.
    Bench(measure::bench::Args),
    /// Build or inspect an exemplar database.
    #[command(subcommand)]
    Db(data::db::Command),
    /// Synthesize a terrain from real exemplars (the embedded ones by default).
    Synth(synthesis::synth::Args),
    /// Write a whole world as a directory of tiles (each a window of it,
    /// exactly), a manifest and a GDAL mosaic; resumable.
    Tiles(synthesis::tiles::Args),
    /// Apply scene files in order as edits of one session, writing every
    /// frame, its preview and a report of where the terrain changed.
    Edit(editing::edit::Args),
    /// Draw a shaded relief map (PNG) of a heightfield.
    Render(terrain::render::Args),
    /// Generate a procedural terrain in a default exemplar style (see --list).
    Generate(synthesis::generate::Args),
    /// Turn a ridge/valley sketch into terrain made of real DEM patches.
    Sketch(synthesis::sketch::Args),
    /// The interactive editor: a web page on this machine where you sketch,
    /// paint and drag constraints and see the terrain change.
    #[cfg(feature = "serve")]
    Serve(editing::serve::Args),
    /// Measure how real a synthesis is against a real DEM (descriptor
    /// distances, realism ratio, type usage), or run the realism protocol
    /// over a folder of DEMs (--suite).
    Eval(measure::eval::Args),
}

/// What every subcommand returns: a message for the user on failure.
pub type CliResult = Result<(), Box<dyn std::error::Error + Send + Sync>>;

fn main() -> ExitCode {
    let cli = Cli::parse();
    #[cfg(feature = "serve")]
    let serving = matches!(cli.command, Command::Serve(_));
    #[cfg(not(feature = "serve"))]
    let serving = false;
    if !serving {
        default_sigpipe();
    }
    let result = match cli.command {
        Command::Info(a) => data::info::run(a),
        Command::Convert(a) => data::convert::run(a),
        Command::Masks(a) => terrain::masks::run(a),
        Command::Mesh(a) => terrain::mesh::run(a),
        Command::Normals(a) => terrain::normals::run(a),
        Command::Water(a) => terrain::water::run(a),
        Command::Erode(a) => terrain::erode::run(a),
        Command::Bench(a) => measure::bench::run(a),
        Command::Db(c) => data::db::run(c),
        Command::Render(a) => terrain::render::run(a),
        Command::Synth(a) => synthesis::synth::run(a),
        Command::Tiles(a) => synthesis::tiles::run(a),
        Command::Edit(a) => editing::edit::run(a),
        Command::Generate(a) => synthesis::generate::run(a),
        Command::Sketch(a) => synthesis::sketch::run(a),
        #[cfg(feature = "serve")]
        Command::Serve(a) => editing::serve::run(a),
        Command::Eval(a) => measure::eval::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // Print the cause chain, skipping causes the message already states.
            let mut shown = e.to_string();
            eprintln!("error: {shown}");
            let mut source = e.source();
            while let Some(s) = source {
                let text = s.to_string();
                if !shown.contains(&text) {
                    eprintln!("  caused by: {text}");
                    shown = text;
                }
                source = s.source();
            }
            ExitCode::FAILURE
        }
    }
}

/// A closed stdout ends a command quietly, as it does any Unix tool
/// (`terrasynth bench | head -1`): Rust starts programs with SIGPIPE
/// ignored, so `println!` into a closed pipe panicked instead. The server
/// keeps it ignored: a client hanging up must not end it.
fn default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: the first thing `main` does, before any thread exists; SIG_DFL
    // is a valid disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
