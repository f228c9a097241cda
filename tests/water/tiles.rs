//! Water on a tiled world (issue 41, `tiles --water`): the tiled
//! computation (`terrasynth::water::tiled`) gives the whole world's filled
//! surface, lake depths, accumulation and river orders bit for bit on a
//! 4 × 4 tiling of a real DEM (with and without a sea), and on worlds whose
//! lakes, flats and spill paths cross many tiles.

use crate::common;
use std::sync::Mutex;
use terrasynth::Heightfield;
use terrasynth::water::tiled::{self, Core, Io, Layout, Report, TileWater};
use terrasynth::water::{self, Params};

/// The tiled water of `hf` mosaicked: (filled, depth, accumulation, rivers).
fn tiled(hf: &Heightfield, tile: usize, params: &Params) -> (Vec<TileWater>, Report) {
    let layout = Layout {
        world: (hf.width(), hf.height()),
        tile,
    };
    let heights = |c: Core| Ok(hf.crop(c.x0, c.y0, c.w, c.h).unwrap().into_vec());
    let out = Mutex::new(Vec::new());
    let sink = |t: TileWater| {
        out.lock().unwrap().push(t);
        Ok(())
    };
    let scratch = tempfile::tempdir().unwrap();
    let io = Io {
        heights: &heights,
        sink: &sink,
        scratch: &scratch.path().join("scratch"),
    };
    let report = tiled::compute(&layout, hf.cell_size(), params, &io).unwrap();
    assert!(
        !scratch.path().join("scratch").exists(),
        "the scratch folder is removed"
    );
    (out.into_inner().unwrap(), report)
}

/// Asserts that the tiles hold the whole world's water, bit for bit.
fn assert_same(hf: &Heightfield, tile: usize, params: &Params) -> Report {
    let whole = water::compute(hf, params).unwrap();
    let (tiles, report) = tiled(hf, tile, params);
    let w = hf.width();
    let layout_count = hf.width().div_ceil(tile) * hf.height().div_ceil(tile);
    assert_eq!(tiles.len(), layout_count);
    let mut seen = vec![false; w * hf.height()];
    for t in &tiles {
        let c = t.core;
        for y in 0..c.h {
            for x in 0..c.w {
                let (i, g) = (y * c.w + x, (c.y0 + y) * w + c.x0 + x);
                let at = format!(
                    "cell ({}, {}) of tile at ({}, {})",
                    c.x0 + x,
                    c.y0 + y,
                    c.x0,
                    c.y0
                );
                assert!(!seen[g], "{at} twice");
                seen[g] = true;
                assert_eq!(
                    t.filled[i].to_bits(),
                    whole.filled[g].to_bits(),
                    "filled, {at}"
                );
                assert_eq!(
                    t.depth[i].to_bits(),
                    whole.bodies.depth[g].to_bits(),
                    "depth, {at}"
                );
                assert_eq!(
                    t.accumulation[i], whole.accumulation[g] as u64,
                    "accumulation, {at}"
                );
                assert_eq!(t.rivers[i], whole.rivers.order[g], "river order, {at}");
            }
        }
    }
    assert!(seen.iter().all(|&s| s));
    assert_eq!(report.lakes, whole.bodies.lakes.len(), "lake count");
    report
}

#[test]
fn a_real_dem_in_4x4_tiles_has_the_whole_worlds_water() {
    // The North German Plain: 18 % of it filled, lakes and flats across
    // every tile border.
    let Some(hf) = common::dem::heights("north_german_plain", "tiled water on a real DEM") else {
        return;
    };
    let tile = hf.width().div_ceil(4);
    let r = assert_same(&hf, tile, &Params::default());
    println!(
        "north_german_plain {}x{} in tiles of {tile}: {r:?}",
        hf.width(),
        hf.height()
    );
    // Distances and flow crossed tile borders more than once.
    assert!(r.flat_rounds > 2 && r.flow_rounds > 2, "{r:?}");
    assert!(r.lakes > 100, "{r:?}");
    let sea = Params {
        sea_level: Some(40.0),
        ..Params::default()
    };
    assert_same(&hf, tile, &sea);
}

#[test]
fn lakes_spills_and_flats_that_cross_many_tiles() {
    // 61 × 47 cells in tiles of 8 (8 × 6, the last row and column short):
    // a wide bowl holding one lake over most tiles, whose spill point is a
    // notch far from the lowest cell, a level plateau (a flat with no
    // lake) and a winding valley.
    let (w, h) = (61, 47);
    let hf = Heightfield::from_fn(w, h, 90.0, |x, y| {
        let (fx, fy) = (x as f32, y as f32);
        let r = ((fx - 28.0).powi(2) + (fy - 22.0).powi(2)).sqrt();
        let mut z = 200.0 - 0.4 * fx + 6.0 * (fy / 5.0).sin() + (x * 7 % 5) as f32 * 0.25;
        if r < 18.0 {
            z = 120.0 + 2.0 * r;
        }
        if (18.0..21.0).contains(&r) {
            z = 190.0 - if y == 22 && x > 40 { 40.0 } else { 0.0 };
        }
        if x > 48 && y < 12 {
            z = 175.0;
        }
        z.floor()
    })
    .unwrap();
    for tile in [8, 13, 61, 1] {
        let r = assert_same(&hf, tile, &Params::default());
        println!("tiles of {tile}: {r:?}");
    }
    let sea = Params {
        sea_level: Some(150.0),
        river_area_km2: 0.05,
        ..Params::default()
    };
    assert_same(&hf, 8, &sea);
}

