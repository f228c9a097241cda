//! `terrasynth masks`: slope, flow accumulation, terrain types and an
//! optional splat map beside a heightfield (see `terrasynth::masks`).

use crate::CliResult;
use crate::args::{EngineArg, Input};
use std::path::PathBuf;
use terrasynth::io::engine::{self, Engine};
use terrasynth::io::write_atomic;
use terrasynth::masks::{self, encode_png8};
use terrasynth::procedural::TypeClassification;

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
    /// Masks for a game engine: those of the heightmap as `convert --for`
    /// writes it (resampled to the engine's size, the same import). With
    /// --splat, unreal gets one 8-bit weightmap per layer at the
    /// heightmap's size (splat_grass.png, splat_rock.png, splat_snow.png,
    /// splat_wet.png: Landscape target layers, weight-blended); unity gets
    /// splat.png with one texel per terrain cell (2^n, the Control Texture
    /// Resolution of a 2^n + 1 heightmap).
    #[arg(long = "for", value_enum)]
    engine: Option<EngineArg>,
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
    let engine = a.engine.map(Engine::from);
    let prepared = engine.map(|e| engine::prepare(&hf, e)).transpose()?;
    for n in prepared.iter().flat_map(|p| &p.notes) {
        eprintln!("note: {n}");
    }
    let hf = prepared.as_ref().map_or(&hf, |p| &p.heightfield);
    let (w, h) = (hf.width(), hf.height());
    let m = masks::compute(hf, a.splat)?;
    let types = TypeClassification::classify(hf);
    let name = a.input.display().to_string();
    let mut files = vec![
        ("slope.png".to_string(), encode_png8(w, h, 1, &m.slope)),
        ("flow.png".to_string(), encode_png8(w, h, 1, &m.flow)),
        ("types.png".to_string(), types.encode_png()),
        (
            "types.json".to_string(),
            types.encode_json(&name, "terrasynth masks: TypeMask::classify"),
        ),
    ];
    let splat_legend = match (&m.splat, engine) {
        (None, _) => "not written (--splat)".to_string(),
        (Some(s), Some(Engine::Unreal)) => {
            for (layer, weights) in masks::SPLAT_LAYERS.iter().zip(masks::splat_layers(s)) {
                files.push((format!("splat_{layer}.png"), encode_png8(w, h, 1, &weights)));
            }
            format!(
                "not written: one weightmap per layer, splat_<layer>.png ({w} x {h}, the heightmap's size), weights summing to 255 across the layers"
            )
        }
        (Some(s), Some(Engine::Unity)) => {
            let cells = masks::splat_cells(s, w, h);
            files.push((
                "splat.png".to_string(),
                encode_png8(w - 1, h - 1, 4, cells.as_flattened()),
            ));
            format!(
                "RGBA weights summing to 255, one texel per terrain cell ({} x {}: Control Texture Resolution); R grass, G rock, B snow, A wet",
                w - 1,
                h - 1
            )
        }
        (Some(s), None) => {
            files.push((
                "splat.png".to_string(),
                encode_png8(w, h, 4, s.as_flattened()),
            ));
            "RGBA weights summing to 255: R grass, G rock (slope > 30 deg), B snow (top 15 % of the relief), A wet (top quarter of log flow)".to_string()
        }
    };
    let mut legend = serde_json::json!({
        "heightfield": name,
        "width": w,
        "height": h,
        "cell_size_m": hf.cell_size(),
        "slope.png": "slope in degrees = value x 90 / 255",
        "flow.png": "D8 flow accumulation on the depression-filled surface (as terrasynth water): cells = exp(value / 255 x ln(width x height))",
        "types.png": "terrain type index, names in types.json",
        "splat.png": splat_legend,
    });
    if let Some(e) = engine {
        legend["engine"] = e.name().into();
    }
    let mut text = serde_json::to_vec_pretty(&legend)?;
    text.push(b'\n');
    files.push(("masks.json".to_string(), text));
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
    match engine.filter(|_| a.splat) {
        Some(Engine::Unreal) => eprintln!(
            "Unreal: Landscape > Paint: add weight-blended target layers grass, rock, snow and wet, and import splat_<layer>.png into each"
        ),
        Some(Engine::Unity) => eprintln!(
            "Unity: Terrain Settings > Control Texture Resolution {}; import splat.png as the terrain's splatmap (Terrain Toolbox > Splatmaps), layers grass, rock, snow, wet in R, G, B, A",
            w - 1
        ),
        None => {}
    }
    Ok(())
}
