//! `terrasynth info`: what is in a heightfield file.

use crate::{CliResult, args::Input};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct Args {
    /// The heightfield file.
    file: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    input: Input,
}

pub fn run(a: Args) -> CliResult {
    let loaded = a.input.load(&a.file)?;
    let hf = &loaded.heightfield;
    let georef = hf.georef();
    let crs = georef.map(|g| match &g.crs {
        Some(c) if g.is_local() => format!("{} (local)", c.label()),
        Some(c) => c.label(),
        None => "none given (placed in map units, taken as metres)".to_string(),
    });
    let (dx, dy) = georef.map_or((hf.cell_size(), hf.cell_size()), |g| {
        g.ground_spacing(hf.height())
    });
    let stats = hf.stats();
    let (min, max, mean) = stats.map_or((None, None, None), |s| {
        (Some(s.min), Some(s.max), Some(s.mean))
    });
    let nodata = hf.nodata_count();
    if a.json {
        let v = serde_json::json!({
            "file": a.file,
            "width": hf.width(),
            "height": hf.height(),
            "cell_size_m": hf.cell_size(),
            "cell_size_default": loaded.cell_size_default,
            "spacing_m": { "east_west": dx, "north_south": dy },
            "native_spacing_m": loaded.grid.native_spacing.map(|(x, y)| serde_json::json!({ "east_west": x, "north_south": y })),
            "resampled": !loaded.grid.notes.is_empty(),
            "crs": crs,
            "epsg": georef.and_then(|g| g.crs.as_ref()).and_then(|c| c.epsg),
            "geotransform": georef.map(|g| [g.origin_x, g.pixel_x, 0.0, g.origin_y, 0.0, -g.pixel_y]),
            "min_m": min,
            "max_m": max,
            "mean_m": mean,
            "nodata": nodata,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        println!("file:      {}", a.file.display());
        println!("size:      {} x {} samples", hf.width(), hf.height());
        println!(
            "cell:      {} m{}  ({:.2} x {:.2} km)",
            hf.cell_size(),
            if loaded.cell_size_default {
                " (default: the file gives none; set it with --cell-size)"
            } else {
                ""
            },
            hf.width() as f64 * dx / 1000.0,
            hf.height() as f64 * dy / 1000.0
        );
        println!("spacing:   {dx:.3} m east-west x {dy:.3} m north-south");
        if let Some((nx, ny)) = loaded
            .grid
            .native_spacing
            .filter(|_| !loaded.grid.notes.is_empty())
        {
            println!(
                "as read:   {nx:.3} m east-west x {ny:.3} m north-south (resampled, see the note)"
            );
        }
        println!(
            "crs:       {}",
            crs.as_deref().unwrap_or("none (no georeference)")
        );
        if let Some(g) = georef {
            println!(
                "origin:    {}, {} (top-left corner; cells {} x {} map units, pixel is {:?})",
                g.origin_x, g.origin_y, g.pixel_x, g.pixel_y, g.pixel_is
            );
        }
        match stats {
            Some(s) => println!(
                "heights:   {:.2} .. {:.2} m (mean {:.2} m, relief {:.2} m)",
                s.min,
                s.max,
                s.mean,
                s.max - s.min
            ),
            None => println!("heights:   none (every sample is nodata)"),
        }
        println!("nodata:    {nodata} samples");
    }
    Ok(())
}