/// `terrasynth tiles` with `args` into `dir`: (success, stderr).
fn tiles_cli(dir: &std::path::Path, args: &[&str]) -> (bool, String) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(["tiles", "--size", "301x233", "--seed", "12", "--tile", "76"])
        .arg("--out-dir")
        .arg(dir)
        .args(args)
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// A raster of the world from tile files `tile_<c>_<r><suffix>`, each
/// holding `core` (x, y, w, h) at `offset` (x, y) in the file.
fn mosaic(dir: &std::path::Path, suffix: &str, cores: &[([usize; 4], [usize; 2])]) -> Vec<f32> {
    let (w, h) = (301, 233);
    let mut out = vec![f32::NAN; w * h];
    for &([cx, cy, cw, ch], [ox, oy]) in cores {
        let name = format!("tile_{}_{}{suffix}", cx / 76, cy / 76);
        let hf = terrasynth::io::read(&dir.join(name), &Default::default()).unwrap();
        for y in 0..ch {
            for x in 0..cw {
                out[(cy + y) * w + cx + x] = hf.get(ox + x, oy + y);
            }
        }
    }
    out
}

#[test]
fn the_cli_writes_water_tiles_equal_to_the_whole_worlds_water() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("world");
    let (ok, err) = tiles_cli(&out, &["--sea-level", "300"]);
    assert!(!ok && err.contains("need --water"), "{err}");
    let (ok, err) = tiles_cli(&out, &["--water", "--river-area", "0"]);
    assert!(
        !ok && err.contains("river area") && !err.contains("panicked"),
        "{err}"
    );
    assert!(
        !out.join("manifest.json").exists(),
        "refused before any tile"
    );
    let knobs = ["--water", "--overlap", "3", "--river-area", "0.5"];
    let (ok, err) = tiles_cli(&out, &knobs);
    assert!(ok, "{err}");
    assert!(err.contains("water:"), "{err}");
    let m: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("manifest.json")).unwrap()).unwrap();
    let records = m["tiles"].as_array().unwrap();
    assert_eq!(records.len(), 16, "4 x 4 tiles");
    let ints = |v: &serde_json::Value| -> Vec<usize> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_u64().unwrap() as usize)
            .collect()
    };
    let heights: Vec<_> = records
        .iter()
        .map(|r| {
            let (c, e) = (ints(&r["core"]), ints(&r["extent"]));
            ([c[0], c[1], c[2], c[3]], [c[0] - e[0], c[1] - e[1]])
        })
        .collect();
    let cores: Vec<_> = heights.iter().map(|&(c, _)| (c, [0, 0])).collect();
    let z = mosaic(&out, ".tif", &heights);
    let cell = m["cell_size_m"].as_f64().unwrap();
    let hf = Heightfield::from_vec(301, 233, cell, z).unwrap();
    let params = Params {
        river_area_km2: 0.5,
        ..Params::default()
    };
    let whole = water::compute(&hf, &params).unwrap();
    assert!(!whole.bodies.lakes.is_empty() && !whole.rivers.segments.is_empty());
    let acc: Vec<f32> = whole.accumulation.iter().map(|&a| a as f32).collect();
    let order: Vec<f32> = whole.rivers.order.iter().map(|&o| o as f32).collect();
    for (raster, want) in [
        ("filled", &whole.filled),
        ("lakes", &whole.bodies.depth),
        ("flow", &acc),
        ("rivers", &order),
    ] {
        let got = mosaic(&out, &format!(".{raster}.tif"), &cores);
        let same = got
            .iter()
            .zip(want.iter())
            .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{raster} tiles differ from the whole world's water");
        assert!(out.join(format!("{raster}.vrt")).exists());
    }
    assert_eq!(m["water"]["lakes"], whole.bodies.lakes.len());
    assert!(!out.join(".water-scratch").exists());
    if !common::have_gdal() {
        return;
    }
    // GDAL reads the water mosaic as the whole world's flow.
    let raw = dir.path().join("flow.bin");
    let o = std::process::Command::new("gdal_translate")
        .args(["-q", "-of", "ENVI"])
        .arg(out.join("flow.vrt"))
        .arg(&raw)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want: Vec<u8> = acc.iter().flat_map(|v| v.to_le_bytes()).collect();
    assert!(
        std::fs::read(&raw).unwrap() == want,
        "GDAL's flow mosaic differs"
    );
}
