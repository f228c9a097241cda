//! `terrasynth convert`: heightfield format conversion.

use crate::{
    CliResult,
    args::{EngineArg, Input, parse_format, write_output},
};
use std::path::PathBuf;
use terrasynth::io::Format;

#[derive(clap::Args)]
pub struct Args {
    /// Input heightfield; the format follows the extension.
    input: PathBuf,
    /// Output heightfield; the format follows the extension.
    ///
    /// .png: 16-bit greyscale + JSON sidecar with the metre mapping (8-bit is
    /// read only). .exr: 32-bit float. .tif/.tiff: GeoTIFF (int16, uint16,
    /// float32 read; float32 written). .hgt: SRTM tile (read only). .asc:
    /// ESRI ASCII grid. .r16/.raw: little-endian u16 + sidecar. .r32:
    /// little-endian f32 + sidecar. .ter: Terragen. R16 and Terragen cannot
    /// store nodata.
    output: PathBuf,
    /// Output format, when the extension does not say it.
    #[arg(long = "out-format", value_parser = parse_format)]
    out_format: Option<Format>,
    /// Fill nodata samples before writing, by harmonic (Laplace)
    /// interpolation from the valid heights around each hole: the smoothest
    /// surface through the rim, never above or below it. Needed to write
    /// nodata to formats that cannot store it (R16, Terragen).
    #[arg(long)]
    fill_nodata: bool,
    /// Lay the output out for a game engine and print its import settings:
    /// unity (16-bit .raw, 2^n+1 square, rows south to north) or unreal
    /// (16-bit .png or .r16 of a recommended size, with the Z scale).
    #[arg(long = "for", value_enum)]
    engine: Option<EngineArg>,
    #[command(flatten)]
    read: Input,
}

pub fn run(a: Args) -> CliResult {
    let mut hf = a.read.read(&a.input)?;
    if a.fill_nodata {
        let report = terrasynth::nodata::fill_nodata(&mut hf)?;
        if report.filled > 0 {
            eprintln!("filled {} nodata samples", report.filled);
        }
    }
    write_output(&hf, &a.output, a.out_format, a.engine, &[&a.input])?;
    eprintln!(
        "wrote {} ({} x {})",
        a.output.display(),
        hf.width(),
        hf.height()
    );
    Ok(())
}
