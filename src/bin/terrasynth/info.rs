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
    let hf = a.input.read(&a.file)?;
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
            "cell:      {} m  ({:.2} x {:.2} km)",
            hf.cell_size(),
            hf.width() as f64 * hf.cell_size() / 1000.0,
            hf.height() as f64 * hf.cell_size() / 1000.0
        );
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
