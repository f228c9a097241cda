//! A whole world as a directory of tiles (issue 17): one file per tile
//! (GeoTIFF, EXR, 16-bit PNG or R16), each a windowed synthesis of its
//! core plus an overlap, a `manifest.json` ([`manifest`]) and a GDAL
//! mosaic `world.vrt` ([`vrt`]).
//!
//! - **Exact**: each tile is `Synthesizer::synthesize_window` of its
//!   extent, so the cores rebuild the world's synthesis byte for byte — no
//!   blending, no seams.
//! - **Bounded memory**: tiles run in parallel (rayon), each holding only
//!   its cone; peak memory is the cone of one tile times the threads,
//!   whatever the world's size.
//! - **Resumable**: a tile is recorded in the manifest (with its CRC-32)
//!   only after its file is in place; a run over a directory whose
//!   manifest describes the same world keeps every recorded tile whose
//!   file still has its CRC, and makes the rest. The manifest is rewritten
//!   at most every [`SAVE_EVERY`] (and at the end), so an interrupted run
//!   loses at most that much work.
//! - With water (`tiles --water`, [`water`]): per-tile lakes, flow and
//!   rivers equal to the whole world's, written after the height tiles.
//! - For a game engine (`tiles --for unreal|unity`, [`engine`]): its
//!   names, sizes and format, neighbours sharing their edge samples, and
//!   `import.json` with the scales and positions to import them at.
//! - 16-bit formats share one height mapping across tiles (game engines
//!   import tiled heightmaps with one height scale, and the mosaic needs
//!   one): the caller's range, or the database's widened by a quarter on
//!   each side; heights outside it are clamped and counted.

pub mod engine;
pub mod grid;
pub mod manifest;
pub mod vrt;
pub mod water;

use crate::heightfield::Heightfield;
use crate::io::engine::Engine;
use crate::io::{self, Format, HeightMapping, IoError};
use crate::progress::Progress;
use crate::synth::SynthError;
use crate::synth::cone::Rect;
use grid::Grid;
use manifest::{Identity, Manifest, Record};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use thiserror::Error;

/// Longest time between two saves of the manifest during a run.
pub const SAVE_EVERY: Duration = Duration::from_secs(2);

/// The formats tiles are written in.
pub const FORMATS: [Format; 4] = [Format::Tiff, Format::Exr, Format::Png16, Format::R16];

/// What to write.
#[derive(Debug, Clone)]
pub struct Tiling {
    pub grid: Grid,
    pub format: Format,
    /// Metres mapped onto the 16-bit codes (png16, r16); ignored otherwise.
    pub height_range_m: Option<(f64, f64)>,
    pub cell_size_m: f64,
    /// How the world is made (database, seed, parameters, scene): kept in
    /// the manifest, and a resumed run must describe the same.
    pub source: serde_json::Value,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    pub written: usize,
    /// Core pixels of the tiles written (for rates).
    pub pixels: u64,
    /// Tiles kept from an earlier run (their CRC verified).
    pub kept: usize,
    /// Samples clamped into the 16-bit height range.
    pub clamped: u64,
    pub manifest: PathBuf,
    pub vrt: Option<PathBuf>,
    /// For an engine: its import settings, also written to [`IMPORT_FILE`].
    pub import: Option<serde_json::Value>,
}

/// The import settings of an engine tile set, in its directory.
pub const IMPORT_FILE: &str = "import.json";

