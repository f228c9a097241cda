//! Tile sets for game engines (`tiles --for unreal|unity`, issue 44): the
//! engine's names and sizes, neighbours whose shared edge samples are
//! byte-equal in the files, every tile equal to the world's synthesis at
//! the shared 16-bit mapping (Unity's rows south first), import settings
//! whose scales map a code to its metres, and typed errors for worlds and
//! sizes an engine cannot take.

use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;
use terrasynth::Heightfield;
use terrasynth::database::{Database, default};
use terrasynth::io::engine::Engine;
use terrasynth::progress::Silent;
use terrasynth::synth::cone::Rect;
use terrasynth::synth::{Params, Synthesizer};
use terrasynth::tiles::{self, TilesError, Tiling, engine, grid::Grid};

fn db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

const SEED: u32 = 5;
const CELL_M: f64 = 30.0;

fn tiling(e: Engine, world: (usize, usize), samples: usize) -> Tiling {
    Tiling {
        grid: Grid {
            world,
            tile: samples - 1,
            overlap: 0,
            engine: Some(e),
        },
        format: engine::format(e),
        height_range_m: Some(tiles::default_height_range(db().quantization())),
        cell_size_m: CELL_M,
        source: serde_json::json!({"seed": SEED}),
    }
}

fn write(t: &Tiling, dir: &Path) -> Result<tiles::Summary, TilesError> {
    let synth = Synthesizer::new(db(), Params::default()).unwrap();
    let world = t.grid.world;
    let window = |r: Rect| synth.synthesize_window(world, r, SEED);
    tiles::write(t, dir, &window, &Silent)
}

fn whole(world: (usize, usize)) -> Heightfield {
    let synth = Synthesizer::new(db(), Params::default()).unwrap();
    synth.synthesize(world.0, world.1, SEED).unwrap()
}

/// The 16-bit code of `h` metres in `range` (as the writers round).
fn code(h: f32, (lo, hi): (f64, f64)) -> u16 {
    ((h as f64 - lo) / (hi - lo) * 65535.0).round() as u16
}

/// A tile file's codes, row by row as stored.
fn codes(path: &Path) -> Vec<u16> {
    let bytes = std::fs::read(path).unwrap();
    if path.extension().unwrap() == "raw" {
        bytes
            .chunks_exact(2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
            .collect()
    } else {
        let mut r = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; r.output_buffer_size().unwrap()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!(info.bit_depth, png::BitDepth::Sixteen);
        buf.chunks_exact(2)
            .map(|b| u16::from_be_bytes([b[0], b[1]]))
            .collect()
    }
}

/// Checks every tile of a written engine set against the world: its name,
/// its size, and each stored sample (rows flipped for Unity) equal to the
/// world's sample at the shared mapping — which makes neighbours' shared
/// edges equal too; asserted directly as well.
fn check_tiles(t: &Tiling, dir: &Path, names: &[&str]) {
    let engine = t.grid.engine.unwrap();
    let range = t.height_range_m.unwrap();
    let (w, h) = t.grid.world;
    let world = whole((w, h));
    let n = t.grid.tile + 1;
    let (cols, rows) = t.grid.size();
    let mut files = std::collections::BTreeMap::new();
    for tile in t.grid.tiles() {
        let name = t.grid.file_name(&tile, "");
        let c = codes(&dir.join(&name));
        assert_eq!(c.len(), n * n, "{name}: {n} x {n} samples");
        for y in 0..n {
            // The file's row y is the world's row `wy`.
            let wy = match engine {
                Engine::Unreal => tile.extent.y0 + y,
                Engine::Unity => tile.extent.y0 + n - 1 - y,
            };
            for x in 0..n {
                let want = code(world.get(tile.extent.x0 + x, wy), range);
                assert_eq!(c[y * n + x], want, "{name} ({x}, {y})");
            }
        }
        files.insert((tile.col, tile.row), c);
    }
    let mut got: Vec<String> = t.grid.tiles().map(|x| t.grid.file_name(&x, "")).collect();
    got.sort();
    assert_eq!(got, names);
    // Shared edges, byte for byte: east-west and north-south neighbours.
    for ((col, row), c) in &files {
        if col + 1 < cols {
            let east = &files[&(col + 1, *row)];
            for y in 0..n {
                assert_eq!(c[y * n + n - 1], east[y * n], "({col}, {row}) east edge");
            }
        }
        if row + 1 < rows {
            let south = &files[&(*col, row + 1)];
            // Unreal: my last row is my south neighbour's first; Unity
            // (rows south first): my first row is its last.
            let (mine, theirs) = match engine {
                Engine::Unreal => (&c[(n - 1) * n..], &south[..n]),
                Engine::Unity => (&c[..n], &south[(n - 1) * n..]),
            };
            assert_eq!(mine, theirs, "({col}, {row}) south edge");
        }
    }
}

#[test]
fn unreal_tiles_share_edges_and_import_at_their_metres() {
    let dir = tempfile::tempdir().unwrap();
    let t = tiling(Engine::Unreal, (2 * 126 + 1, 126 + 1), 127);
    let s = write(&t, dir.path()).unwrap();
    assert_eq!(s.written, 2);
    check_tiles(&t, dir.path(), &["tile_x0_y0.png", "tile_x1_y0.png"]);
    // The settings: Unreal's code c stands at LocZ + (c − 32768)·ScaleZ/128
    // cm, which must be our mapping's lo + c·(hi − lo)/65535 m; tiles sit
    // 126 samples of 30 m apart.
    let i: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join(tiles::IMPORT_FILE)).unwrap())
            .unwrap();
    assert_eq!(s.import.as_ref(), Some(&i));
    let (lo, hi) = t.height_range_m.unwrap();
    let (z, loc) = (
        i["scale"][2].as_f64().unwrap(),
        i["location_z_cm"].as_f64().unwrap(),
    );
    for c in [0u32, 1, 32768, 40000, 65535] {
        let unreal = loc + (c as f64 - 32768.0) * z / 128.0;
        let ours = (lo + c as f64 * (hi - lo) / 65535.0) * 100.0;
        assert!(
            (unreal - ours).abs() < 1e-6 * ours.abs().max(1.0),
            "{c}: {unreal} vs {ours}"
        );
    }
    assert_eq!(i["scale"][0], 3000.0);
    assert_eq!(i["tiles"][1]["location_cm"][0], 126.0 * 3000.0);
    assert_eq!(i["tile_samples"], 127);
}

