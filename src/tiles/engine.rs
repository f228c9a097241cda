//! Tile sets a game engine imports as one seamless landscape (`tiles --for
//! unreal|unity`, issue 44): the engine's names, sizes and file format, a
//! shared edge between neighbours, and the import settings that put every
//! tile in place at the right scale (`import.json`, [`settings`]).
//!
//! - **Shared edges.** An engine joins two terrain tiles by their border
//!   vertices, so neighbours must hold the *same* border row or column:
//!   a tile of `n` samples covers `n − 1` quads, and tile `i` starts at
//!   sample `i·(n − 1)`. Both hold that column, computed once by the
//!   windowed synthesis, so the edges are byte-equal (Houdini users set
//!   "tile overlap 1" for the same reason). A world of `c` tiles across is
//!   `c·(n − 1) + 1` samples wide.
//! - **Unreal** (World Partition / World Composition tiled import):
//!   16-bit greyscale PNGs named `<name>_x<X>_y<Y>.png`, X east and Y south
//!   as the image's rows run, of a recommended landscape size (127 … 8129
//!   samples). Heights: Unreal puts code 32768 at the landscape's Z and
//!   each code `ScaleZ / 128` cm from it.
//! - **Unity** (Terrain Toolbox, Batch mode): headerless 16-bit little-endian
//!   RAW ("Windows" byte order), 2^k + 1 samples, named `<name>_<X>_<Z>.raw`
//!   with Z counted **north**wards, as Unity's Z axis runs. Unity reads a
//!   RAW file's first row as the terrain's south edge (z = 0), so each file
//!   holds its rows south first — imported with "Flip Vertically" off, the
//!   world is not mirrored. A Unity terrain spans the heights 0 … its size
//!   Y, placed at the world's lowest height.

use super::grid::{Grid, Tile};
use crate::heightfield::Heightfield;
use serde_json::{Value, json};

/// The engines `tiles --for` writes for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    Unreal,
    Unity,
}

/// Unreal's recommended landscape sizes, in samples per side (its
/// Landscape Technical Guide): whole components of 63 or 127 quads.
pub const UNREAL_SIZES: [usize; 7] = [127, 253, 505, 1009, 2017, 4033, 8129];

/// Unity's heightmap resolutions, 2^k + 1 samples per side.
pub const UNITY_SIZES: [usize; 8] = [33, 65, 129, 257, 513, 1025, 2049, 4097];

impl Engine {
    pub fn name(self) -> &'static str {
        match self {
            Engine::Unreal => "unreal",
            Engine::Unity => "unity",
        }
    }

    /// The tile sizes (samples per side) the engine imports.
    pub fn sizes(self) -> &'static [usize] {
        match self {
            Engine::Unreal => &UNREAL_SIZES,
            Engine::Unity => &UNITY_SIZES,
        }
    }

    /// The size a tile set for the engine gets unless one is asked for:
    /// about a thousand samples, like the tiles of other worlds.
    pub fn default_size(self) -> usize {
        match self {
            Engine::Unreal => 1009,
            Engine::Unity => 1025,
        }
    }

    /// The file format: Unreal imports 16-bit PNG, Unity RAW.
    pub fn format(self) -> crate::io::Format {
        match self {
            Engine::Unreal => crate::io::Format::Png16,
            Engine::Unity => crate::io::Format::R16,
        }
    }

    /// The file name of `t` in `g`: `tile_x<X>_y<Y>.png` (Unreal) or
    /// `tile_<X>_<Z>.raw` (Unity, Z northwards); numbers are not padded,
    /// as the engines parse them.
    pub fn file_name(self, g: &Grid, t: &Tile) -> String {
        match self {
            Engine::Unreal => format!("tile_x{}_y{}.png", t.col, t.row),
            Engine::Unity => format!("tile_{}_{}.raw", t.col, g.size().1 - 1 - t.row),
        }
    }

    /// A tile's heights as the engine wants them in its file: Unity's rows
    /// south first, Unreal's as they are. The flipped tile has no map
    /// placement (its rows run north), so its sidecar names none.
    pub fn orient(self, mut hf: Heightfield) -> Heightfield {
        if self == Engine::Unity {
            let w = hf.width();
            let rows: Vec<f32> = hf.data().chunks_exact(w).rev().flatten().copied().collect();
            hf.data_mut().copy_from_slice(&rows);
            hf.set_georef(None);
        }
        hf
    }
}

/// The import settings of an engine tile set (written as `import.json`):
/// per tile its file and where it goes, and the scales that make one
/// 16-bit code, one sample and one metre agree — `range_m` being the
/// metres mapped onto the codes 0 … 65535.
pub fn settings(
    engine: Engine,
    g: &Grid,
    files: &[String],
    cell_size_m: f64,
    (lo, hi): (f64, f64),
) -> Value {
    let q = g.tile;
    let (cols, rows) = g.size();
    let span = hi - lo;
    let tiles: Vec<Value> = g
        .tiles()
        .zip(files)
        .map(|(t, f)| match engine {
            Engine::Unreal => json!({
                "file": f,
                "x": t.col,
                "y": t.row,
                "location_cm": [
                    (t.col * q) as f64 * cell_size_m * 100.0,
                    (t.row * q) as f64 * cell_size_m * 100.0,
                ],
            }),
            Engine::Unity => {
                let z = rows - 1 - t.row;
                json!({
                    "file": f,
                    "x": t.col,
                    "z": z,
                    "position_m": [
                        (t.col * q) as f64 * cell_size_m,
                        lo,
                        (z * q) as f64 * cell_size_m,
                    ],
                })
            }
        })
        .collect();
    let samples = q + 1;
    match engine {
        Engine::Unreal => json!({
            "engine": "unreal",
            "format": "16-bit greyscale PNG",
            "tile_samples": samples,
            "tiles_across": [cols, rows],
            "scale": [cell_size_m * 100.0, cell_size_m * 100.0, span * 12800.0 / 65535.0],
            "location_z_cm": (lo + span * 32768.0 / 65535.0) * 100.0,
            "heights_m": [lo, hi],
            "tiles": tiles,
        }),
        Engine::Unity => json!({
            "engine": "unity",
            "format": "RAW",
            "depth": 16,
            "byte_order": "Windows",
            "flip_vertically": false,
            "heightmap_resolution": samples,
            "tiles_across": [cols, rows],
            "terrain_size_m": [q as f64 * cell_size_m, span, q as f64 * cell_size_m],
            "heights_m": [lo, hi],
            "tiles": tiles,
        }),
    }
}

/// One line per setting a person types into the engine's import dialog.
pub fn summary(s: &Value) -> String {
    match s["engine"].as_str() {
        Some("unreal") => format!(
            "Unreal: import the tiles as a tiled heightmap ({n} x {n} samples each); Scale X, Y, Z = {}, {}, {}; Location Z = {} cm; tile locations in import.json",
            s["scale"][0],
            s["scale"][1],
            s["scale"][2],
            s["location_z_cm"],
            n = s["tile_samples"],
        ),
        _ => format!(
            "Unity: Terrain Toolbox, Import Heightmap, Batch; RAW 16-bit, Byte Order Windows, Flip Vertically off; Heightmap Resolution {}; Terrain Size {} x {} x {} m (width, height, length); tile positions in import.json (y = {} m)",
            s["heightmap_resolution"],
            s["terrain_size_m"][0],
            s["terrain_size_m"][1],
            s["terrain_size_m"][2],
            s["heights_m"][0]
        ),
    }
}
