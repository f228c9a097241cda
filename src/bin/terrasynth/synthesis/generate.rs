//! `terrasynth generate`: a procedural terrain in one of the built-in
//! styles, with its terrain-type mask.

use crate::CliResult;
use crate::progress::Bar;
use std::path::PathBuf;
use terrasynth::io::{self, WriteOptions};
use terrasynth::procedural::Style;
use terrasynth::procedural::styles::{DEFAULT_SEED, DEFAULT_SIZE};

#[derive(clap::Args)]
#[command(
    after_help = "Besides OUT, writes the terrain-type mask OUT_types.png (8-bit, one type index per pixel) and OUT_types.json (the type names).\nThe same style, size and seed give the same bytes on every machine and thread count.\nThe embedded default database is real terrain (SRTM DEMs, see data/CREDITS.md), not these styles; build a database of generated terrain with `terrasynth db build`."
)]
pub struct Args {
    /// Terrain style (see --list).
    #[arg(long, required_unless_present = "list")]
    style: Option<String>,
    /// Output heightfield; the format follows the extension (.png: 16-bit + JSON sidecar).
    #[arg(short, long, required_unless_present = "list")]
    output: Option<PathBuf>,
    /// Side of the square terrain in cells of 30 m (at least 32); larger shows more landscape.
    #[arg(long, default_value_t = DEFAULT_SIZE as u32, value_parser = clap::value_parser!(u32).range(32..=8192))]
    size: u32,
    /// Random seed; the same seed always gives the same terrain.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    seed: u32,
    /// List the styles and exit.
    #[arg(long)]
    list: bool,
}

pub fn run(a: Args) -> CliResult {
    if a.list {
        for s in Style::ALL {
            println!("{:<8} {}", s.name(), s.description());
        }
        return Ok(());
    }
    let (Some(name), Some(out)) = (a.style, a.output) else {
        return Err("--style and --output are required".into());
    };
    let style = Style::from_name(&name)?;
    let bar = Bar::new();
    let (hf, types) = style.generate(a.size as usize, a.seed, &bar)?;
    io::write(&hf, &out, &WriteOptions::default())?;
    types.write_beside(&out, &style.types_method(a.size as usize, a.seed))?;
    eprintln!(
        "wrote {} and {} ({} x {}, {} style, seed {})",
        out.display(),
        terrasynth::procedural::TypeClassification::path_for(&out).display(),
        hf.width(),
        hf.height(),
        style.name(),
        a.seed
    );
    Ok(())
}