#[test]
fn unity_tiles_run_south_first_and_count_z_northwards() {
    let dir = tempfile::tempdir().unwrap();
    let t = tiling(Engine::Unity, (2 * 32 + 1, 2 * 32 + 1), 33);
    let s = write(&t, dir.path()).unwrap();
    assert_eq!((s.written, s.vrt), (4, None));
    let names = [
        "tile_0_0.raw",
        "tile_0_1.raw",
        "tile_1_0.raw",
        "tile_1_1.raw",
    ];
    check_tiles(&t, dir.path(), &names);
    let i = s.import.unwrap();
    let (lo, hi) = t.height_range_m.unwrap();
    assert_eq!(i["heightmap_resolution"], 33);
    assert_eq!(i["terrain_size_m"][1], hi - lo);
    // The north-west tile (the grid's first) is at x = 0, z = 1 tile north.
    assert_eq!(i["tiles"][0]["file"], "tile_0_1.raw");
    assert_eq!(
        i["tiles"][0]["position_m"],
        serde_json::json!([0.0, lo, 32.0 * CELL_M])
    );
}

#[test]
fn worlds_and_sizes_an_engine_cannot_take_are_typed_errors() {
    let dir = tempfile::tempdir().unwrap();
    let e = write(&tiling(Engine::Unreal, (300, 127), 127), dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::EngineWorld { .. }), "{e}");
    // The nearest whole number of tiles: 2 x 126 + 1.
    assert!(e.to_string().contains("253x127"), "{e}");
    let e = write(&tiling(Engine::Unity, (129, 129), 128), dir.path()).unwrap_err();
    assert!(
        matches!(e, TilesError::EngineSize { samples: 128, .. }),
        "{e}"
    );
    let mut t = tiling(Engine::Unity, (65, 65), 33);
    t.format = terrasynth::io::Format::Png16;
    let e = write(&t, dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::EngineLayout { .. }), "{e}");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing written"
    );
}

#[test]
fn the_cli_prints_the_import_settings() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("unity");
    let o = Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(["tiles", "--for", "unity", "--size", "65x65", "--tile", "33"])
        .args(["--seed", "3", "--out-dir"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(
        err.contains("Flip Vertically off") && err.contains("Heightmap Resolution 33"),
        "{err}"
    );
    assert!(out.join("tile_1_1.raw").exists() && out.join(tiles::IMPORT_FILE).exists());
    let o = Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(["tiles", "--for", "unreal", "--size", "65x65", "--out-dir"])
        .arg(dir.path().join("unreal"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("k x 1008 + 1"), "{err}");
}