/// Failures of a tiled run.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum TilesError {
    #[error("tile size {0} is invalid: expected 1..={max}", max = crate::size::MAX_SIDE)]
    TileSize(usize),
    #[error("overlap {overlap} is invalid: expected 0..={tile} (at most the tile size)")]
    Overlap { overlap: usize, tile: usize },
    #[error("tiles cannot be written as {0}: expected one of tiff, exr, png16, r16")]
    Format(Format),
    #[error("height range {0}..{1} m is invalid: expected finite min < max")]
    HeightRange(f64, f64),
    #[error("{0} tiles need one height range for every tile (e.g. `default_height_range`)")]
    NoHeightRange(Format),
    #[error("{engine} tiles of {samples} samples are not imported: expected one of {sizes:?}", engine = .engine.name())]
    EngineSize {
        engine: Engine,
        samples: usize,
        sizes: &'static [usize],
    },
    #[error("{engine} tiles are {format} files with no overlap (got {got} with overlap {overlap})", engine = .engine.name(), format = engine::format(*.engine))]
    EngineLayout {
        engine: Engine,
        got: Format,
        overlap: usize,
    },
    #[error(
        "a {w}x{h} world is not a whole number of {engine} tiles of {samples} samples sharing their edges: each side must be k x {quads} + 1, e.g. {sw}x{sh}",
        engine = .engine.name(), quads = .samples - 1, w = .world.0, h = .world.1,
        sw = fit(.world.0, .samples - 1), sh = fit(.world.1, .samples - 1)
    )]
    EngineWorld {
        engine: Engine,
        world: (usize, usize),
        samples: usize,
    },
    #[error("{path}: {reason}")]
    Manifest { path: PathBuf, reason: String },
    #[error(
        "{dir} holds tiles of another world ({field} differs): choose another directory, or remove its manifest.json to start over"
    )]
    OtherWorld { dir: PathBuf, field: &'static str },
    #[error("tile {file}: {source}")]
    Synth {
        file: String,
        #[source]
        source: SynthError,
    },
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Water(#[from] crate::water::WaterError),
}

/// The world side nearest `n` (at least one tile) made of whole tiles of
/// `quads` quads sharing their edges.
fn fit(n: usize, quads: usize) -> usize {
    ((n.saturating_sub(1) + quads / 2) / quads).max(1) * quads + 1
}

/// The identity a tiling writes into its manifest.
fn identity(t: &Tiling, range: Option<(f64, f64)>) -> Identity {
    Identity {
        world: [t.grid.world.0, t.grid.world.1],
        cell_size_m: t.cell_size_m,
        source: t.source.clone(),
        format: t.format.name().to_string(),
        tile_size: t.grid.tile,
        overlap: t.grid.overlap,
        height_range_m: range.map(|(a, b)| [a, b]),
        engine: t.grid.engine.map(|e| e.name().to_string()),
    }
}

/// Checks a tiling before anything is written.
fn check(t: &Tiling) -> Result<(), TilesError> {
    let g = &t.grid;
    if !(1..=crate::size::MAX_SIDE).contains(&g.tile) {
        return Err(TilesError::TileSize(g.tile));
    }
    if g.overlap > g.tile {
        return Err(TilesError::Overlap {
            overlap: g.overlap,
            tile: g.tile,
        });
    }
    if !FORMATS.contains(&t.format) {
        return Err(TilesError::Format(t.format));
    }
    if let Some(engine) = g.engine {
        let samples = g.tile + 1;
        if !engine.sizes().contains(&samples) {
            return Err(TilesError::EngineSize {
                engine,
                samples,
                sizes: engine.sizes(),
            });
        }
        if t.format != engine::format(engine) || g.overlap != 0 {
            return Err(TilesError::EngineLayout {
                engine,
                got: t.format,
                overlap: g.overlap,
            });
        }
        let whole = |n: usize| n > g.tile && (n - 1) % g.tile == 0;
        if !(whole(g.world.0) && whole(g.world.1)) {
            return Err(TilesError::EngineWorld {
                engine,
                world: g.world,
                samples,
            });
        }
    }
    match t.height_range_m {
        Some((a, b)) if !(a.is_finite() && b.is_finite() && a < b) => {
            Err(TilesError::HeightRange(a, b))
        }
        None if matches!(t.format, Format::Png16 | Format::R16) => {
            Err(TilesError::NoHeightRange(t.format))
        }
        _ => Ok(()),
    }
}

/// The height range 16-bit tiles of a database's worlds default to: the
/// database's own range (its exemplars' lowest to highest height), widened
/// by a quarter of it on each side — synthesized heights are the
/// exemplars' plus offsets that rarely leave it by much — with codes
/// 1/43690 of the exemplars' relief apart.
pub fn default_height_range(q: crate::database::Quantization) -> (f64, f64) {
    let span = 65535.0 * q.scale_m;
    (q.offset_m - span / 4.0, q.offset_m + span * 1.25)
}

/// The first field in which two identities differ.
fn differs(a: &Identity, b: &Identity) -> Option<&'static str> {
    [
        ("world size", a.world == b.world),
        ("cell size", a.cell_size_m == b.cell_size_m),
        (
            "source (database, seed, parameters or scene)",
            a.source == b.source,
        ),
        ("format", a.format == b.format),
        ("tile size", a.tile_size == b.tile_size),
        ("overlap", a.overlap == b.overlap),
        ("height range", a.height_range_m == b.height_range_m),
        ("engine", a.engine == b.engine),
    ]
    .into_iter()
    .find(|(_, same)| !same)
    .map(|(f, _)| f)
}

/// A tile file's bytes and its sidecar's, `None` when either is missing.
fn tile_bytes(path: &Path, format: Format) -> Option<(Vec<u8>, Option<Vec<u8>>)> {
    let bytes = std::fs::read(path).ok()?;
    let sidecar = match format.uses_sidecar() {
        true => Some(std::fs::read(io::sidecar_path(path)).ok()?),
        false => None,
    };
    Some((bytes, sidecar))
}

