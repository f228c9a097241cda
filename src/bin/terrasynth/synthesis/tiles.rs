//! `terrasynth tiles`: a whole world as a directory of tiles, a manifest
//! and a GDAL mosaic (see `terrasynth::tiles`).

use crate::CliResult;
use crate::args::{
    BackendArg, EngineArg, SynthesisArgs, load_database, parse_world_size, select_backend,
};
use std::path::PathBuf;
use std::time::Instant;
use terrasynth::io::engine::Engine;
use terrasynth::io::{self, Format};
use terrasynth::scene::{Scene, WindowedScene};
use terrasynth::synth::Synthesizer;
use terrasynth::synth::cone::Rect;
use terrasynth::tiles::{self, Tiling, grid::Grid};

#[derive(clap::Args)]
pub struct Args {
    /// Folder for the tiles, manifest.json and world.vrt. Running again
    /// over it resumes: tiles whose CRC verifies are kept.
    #[arg(long)]
    out_dir: PathBuf,
    /// World size WxH (each side up to 1048576, e.g. 65536x65536).
    #[arg(long, value_parser = parse_world_size, required_unless_present = "scene")]
    size: Option<(usize, usize)>,
    /// A scene file: the world is its terrain (its database, size, seed and
    /// controls replace --db, --size, --seed, --jitter, --passes,
    /// --start-exemplar and --height-prior).
    #[arg(long, conflicts_with_all = ["db", "size", "seed", "jitter", "passes", "start_exemplar", "piece_size", "height_prior"])]
    scene: Option<PathBuf>,
    /// Tile side in pixels (the last row and column may be shorter)
    /// [default: 1024]. With --for: samples per tile file, its shared edge
    /// included — Unreal 127, 253, 505, 1009 (default), 2017, 4033, 8129;
    /// Unity 33 … 1025 (default) … 4097 (2^k + 1).
    #[arg(long)]
    tile: Option<usize>,
    /// Extra pixels each tile file holds on every side (shared with its
    /// neighbours, for tools that blend tile borders; the mosaic uses the
    /// cores only). At most the tile size.
    #[arg(long, default_value_t = 0)]
    overlap: usize,
    /// Tile format [default: tiff].
    #[arg(long, value_enum, conflicts_with = "engine")]
    format: Option<TileFormat>,
    /// Lay the tiles out for a game engine: its names, sizes and format,
    /// neighbours sharing their edge samples (so the engine joins them
    /// without seams), and import.json with the scales and positions to
    /// import them at (also printed). The world must be k x (tile − 1) + 1
    /// samples on each side. unreal: tile_x<X>_y<Y>.png, 16-bit PNG;
    /// unity: tile_<X>_<Z>.raw, 16-bit RAW (Windows byte order), rows south
    /// first, Z northwards.
    #[arg(long = "for", value_enum, conflicts_with_all = ["overlap", "water"])]
    engine: Option<EngineArg>,
    /// 16-bit formats (png, r16): metres MIN,MAX mapped onto the codes,
    /// the same for every tile. Default: the database's height range
    /// widened by a quarter of it on each side.
    #[arg(long, value_parser = parse_range)]
    height_range: Option<(f64, f64)>,
    /// Exemplar database (.tsdb); default: the embedded one.
    #[arg(long)]
    db: Option<PathBuf>,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    #[command(flatten)]
    synthesis: SynthesisArgs,
    /// Where the stages run: cpu, gpu or auto. Same tiles on each.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
    /// Also the world's water, bit for bit `terrasynth water` on the whole
    /// world: per tile tile_<col>_<row>.{filled,lakes,flow,rivers}.tif (its
    /// core), and filled.vrt, lakes.vrt, flow.vrt, rivers.vrt. Computed
    /// again on every run.
    #[arg(long)]
    water: bool,
    #[command(flatten)]
    water_params: crate::terrain::water::Knobs,
}

