//! `terrasynth masks`: slope, flow accumulation, terrain types and an
//! optional splat map beside a heightfield (see `terrasynth::masks`).

use crate::{CliResult, args::Input};
use std::path::PathBuf;
use terrasynth::io::write_atomic;
use terrasynth::masks::{self, encode_png8};
use terrasynth::procedural::TypeMask;

#[derive(clap::Args)]
pub struct Args {
    /// The heightfield.
    input: PathBuf,
    /// Folder for slope.png, flow.png, types.png (+ types.json), splat.png
    /// and masks.json (what each value means).
    #[arg(long)]
    out_dir: PathBuf,
    /// Also write splat.png: RGBA weights summing to 255 (R grass, G rock,
    /// B snow, A wet ground), for engine terrain layers.
    #[arg(long)]
    splat: bool,
    #[command(flatten)]
    read: Input,
}

pub fn run(a: Args) -> CliResult {
    let hf = a.read.read(&a.input)?;
    if hf.nodata_count() > 0 {
        return Err(format!(
            "{}: {} nodata samples; masks need every height (fill them: terrasynth convert --fill-nodata IN OUT)",
            a.input.display(),
            hf.nodata_count()
        )
        .into());
    }
    std::fs::create_dir_all(&a.out_dir)
        .map_err(|e| format!("cannot create {}: {e}", a.out_dir.display()))?;
    let (w, h) = (hf.width(), hf.height());
    let m = masks::compute(&hf, a.splat)?;
    let types = TypeMask::classify(&hf);
    let name = a.input.display().to_string();
    let mut files = vec![
        ("slope.png", encode_png8(w, h, 1, &m.slope)),
        ("flow.png", encode_png8(w, h, 1, &m.flow)),
        ("types.png", types.encode_png()),
        (
            "types.json",
            types.encode_json(&name, "terrasynth masks: TypeMask::classify"),
        ),
    ];
    if let Some(s) = &m.splat {
        files.push(("splat.png", encode_png8(w, h, 4, s.as_flattened())));
    }
    let legend = serde_json::json!({
        "heightfield": name,
        "width": w,
        "height": h,
        "cell_size_m": hf.cell_size(),
        "slope.png": "slope in degrees = value x 90 / 255",
        "flow.png": "D8 flow accumulation on the depression-filled surface (as terrasynth water): cells = exp(value / 255 x ln(width x height))",
        "types.png": "terrain type index, names in types.json",
        "splat.png": if a.splat { "RGBA weights summing to 255: R grass, G rock (slope > 30 deg), B snow (top 15 % of the relief), A wet (top quarter of log flow)" } else { "not written (--splat)" },
    });
    let mut text = serde_json::to_vec_pretty(&legend)?;
    text.push(b'\n');
    files.push(("masks.json", text));
    for (file, bytes) in &files {
        let p = a.out_dir.join(file);
        if terrasynth::io::same_file(&p, &a.input) {
            return Err(format!("{}: refusing to overwrite the input", p.display()).into());
        }
        write_atomic(&p, bytes)?;
    }
    eprintln!(
        "wrote {} masks ({w} x {h}) to {}",
        files.len(),
        a.out_dir.display()
    );
    Ok(())
}
