//! Argument pieces shared by several subcommands.

use clap::Args as ClapArgs;
use std::path::Path;
use terrasynth::io::{self, Format, ReadOptions};

/// How to read an input heightfield.
#[derive(ClapArgs, Debug, Clone, Default)]
pub struct Input {
    /// Input format, when the extension does not say it.
    #[arg(long = "in-format", value_parser = parse_format)]
    pub format: Option<Format>,
    /// Dimensions WxH of headerless raw input (R16/R32) without a sidecar.
    #[arg(long = "in-size", value_parser = parse_size)]
    pub size: Option<(usize, usize)>,
    /// Cell size in metres. A georeferenced input (GeoTIFF, SRTM tile, ASC
    /// with .prj) is resampled to square cells of this size; any other
    /// input's cell size is overridden. Geographic inputs are resampled to
    /// square cells of their north-south spacing without it.
    #[arg(long = "cell-size")]
    pub cell_size: Option<f64>,
    /// Band of a multi-band GeoTIFF, 1-based (as gdal_translate -b).
    #[arg(long)]
    pub band: Option<usize>,
}

impl Input {
    pub fn read(&self, path: &Path) -> Result<terrasynth::Heightfield, io::IoError> {
        self.load(path).map(|l| l.heightfield)
    }

    /// Reads with what the reader decided, printing its notices.
    pub fn load(&self, path: &Path) -> Result<io::Loaded, io::IoError> {
        let loaded = io::load(
            path,
            &ReadOptions {
                format: self.format,
                size: self.size,
                cell_size: self.cell_size,
                band: self.band,
            },
        )?;
        for n in &loaded.grid.notes {
            eprintln!("note: {}: {n}", path.display());
        }
        Ok(loaded)
    }
}

pub fn parse_format(s: &str) -> Result<Format, String> {
    Format::from_name(&s.to_ascii_lowercase())
        .ok_or_else(|| format!("unknown format {s:?}: expected one of {}", Format::list()))
}

/// Parses `WxH` (e.g. `1024x768`); each side in 1..=65535.
pub fn parse_size(s: &str) -> Result<(usize, usize), String> {
    let err =
        || format!("invalid size {s:?}: expected WxH with each side in 1..=65535, e.g. 1024x1024");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(err)?;
    let w: usize = w.trim().parse().map_err(|_| err())?;
    let h: usize = h.trim().parse().map_err(|_| err())?;
    if (1..=65535).contains(&w) && (1..=65535).contains(&h) {
        Ok((w, h))
    } else {
        Err(err())
    }
}

/// Parses a world size `WxH` (e.g. `65536x65536`); each side in
/// 1..=1048576. Only windows of a world are ever allocated (`--window`,
/// `tiles`), so a world may be far larger than memory.
pub fn parse_world_size(s: &str) -> Result<(usize, usize), String> {
    let max = terrasynth::size::MAX_SIDE;
    let err = || {
        format!("invalid size {s:?}: expected WxH with each side in 1..={max}, e.g. 65536x65536")
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(err)?;
    let w: usize = w.trim().parse().map_err(|_| err())?;
    let h: usize = h.trim().parse().map_err(|_| err())?;
    if (1..=max).contains(&w) && (1..=max).contains(&h) {
        Ok((w, h))
    } else {
        Err(err())
    }
}

/// Parses a window `X,Y,W,H` of output pixels (W, H ≥ 1; whether it fits
/// the world is checked against `--size`).
pub fn parse_window(s: &str) -> Result<terrasynth::synth::cone::Rect, String> {
    let err = || {
        format!(
            "invalid window {s:?}: expected X,Y,W,H in output pixels with W and H at least 1, e.g. 4096,8192,1024,1024"
        )
    };
    let v: Vec<usize> = s
        .split(',')
        .map(|p| p.trim().parse().map_err(|_| err()))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, w, h] if w >= 1 && h >= 1 => Ok(terrasynth::synth::cone::Rect::new(x, y, w, h)),
        _ => Err(err()),
    }
}

/// Loads `--db`, or the embedded default database (built and cached on
/// first use, with a progress bar and a one-line notice).
pub fn load_database(
    db: Option<&Path>,
) -> Result<terrasynth::database::Database, terrasynth::database::DbError> {
    use terrasynth::database::{Database, default};
    match db {
        Some(p) => Database::load(p),
        None => {
            let dir = default::cache_dir();
            if !default::cache_path(&dir).exists() {
                eprintln!(
                    "building the default database from the embedded SRTM DEMs ({}); cached in {}",
                    default::names().join(", "),
                    dir.display()
                );
            }
            Ok(default::load_or_build(&dir, &crate::progress::Bar::new())?.0)
        }
    }
}