/// `--format`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
enum TileFormat {
    /// Float32 GeoTIFF, placed in the world's local grid.
    Tiff,
    /// OpenEXR, one float channel.
    Exr,
    /// 16-bit PNG with a JSON sidecar (metres mapping).
    Png,
    /// Headerless 16-bit little-endian with a JSON sidecar (Unity/Unreal).
    R16,
}

impl From<TileFormat> for Format {
    fn from(f: TileFormat) -> Format {
        match f {
            TileFormat::Tiff => Format::Tiff,
            TileFormat::Exr => Format::Exr,
            TileFormat::Png => Format::Png16,
            TileFormat::R16 => Format::R16,
        }
    }
}

/// Parses `MIN,MAX` metres.
fn parse_range(s: &str) -> Result<(f64, f64), String> {
    let err = || format!("invalid height range {s:?}: expected MIN,MAX in metres with MIN < MAX");
    let (a, b) = s.split_once(',').ok_or_else(err)?;
    let (a, b): (f64, f64) = (
        a.trim().parse().map_err(|_| err())?,
        b.trim().parse().map_err(|_| err())?,
    );
    if a.is_finite() && b.is_finite() && a < b {
        Ok((a, b))
    } else {
        Err(err())
    }
}

/// What the tiles are windows of: a plain synthesis or a scene.
enum World {
    Plain { size: (usize, usize), seed: u32 },
    Scene(Box<WindowedScene>),
}

