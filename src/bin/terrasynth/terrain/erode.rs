//! `terrasynth erode`: the local erosion filter (see `terrasynth::erode`).

use crate::{
    CliResult,
    args::{Input, parse_format, write_output},
};
use std::path::PathBuf;
use std::time::Instant;
use terrasynth::erode::{DEFAULT_STRENGTH, MAX_STRENGTH};
use terrasynth::io::Format;

#[derive(clap::Args)]
pub struct Args {
    /// Input heightfield (any readable format; no nodata).
    input: PathBuf,
    /// Output heightfield; the format follows the extension. Never the
    /// input.
    #[arg(short, long)]
    output: PathBuf,
    /// Strength, 0 (unchanged) to 10: stream-power incision and hillslope
    /// creep both scale with it.
    #[arg(long, default_value_t = DEFAULT_STRENGTH)]
    strength: f32,
    /// Output format, when the extension does not say it.
    #[arg(long = "out-format", value_parser = parse_format)]
    out_format: Option<Format>,
    #[command(flatten)]
    read: Input,
}

/// Parses `--erode`'s strength, refusing what `erode` would.
pub fn parse_strength(s: &str) -> Result<f32, String> {
    let v: f32 = s
        .parse()
        .map_err(|_| format!("invalid strength {s:?}: expected a number in 0..={MAX_STRENGTH}"))?;
    if v.is_finite() && (0.0..=MAX_STRENGTH).contains(&v) {
        Ok(v)
    } else {
        Err(format!(
            "strength {v} is invalid: expected a finite value in 0..={MAX_STRENGTH}"
        ))
    }
}

pub fn run(a: Args) -> CliResult {
    crate::synthesis::synth::check_outputs(&[Some(&a.output)], &[&a.input])?;
    let hf = a.read.read(&a.input)?;
    let t = Instant::now();
    let out = terrasynth::erode::erode(&hf, a.strength)
        .map_err(|e| format!("{}: {e}", a.input.display()))?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    write_output(&out, &a.output, a.out_format, None, &[&a.input])?;
    eprintln!(
        "wrote {} ({} x {}, strength {}) in {ms:.0} ms",
        a.output.display(),
        out.width(),
        out.height(),
        a.strength
    );
    Ok(())
}
