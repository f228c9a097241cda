//! Tiled worlds (issue 17): the tiles' cores rebuild the whole synthesis
//! byte for byte (with overlap, odd sizes), a run resumes by keeping the
//! tiles whose CRC verifies, a directory of another world is refused,
//! bad tilings are typed errors, and GDAL opens the mosaic (`world.vrt`)
//! as the world — skipped without GDAL unless `TERRASYNTH_REQUIRE_GDAL`.

use std::path::Path;
use std::process::Command;
use std::sync::OnceLock;
use terrasynth::Heightfield;
use terrasynth::database::{Database, default};
use terrasynth::io::{self, Format, ReadOptions};
use terrasynth::progress::Silent;
use terrasynth::synth::cone::Rect;
use terrasynth::synth::{Params, Synthesizer};
use terrasynth::tiles::{self, TilesError, Tiling, grid::Grid, manifest::Manifest};

use crate::common::have_gdal;

fn db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

const WORLD: (usize, usize) = (301, 233);
const SEED: u32 = 12;

fn tiling(format: Format, tile: usize, overlap: usize) -> Tiling {
    let range = matches!(format, Format::Png16 | Format::R16)
        .then(|| tiles::default_height_range(db().quantization()));
    Tiling {
        grid: Grid {
            world: WORLD,
            tile,
            overlap,
            engine: None,
        },
        format,
        height_range_m: range,
        cell_size_m: 30.0,
        source: serde_json::json!({"seed": SEED}),
    }
}

fn write(t: &Tiling, dir: &Path) -> Result<tiles::Summary, TilesError> {
    let synth = Synthesizer::new(db(), Params::default()).unwrap();
    let window = |r: Rect| synth.synthesize_window(WORLD, r, SEED);
    tiles::write(t, dir, &window, &Silent)
}

/// The world rebuilt from the tiles' cores (read back with our readers).
fn mosaic(dir: &Path) -> Vec<f32> {
    let m = Manifest::read(dir).unwrap().unwrap();
    let (w, h) = (m.identity.world[0], m.identity.world[1]);
    let mut out = vec![f32::NAN; w * h];
    for r in &m.tiles {
        let hf = io::read(&dir.join(&r.file), &ReadOptions::default()).unwrap();
        let ([cx, cy, cw, ch], [ex, ey, ..]) = (r.core, r.extent);
        assert_eq!((hf.width(), hf.height()), (r.extent[2], r.extent[3]));
        for y in 0..ch {
            for x in 0..cw {
                out[(cy + y) * w + cx + x] = hf.get(cx - ex + x, cy - ey + y);
            }
        }
    }
    out
}

fn whole() -> Heightfield {
    let synth = Synthesizer::new(db(), Params::default()).unwrap();
    synth.synthesize(WORLD.0, WORLD.1, SEED).unwrap()
}

#[test]
fn tile_cores_rebuild_the_world_byte_for_byte() {
    let want: Vec<u32> = whole().data().iter().map(|v| v.to_bits()).collect();
    for (format, tile, overlap) in [(Format::Tiff, 100, 9), (Format::Exr, 128, 0)] {
        let dir = tempfile::tempdir().unwrap();
        let s = write(&tiling(format, tile, overlap), dir.path()).unwrap();
        assert_eq!(
            (s.written, s.kept),
            (tiling(format, tile, 0).grid.tiles().count(), 0)
        );
        let got: Vec<u32> = mosaic(dir.path()).iter().map(|v| v.to_bits()).collect();
        assert!(
            got == want,
            "{format} tiles of {tile} (+{overlap}) differ from the world"
        );
        assert!(s.vrt.is_some());
    }
}