pub fn run(a: Args) -> CliResult {
    if a.water_params.any() && !a.water {
        return Err(
            "--sea-level, --river-area, --lake-min-depth and --lake-min-area need --water".into(),
        );
    }
    let water_params = a.water_params.params();
    water_params.check()?;
    let scene = a.scene.as_deref().map(Scene::read).transpose()?;
    let db_path = match &scene {
        Some(s) => s.database.clone(),
        None => a.db.clone(),
    };
    let db = load_database(db_path.as_deref())?;
    let (world, params) = match &scene {
        Some(s) => {
            let ws = WindowedScene::new(s, &db)?;
            let params = ws.params();
            (World::Scene(Box::new(ws)), params)
        }
        None => {
            let params = a.synthesis.params(false);
            let size = a.size.expect("clap requires --size without --scene");
            (World::Plain { size, seed: a.seed }, params)
        }
    };
    let size = match &world {
        World::Plain { size, .. } => *size,
        World::Scene(s) => (s.width, s.height),
    };
    let mut synth = Synthesizer::new(&db, params.clone())?;
    select_backend(&mut synth, a.backend)?;
    let engine = a.engine.map(Engine::from);
    let format = match engine {
        Some(e) => tiles::engine::format(e),
        None => Format::from(a.format.unwrap_or(TileFormat::Tiff)),
    };
    // An engine's tile counts samples, shared edge included; the grid, quads.
    let tile = match engine {
        Some(e) => a
            .tile
            .unwrap_or(tiles::engine::default_samples(e))
            .saturating_sub(1),
        None => a.tile.unwrap_or(1024),
    };
    let grid = Grid {
        world: size,
        tile,
        overlap: a.overlap,
        engine,
    };
    // Memory: one tile's cone per thread, for a tile amid the world (at
    // the edges the cone is smaller); a scene's tiles hold about three
    // times that (its first frame's passes are recorded for the pastes).
    let (w, h) = size;
    let side = |n: usize| (tile + usize::from(engine.is_some()) + 2 * a.overlap).min(n);
    let (tw, th) = (side(w), side(h));
    let probe = Rect::new((w - tw) / 2, (h - th) / 2, tw, th);
    let cone = synth
        .window_cone(size, probe)
        .map_err(crate::synthesis::synth::window_error(probe))?;
    let threads = rayon::current_num_threads() as u64;
    let factor = if scene.is_some() { 3 } else { 1 };
    io::check_memory(
        &format!("{threads} tiles of {tw}x{th} in parallel"),
        cone.bytes() * threads * factor,
    )?;
    if a.water {
        let (cw, ch) = (tile.min(w), tile.min(h));
        let rings = (w.div_ceil(tile) * h.div_ceil(tile) * 2 * (cw + ch)) as u64;
        io::check_memory(
            &format!("water of {threads} tiles of {cw}x{ch} in parallel"),
            terrasynth::water::tiled::BYTES_PER_CELL * (cw * ch) as u64 * threads
                + rings * terrasynth::water::tiled::BYTES_PER_RING_CELL,
        )?;
    }
    let height_range_m = matches!(format, Format::Png16 | Format::R16).then(|| {
        a.height_range
            .unwrap_or_else(|| tiles::default_height_range(db.quantization()))
    });
    let crc = |b: &[u8]| format!("0x{:08x}", crc32fast::hash(b));
    let mut source = serde_json::json!({
        "database": {
            "file": db_path.as_ref().map(|p| p.display().to_string()),
            "crc32": crc(db.file_bytes()),
        },
        "jitter": params.jitter,
        "passes": params.passes,
        // What the engine made of them (the start level's passes follow
        // the exemplars): tiles of a directory written before that rule
        // are not kept beside tiles written after it.
        "level_passes": synth.level_passes(w, h),
        "start_exemplar": params.start_exemplar,
        "piece_size": params.piece_size,
        "height_prior": params.prior,
    });
    source["seed"] = match &world {
        World::Plain { seed, .. } => *seed,
        World::Scene(s) => s.seed,
    }
    .into();
    if let Some(path) = &a.scene {
        // The scene file itself (images it names are not checked).
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        source["scene"] = serde_json::json!({
            "file": path.display().to_string(),
            "crc32": crc(&bytes),
        });
    }
    let tiling = Tiling {
        grid,
        format,
        height_range_m,
        cell_size_m: synth.cell_size_m(),
        source,
    };
    let t = Instant::now();
    let window = |r: Rect| match &world {
        World::Plain { size, seed } => synth.synthesize_window(*size, r, *seed),
        World::Scene(s) => s.synthesize_window(&synth, r),
    };
    let s = tiles::write(&tiling, &a.out_dir, &window, &crate::progress::Bar::new())?;
    let secs = t.elapsed().as_secs_f64();
    let (cols, rows) = grid.size();
    eprintln!(
        "wrote {} of {} tiles ({cols} x {rows}; {} kept from an earlier run) of a {w}x{h} world to {} in {secs:.1} s ({:.2} MP/s)",
        s.written,
        cols * rows,
        s.kept,
        a.out_dir.display(),
        s.pixels as f64 / 1e6 / secs.max(1e-9)
    );
    if s.clamped > 0 {
        let (lo, hi) = height_range_m.expect("16-bit formats have a range");
        eprintln!(
            "note: {} samples lay outside the height range {lo:.1}..{hi:.1} m and were clamped (widen it with --height-range)",
            s.clamped
        );
    }
    if a.water {
        let t = Instant::now();
        let r = tiles::water::write(
            &tiling,
            &a.out_dir,
            &water_params,
            &crate::progress::Bar::new(),
        )?;
        eprintln!(
            "water: {} lakes; flats settled in {} rounds, flow in {}; {:.1} s (filled.vrt, lakes.vrt, flow.vrt, rivers.vrt)",
            r.lakes,
            r.flat_rounds,
            r.flow_rounds,
            t.elapsed().as_secs_f64()
        );
    }
    if let Some(settings) = &s.import {
        eprintln!("{}", tiles::engine::summary(settings));
        eprintln!("wrote {}", a.out_dir.join(tiles::IMPORT_FILE).display());
    }
    eprintln!("wrote {}", s.manifest.display());
    match &s.vrt {
        Some(v) => eprintln!("wrote {} (open the mosaic in GDAL or QGIS)", v.display()),
        None => eprintln!("note: GDAL cannot open {format} tiles, so no world.vrt was written"),
    }
    Ok(())
}