/// `--backend`: where the synthesis stages run.
/// The synthesis parameters `synth` and `tiles` share (one definition, so
/// the two commands cannot drift apart in flags, defaults or help).
#[derive(ClapArgs, Debug, Clone)]
pub struct SynthesisArgs {
    /// Jitter amplitude r in texels (paper default 0.4; 0 reproduces the exemplar).
    #[arg(long, default_value_t = 0.4)]
    pub jitter: f64,
    /// Correction passes per level (the start level takes up to 4× as many
    /// for exemplars smooth at the pixel scale).
    #[arg(long, default_value_t = 2)]
    pub passes: u32,
    /// Exemplar (index) the synthesis starts from: its pieces make the
    /// coarse structure and the output takes its cell size. Default: pieces
    /// from every exemplar, exemplar 0's cell size.
    #[arg(long)]
    pub start_exemplar: Option<usize>,
    /// Side in pixels (8..=1024) of the exemplar pieces the coarse start
    /// lays: the knob between new and faithful. Small pieces (default)
    /// make new landforms; large ones (256, 512) keep the exemplars' own
    /// massifs and valleys whole — and repeat them across a world.
    #[arg(long, default_value_t = terrasynth::synth::Params::default().piece_size)]
    pub piece_size: usize,
    /// Height prior P of the correction: 0 (the paper's pure relative
    /// height matching), 1, 2, 4 or 8. Higher keeps candidates nearer the
    /// altitude the coarser level chose (more relief, less drift).
    #[arg(long, default_value_t = terrasynth::stages::correct::DEFAULT_PRIOR)]
    pub height_prior: u32,
    /// The finest level whose correction also scores each source's most
    /// similar texel C₂ (k = 2); finer levels score C₁ alone. 0 is the
    /// paper's k = 2 at every level; the default leaves out level 0, where
    /// C₂ almost never wins.
    #[arg(long, default_value_t = terrasynth::synth::Params::default().similar_from)]
    pub similar_from: usize,
}

impl SynthesisArgs {
    /// The engine's parameters; `keep_levels` when the level maps are wanted.
    pub fn params(&self, keep_levels: bool) -> terrasynth::synth::Params {
        terrasynth::synth::Params {
            jitter: self.jitter,
            passes: self.passes,
            start_exemplar: self.start_exemplar,
            piece_size: self.piece_size,
            prior: self.height_prior,
            similar_from: self.similar_from,
            keep_levels,
        }
    }
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum BackendArg {
    /// The rayon + SIMD stages (the reference).
    Cpu,
    /// The WGSL stages on a Vulkan GPU (needs a build with `--features gpu`).
    Gpu,
    /// The GPU when one is found, else the CPU (with a one-line notice).
    Auto,
}

impl From<BackendArg> for terrasynth::backend::Choice {
    fn from(a: BackendArg) -> Self {
        use terrasynth::backend::Choice;
        match a {
            BackendArg::Cpu => Choice::Cpu,
            BackendArg::Gpu => Choice::Gpu,
            BackendArg::Auto => Choice::Auto,
        }
    }
}

/// Moves `synth` to the requested backend, printing Auto's fallback notice.
pub fn select_backend(
    synth: &mut terrasynth::synth::Synthesizer<'_>,
    arg: BackendArg,
) -> Result<(), terrasynth::synth::SynthError> {
    if let Some(notice) = synth.use_backend(arg.into())? {
        eprintln!("note: {notice}");
    }
    Ok(())
}

/// `--for`: a game engine's heightmap conventions.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum EngineArg {
    /// Unity Terrain: 16-bit RAW (.raw), 2^n+1 square, rows south to north.
    Unity,
    /// Unreal Landscape: 16-bit PNG or .r16 of a recommended size.
    Unreal,
}

impl From<EngineArg> for terrasynth::io::engine::Engine {
    fn from(e: EngineArg) -> Self {
        match e {
            EngineArg::Unity => Self::Unity,
            EngineArg::Unreal => Self::Unreal,
        }
    }
}

/// Writes an output heightfield: never over one of `inputs`, with the
/// engine's conventions and import settings when `engine` is given, and
/// the writer's notices printed.
pub fn write_output(
    hf: &terrasynth::Heightfield,
    path: &Path,
    format: Option<Format>,
    engine: Option<EngineArg>,
    inputs: &[&Path],
) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    use terrasynth::io::engine::{self, Engine};
    let mut opts = io::WriteOptions {
        format,
        inputs: inputs.iter().map(|p| p.to_path_buf()).collect(),
        ..Default::default()
    };
    let mut prepared = None;
    let hf = match engine {
        None => hf,
        Some(e) => {
            let e = Engine::from(e);
            let ext = path
                .extension()
                .and_then(|x| x.to_str())
                .unwrap_or("")
                .to_ascii_lowercase();
            if format.is_some() || !e.accepts(&ext) {
                return Err(format!(
                    "--for {} writes {}; name the output accordingly (e.g. terrain.{})",
                    e.name(),
                    if e == Engine::Unity {
                        "a 16-bit .raw"
                    } else {
                        "a 16-bit .png or .r16"
                    },
                    if e == Engine::Unity { "raw" } else { "png" }
                )
                .into());
            }
            let p = prepared.insert(engine::prepare(hf, e)?);
            for n in &p.notes {
                eprintln!("note: {n}");
            }
            opts.south_up = p.south_up;
            &p.heightfield
        }
    };
    for n in io::write_noted(hf, path, &opts)? {
        eprintln!("note: {n}");
    }
    if let Some(p) = &prepared {
        eprintln!("import settings for {}:", path.display());
        for s in &p.settings {
            eprintln!("  {s}");
        }
    }
    Ok(())
}