#[test]
fn sixteen_bit_tiles_share_one_mapping() {
    let want = whole();
    let dir = tempfile::tempdir().unwrap();
    let t = tiling(Format::Png16, 128, 4);
    let s = write(&t, dir.path()).unwrap();
    assert_eq!(s.clamped, 0);
    let (lo, hi) = t.height_range_m.unwrap();
    let step = (hi - lo) / 65535.0;
    let got = mosaic(dir.path());
    for (a, b) in got.iter().zip(want.data()) {
        assert!(((a - b).abs() as f64) <= step / 2.0 + 1e-3, "{a} vs {b}");
    }
    let r16 = tempfile::tempdir().unwrap();
    let s = write(&tiling(Format::R16, 200, 0), r16.path()).unwrap();
    assert_eq!(s.vrt, None, "GDAL cannot open headerless r16");
}

#[test]
fn a_second_run_keeps_verified_tiles_and_remakes_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let t = tiling(Format::Tiff, 128, 2);
    write(&t, dir.path()).unwrap();
    let m = Manifest::read(dir.path()).unwrap().unwrap();
    assert_eq!(m.tiles.len(), 6);
    std::fs::remove_file(dir.path().join(&m.tiles[1].file)).unwrap();
    std::fs::write(dir.path().join(&m.tiles[4].file), b"not a tile").unwrap();
    let s = write(&t, dir.path()).unwrap();
    assert_eq!((s.written, s.kept), (2, 4));
    assert_eq!(Manifest::read(dir.path()).unwrap().unwrap(), m);
    // Another world in the same directory is refused before any work.
    let mut other = tiling(Format::Tiff, 128, 2);
    other.source = serde_json::json!({"seed": SEED + 1});
    let e = write(&other, dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::OtherWorld { .. }), "{e}");
    assert!(e.to_string().contains("source"), "{e}");
}

#[test]
fn bad_tilings_are_typed_errors() {
    let dir = tempfile::tempdir().unwrap();
    let e = write(&tiling(Format::Tiff, 0, 0), dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::TileSize(0)), "{e}");
    let e = write(&tiling(Format::Tiff, 64, 65), dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::Overlap { overlap: 65, .. }), "{e}");
    let e = write(&tiling(Format::Asc, 64, 0), dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::Format(Format::Asc)), "{e}");
    let mut t = tiling(Format::Png16, 64, 0);
    t.height_range_m = None;
    let e = write(&t, dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::NoHeightRange(_)), "{e}");
    t.height_range_m = Some((5.0, 5.0));
    let e = write(&t, dir.path()).unwrap_err();
    assert!(matches!(e, TilesError::HeightRange(..)), "{e}");
}

#[test]
fn the_cli_writes_a_mosaic_gdal_reads_as_the_world() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tiles");
    let run = |extra: &[&str]| {
        let o = Command::new(env!("CARGO_BIN_EXE_terrasynth"))
            .args([
                "tiles", "--size", "301x233", "--seed", "12", "--tile", "100",
            ])
            .args(["--overlap", "5", "--out-dir"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    let (ok, err) = run(&[]);
    assert!(ok, "{err}");
    assert!(err.contains("wrote 12 of 12 tiles"), "{err}");
    let (ok, err) = run(&[]);
    assert!(ok && err.contains("12 kept"), "{err}");
    let (ok, err) = run(&["--jitter", "0.3"]);
    assert!(!ok && err.contains("another world"), "{err}");
    // The manifest names the passes per level the engine ran; a directory
    // written before the start level's passes followed the exemplars (no
    // such entry) is another world.
    let manifest = out.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&manifest).unwrap()).unwrap();
    assert_eq!(m["source"]["level_passes"], serde_json::json!([2, 2, 2]));
    m["source"].as_object_mut().unwrap().remove("level_passes");
    std::fs::write(&manifest, serde_json::to_vec(&m).unwrap()).unwrap();
    let (ok, err) = run(&[]);
    assert!(!ok && err.contains("another world"), "{err}");
    if !have_gdal() {
        return;
    }
    let raw = dir.path().join("mosaic.bin");
    let o = Command::new("gdal_translate")
        .args(["-q", "-of", "ENVI"])
        .arg(out.join("world.vrt"))
        .arg(&raw)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&raw).unwrap();
    let want: Vec<u8> = whole()
        .data()
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    assert!(bytes == want, "GDAL's mosaic differs from the world");
}
