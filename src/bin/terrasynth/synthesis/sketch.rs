//! `terrasynth sketch`: a ridge/valley sketch becomes terrain built from
//! patches of real DEMs (seeds 001, 004).

use crate::CliResult;
use crate::args::{BackendArg, Input, parse_size};
use crate::progress::Bar;
use std::path::PathBuf;
use terrasynth::backend::engine::Engine;
use terrasynth::io::{self, WriteOptions};
use terrasynth::patch::fill::fill_ssd::FillCost;
use terrasynth::patch::input::sketch::Sketch;
use terrasynth::patch::{self, Library, Params};
use terrasynth::render::{self, RenderOptions};

const ABOUT: &str = "\
Sketch: a grey PNG (mid-grey = no preference, white = ridges, black =
valleys; a smooth grey elevation sketch works too) or JSON polylines:
  {\"width\": 512, \"height\": 512, \"strokes\": [
     {\"kind\": \"ridge\", \"width\": 12, \"points\": [[40, 60], [300, 200]]}]}
Examples in data/sketches/.

Example:
  terrasynth sketch data/sketches/lambda_circle.json \\
      --sources ../shared/dem/*.png -o out.exr --preview out.png";

#[derive(clap::Args)]
#[command(after_help = ABOUT)]
pub struct Args {
    /// The sketch (.json polylines, or an image).
    sketch: PathBuf,
    /// Source DEMs (any readable heightfield format). Those whose 2-98 %
    /// relief is under half the largest one's are left out (with a note):
    /// the others are brought to the largest relief.
    #[arg(long, num_args = 1.., required = true, value_name = "DEM")]
    sources: Vec<PathBuf>,
    /// Output size WxH [default: the sketch's size].
    #[arg(long, value_parser = parse_size)]
    size: Option<(usize, usize)>,
    /// Patch side in pixels (multiple of 8, 16..=256).
    #[arg(long, default_value_t = 64)]
    patch: usize,
    /// Output heightfield (format from the extension).
    #[arg(short, long)]
    output: PathBuf,
    /// Also write a shaded-relief preview PNG.
    #[arg(long)]
    preview: Option<PathBuf>,
    /// Where prepared source features are cached [default:
    /// $TERRASYNTH_CACHE_DIR, else $XDG_CACHE_HOME/terrasynth, else
    /// ~/.cache/terrasynth].
    #[arg(long, value_name = "DIR")]
    cache_dir: Option<PathBuf>,
    /// Prepare every source from scratch and cache nothing.
    #[arg(long, conflicts_with = "cache_dir")]
    no_cache: bool,
    /// Where the data-parallel cost stage (`fill_ssd`) runs: cpu, gpu
    /// (`--features gpu` builds) or auto. Same output bytes on each.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
    #[command(flatten)]
    read: Input,
}

pub fn run(a: Args) -> CliResult {
    let sketch = Sketch::read(&a.sketch)?;
    let (w, h) = a.size.unwrap_or_else(|| sketch.size());
    let mut sources = Vec::new();
    for p in &a.sources {
        let hf = a.read.read(p)?;
        let name = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        sources.push((name, hf));
    }
    let params = Params {
        patch: a.patch,
        ..Params::default()
    };
    let bar = Bar::new();
    let t_prep = std::time::Instant::now();
    let (lib, hits) = if a.no_cache {
        (Library::prepare(&sources, &params, &bar)?, 0)
    } else {
        let dir = a
            .cache_dir
            .clone()
            .unwrap_or_else(terrasynth::database::default::cache_dir);
        Library::prepare_cached(&sources, &params, &dir, &bar)?
    };
    let prep_ms = t_prep.elapsed().as_secs_f64() * 1e3;
    if !lib.left_out.is_empty() {
        let names: Vec<String> = lib
            .left_out
            .iter()
            .map(|(name, relief)| format!("{name} ({relief:.0} m)"))
            .collect();
        eprintln!(
            "note: {} of {} sources are left out, their 2-98 % relief under half the largest ({:.0} m), which a sketch's ranges take: {}",
            lib.left_out.len(),
            sources.len(),
            lib.relief,
            names.join(", ")
        );
    }
    let (engine, notice) = Engine::choose(a.backend.into())?;
    if let Some(n) = notice {
        eprintln!("note: {n}");
    }
    let cost = FillCost::new(&engine, &lib)?;
    let result = patch::synthesize_with(&lib, &sketch, w, h, &cost, &bar)?;
    io::write(&result.heightfield, &a.output, &WriteOptions::default())?;
    let t = &result.timings;
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    let s = &result.stats;
    eprintln!(
        "wrote {} ({w} x {h}) from {} source(s), {} pits on patch joins raised, fill costs on the {}: {} user patches, {} feature + {} fill patches",
        a.output.display(),
        lib.sources.len(),
        s.join_pits,
        cost.name(),
        s.user_patches,
        s.feature_patches,
        s.fill_patches
    );
    eprintln!(
        "ms: source preparation {prep_ms:.0} ({hits} of {} from the cache); sketch {:.0}, feature round1 {:.0} round2 {:.0} merge {:.0}, fill round1 {:.0} round2 {:.0} merge {:.0}, total {:.0}",
        lib.sources.len(),
        ms(t.sketch),
        ms(t.feature_round1),
        ms(t.feature_round2),
        ms(t.feature_merge),
        ms(t.fill_round1),
        ms(t.fill_round2),
        ms(t.fill_merge),
        ms(t.total)
    );
    if let Some(adh) = patch::adherence(&result.heightfield, &sketch, a.patch as f32 / 16.0) {
        eprintln!("feature adherence (ridge mean - valley or background mean) / relief: {adh:.3}");
    }
    if let Some(p) = &a.preview {
        let preview = render::render_on(&engine, &result.heightfield, &RenderOptions::default())?;
        render::write_png(p, &preview.image)?;
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}
