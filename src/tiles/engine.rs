//! Tile sets a game engine imports as one seamless landscape (`tiles --for
//! unreal|unity`, issue 44), on top of the single-heightmap presets of
//! [`crate::io::engine`] (sizes, file types, row order, Z scale): the
//! engine's tile names, a shared edge between neighbours, and the import
//! settings that put every tile in place (`import.json`, [`settings`]).
//!
//! - **Shared edges.** An engine joins two terrain tiles by their border
//!   vertices, so neighbours must hold the *same* border row or column:
//!   a tile of `n` samples covers `n − 1` quads, and tile `i` starts at
//!   sample `i·(n − 1)`. Both hold that column, computed once by the
//!   windowed synthesis, so the edges are byte-equal (Houdini users set
//!   "tile overlap 1" for the same reason). A world of `c` tiles across is
//!   `c·(n − 1) + 1` samples wide.
//! - **Unreal** (World Partition / World Composition tiled import): 16-bit
//!   greyscale PNGs named `tile_x<X>_y<Y>.png`, Y southwards as the image's
//!   rows run.
//! - **Unity** (Terrain Toolbox, Import Heightmap, Batch mode, whose names
//!   end in the X and Z indices): RAW files `tile_<X>_<Z>.raw` with Z
//!   counted **north**wards, as Unity's Z axis runs, and rows south first
//!   (`WriteOptions::south_up`, "Flip Vertically" off).

use super::grid::{Grid, Tile};
use crate::io::Format;
use crate::io::engine::{Engine, unreal_z};
use serde_json::{Value, json};

/// The tile size (samples per side) a tile set for `e` gets unless one is
/// asked for: about a thousand samples, like the tiles of other worlds.
pub fn default_samples(e: Engine) -> usize {
    match e {
        Engine::Unreal => 1009,
        Engine::Unity => 1025,
    }
}

/// The tiles' file format: Unreal takes 16-bit PNG, Unity RAW.
pub fn format(e: Engine) -> Format {
    match e {
        Engine::Unreal => Format::Png16,
        Engine::Unity => Format::R16,
    }
}

/// The file name of `t` in `g`: `tile_x<X>_y<Y>.png` (Unreal) or
/// `tile_<X>_<Z>.raw` (Unity, Z northwards); numbers are not padded, as
/// the engines parse them.
pub fn file_name(e: Engine, g: &Grid, t: &Tile) -> String {
    match e {
        Engine::Unreal => format!("tile_x{}_y{}.png", t.col, t.row),
        Engine::Unity => format!("tile_{}_{}.raw", t.col, g.size().1 - 1 - t.row),
    }
}

/// The import settings of an engine tile set (written as `import.json`):
/// per tile its file and where it goes, and the scales that make one
/// 16-bit code, one sample and one metre agree — `lo … hi` being the
/// metres mapped onto the codes 0 … 65535.
pub fn settings(
    e: Engine,
    g: &Grid,
    files: &[String],
    cell_size_m: f64,
    (lo, hi): (f64, f64),
) -> Value {
    let q = g.tile;
    let (cols, rows) = g.size();
    let tile_m = q as f64 * cell_size_m;
    let tiles: Vec<Value> = g
        .tiles()
        .zip(files)
        .map(|(t, f)| match e {
            Engine::Unreal => json!({
                "file": f,
                "x": t.col,
                "y": t.row,
                "location_cm": [t.col as f64 * tile_m * 100.0, t.row as f64 * tile_m * 100.0],
            }),
            Engine::Unity => {
                let z = rows - 1 - t.row;
                json!({
                    "file": f,
                    "x": t.col,
                    "z": z,
                    "position_m": [t.col as f64 * tile_m, lo, z as f64 * tile_m],
                })
            }
        })
        .collect();
    match e {
        Engine::Unreal => {
            let (z_scale, location_z) = unreal_z(lo, hi);
            json!({
                "engine": "unreal",
                "format": "16-bit greyscale PNG",
                "tile_samples": q + 1,
                "tiles_across": [cols, rows],
                "scale": [cell_size_m * 100.0, cell_size_m * 100.0, z_scale],
                "location_z_cm": location_z,
                "heights_m": [lo, hi],
                "tiles": tiles,
            })
        }
        Engine::Unity => json!({
            "engine": "unity",
            "format": "RAW",
            "depth": 16,
            "byte_order": "Windows",
            "flip_vertically": false,
            "heightmap_resolution": q + 1,
            "tiles_across": [cols, rows],
            "terrain_size_m": [tile_m, hi - lo, tile_m],
            "heights_m": [lo, hi],
            "tiles": tiles,
        }),
    }
}

/// The settings a person types into the engine's import dialog, on one line.
pub fn summary(s: &Value) -> String {
    let num = |v: &Value| format!("{:.3}", v.as_f64().unwrap_or(f64::NAN));
    match s["engine"].as_str() {
        Some("unreal") => format!(
            "Unreal: import the tiles as a tiled heightmap ({n} x {n} samples each); Scale X, Y, Z = {}, {}, {}; Location Z = {} cm; tile locations in import.json",
            num(&s["scale"][0]),
            num(&s["scale"][1]),
            num(&s["scale"][2]),
            num(&s["location_z_cm"]),
            n = s["tile_samples"],
        ),
        _ => format!(
            "Unity: Terrain Toolbox, Import Heightmap, Batch; RAW 16-bit, Byte Order Windows, Flip Vertically off; Heightmap Resolution {}; Terrain Size {} x {} x {} m (width, height, length); tile positions in import.json (y = {} m)",
            s["heightmap_resolution"],
            num(&s["terrain_size_m"][0]),
            num(&s["terrain_size_m"][1]),
            num(&s["terrain_size_m"][2]),
            num(&s["heights_m"][0]),
        ),
    }
}