/// Writes the tiles of `t` into `dir` (created if needed), `window`
/// synthesizing each tile's extent; `progress` counts tiles. See the
/// module docs for resuming.
pub fn write(
    t: &Tiling,
    dir: &Path,
    window: &(dyn Fn(Rect) -> Result<Heightfield, SynthError> + Sync),
    progress: &dyn Progress,
) -> Result<Summary, TilesError> {
    check(t)?;
    std::fs::create_dir_all(dir).map_err(|e| IoError::os(dir, e))?;
    let sixteen = matches!(t.format, Format::Png16 | Format::R16);
    let range = t.height_range_m.filter(|_| sixteen);
    let identity = identity(t, range);
    let ext = match t.format {
        Format::Tiff => "tif",
        Format::Exr => "exr",
        Format::Png16 => "png",
        _ => "r16",
    };
    let tiles: Vec<_> = t.grid.tiles().collect();
    let files: Vec<String> = tiles.iter().map(|x| t.grid.file_name(x, ext)).collect();
    // Tiles of an earlier run of the same world whose files still verify.
    let mut done: Vec<Option<Record>> = vec![None; tiles.len()];
    if let Some(old) = Manifest::read(dir)? {
        if let Some(field) = differs(&old.identity, &identity) {
            return Err(TilesError::OtherWorld {
                dir: dir.to_path_buf(),
                field,
            });
        }
        for r in old.tiles {
            let k = r.row * t.grid.size().0 + r.col;
            let ok = files.get(k) == Some(&r.file)
                && tile_bytes(&dir.join(&r.file), t.format)
                    .is_some_and(|(b, s)| manifest::crc32(&b, s.as_deref()) == r.crc32);
            if ok {
                done[k] = Some(r);
            }
        }
    }
    let kept = done.iter().flatten().count();
    let (cols, rows) = t.grid.size();
    let manifest = Mutex::new((
        Manifest {
            version: manifest::VERSION,
            identity,
            grid: [cols, rows],
            vrt: None,
            water: None,
            tiles: Vec::new(),
        },
        done,
        Instant::now(),
    ));
    let save = |m: &mut (Manifest, Vec<Option<Record>>, Instant)| {
        m.0.tiles = m.1.iter().flatten().cloned().collect();
        m.2 = Instant::now();
        m.0.write(dir)
    };
    save(&mut manifest.lock().expect("manifest lock"))?;
    progress.start("tiles", tiles.len() as u64);
    progress.advance(kept as u64);
    let opts = io::WriteOptions {
        format: Some(t.format),
        height_range: range,
        // Unity reads a RAW file's first row as its south edge.
        south_up: t.grid.engine == Some(Engine::Unity),
        ..Default::default()
    };
    let clamped = std::sync::atomic::AtomicU64::new(0);
    let todo: Vec<usize> = (0..tiles.len())
        .filter(|&k| manifest.lock().expect("manifest lock").1[k].is_none())
        .collect();
    let result = todo
        .par_iter()
        .try_for_each(|&k| -> Result<(), TilesError> {
            let (tile, file) = (&tiles[k], &files[k]);
            let hf = window(tile.extent).map_err(|source| TilesError::Synth {
                file: file.clone(),
                source,
            })?;
            if let Some((lo, hi)) = range {
                let n = hf
                    .data()
                    .iter()
                    .filter(|&&v| (v as f64) < lo || (v as f64) > hi);
                clamped.fetch_add(n.count() as u64, std::sync::atomic::Ordering::Relaxed);
            }
            let path = dir.join(file);
            io::write(&hf, &path, &opts)?;
            let (bytes, sidecar) = tile_bytes(&path, t.format).ok_or_else(|| {
                IoError::os(
                    &path,
                    std::io::Error::other("the tile vanished after writing"),
                )
            })?;
            let rect = |r: Rect| [r.x0, r.y0, r.width(), r.height()];
            let record = Record {
                col: tile.col,
                row: tile.row,
                file: file.clone(),
                core: rect(tile.core),
                extent: rect(tile.extent),
                crc32: manifest::crc32(&bytes, sidecar.as_deref()),
            };
            let mut m = manifest.lock().expect("manifest lock");
            m.1[k] = Some(record);
            if m.2.elapsed() >= SAVE_EVERY {
                save(&mut m)?;
            }
            drop(m);
            progress.advance(1);
            Ok(())
        });
    progress.finish();
    let mut m = manifest.into_inner().expect("manifest lock");
    // Save what was finished even when a tile failed, then report it.
    save(&mut m)?;
    result?;
    let vrt = vrt::supported(t.format).then(|| {
        let mapping = (t.format == Format::Png16).then(|| {
            let (lo, hi) = range.expect("16-bit tiles have a range");
            HeightMapping::spanning(lo, hi, 65535)
        });
        vrt::vrt(&t.grid, t.cell_size_m, t.format, &files, mapping)
    });
    if let Some(x) = &vrt {
        io::write_atomic(&dir.join(vrt::FILE), x.as_bytes())?;
        m.0.vrt = Some(vrt::FILE.to_string());
        save(&mut m)?;
    }
    let import = t.grid.engine.map(|e| {
        let range = range.expect("engine tiles are 16-bit, with a range");
        engine::settings(e, &t.grid, &files, t.cell_size_m, range)
    });
    if let Some(s) = &import {
        let mut json = serde_json::to_vec_pretty(s).expect("JSON values serialize");
        json.push(b'\n');
        io::write_atomic(&dir.join(IMPORT_FILE), &json)?;
    }
    Ok(Summary {
        written: todo.len(),
        pixels: todo.iter().map(|&k| tiles[k].core.pixels() as u64).sum(),
        kept,
        clamped: clamped.into_inner(),
        manifest: dir.join(manifest::FILE),
        vrt: vrt.map(|_| dir.join(vrt::FILE)),
        import,
    })
}
