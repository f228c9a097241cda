//! `terrasynth water` (issue 41): tests that fail on a wrong fill or a
//! broken network. A pit fills to its exact spill level; every cell of a
//! real DEM and of a coast with a sea drains, along D8 receivers, to the
//! border or the sea; accumulation is one plus the donors' everywhere;
//! every river of a synthesized 1024² terrain reaches a lake, the sea or
//! the border; the CLI writes rasters and GeoJSON that GDAL reads, in the
//! input's georeference, and refuses bad input cleanly. The comparison with
//! pysheds is `tests/python/test_water.py`.

use crate::common;
use std::path::Path;
use std::process::{Command, Output};
use terrasynth::Heightfield;
use terrasynth::water::d8::OUTLET;
use terrasynth::water::lakes::{LAKE, SEA};
use terrasynth::water::rivers::End;
use terrasynth::water::{self, Params, Water};

/// Follows receivers from every cell; each chain must end at an outlet
/// (a border cell, or a sea cell) within `n` steps (no cycle).
fn assert_every_cell_drains(w: &Water) {
    let (width, height) = (w.width, w.height);
    let n = width * height;
    // Memoized: a cell is known to drain once its receiver is.
    let mut drains = vec![false; n];
    let mut path = Vec::new();
    for start in 0..n {
        let mut c = start;
        path.clear();
        loop {
            if drains[c] {
                break;
            }
            path.push(c);
            assert!(path.len() <= n, "a cycle through cell {c}");
            let r = w.receivers[c];
            if r == OUTLET {
                let (x, y) = (c % width, c / width);
                let border = x == 0 || y == 0 || x == width - 1 || y == height - 1;
                assert!(
                    border || w.bodies.class[c] == SEA,
                    "cell ({x}, {y}) is an outlet inside the land"
                );
                break;
            }
            c = r as usize;
        }
        for &p in &path {
            drains[p] = true;
        }
    }
}

/// Every cell's accumulation is itself plus its donors'; outlets sum to n.
fn assert_accumulation_sums(w: &Water) {
    let n = w.receivers.len();
    let mut expected = vec![1u64; n];
    for (c, &r) in w.receivers.iter().enumerate() {
        if r != OUTLET {
            expected[r as usize] += w.accumulation[c] as u64;
        }
    }
    for (c, (&a, &e)) in w.accumulation.iter().zip(&expected).enumerate() {
        assert_eq!(a as u64, e, "cell {c}");
    }
    let outlets: u64 = (0..n)
        .filter(|&c| w.receivers[c] == OUTLET)
        .map(|c| w.accumulation[c] as u64)
        .sum();
    assert_eq!(outlets, n as u64);
}

#[test]
fn a_pit_fills_to_its_exact_spill_level() {
    // A 65² plane falling east with a 20 m deep bowl whose 8 m rim is
    // notched east of the centre: the bowl fills exactly to the height of
    // the notch's first (highest) cell, as one lake, which drains through it.
    let (n, cell) = (65, 50.0);
    let bowl = |x: usize, y: usize| {
        let r = ((x as f64 - 32.0).powi(2) + (y as f64 - 32.0).powi(2)).sqrt();
        let rim = if (10.0..14.0).contains(&r) { 8.0 } else { 0.0 };
        let pit = if r < 10.0 { -20.0 + 2.0 * r } else { 0.0 };
        (100.0 - 0.25 * x as f64 + rim + pit) as f32
    };
    let mut hf = Heightfield::from_fn(n, n, cell, bowl).unwrap();
    // The notch: the rim's cells on row 32 east of the bowl drop to just
    // above the plane.
    for x in 42..=45 {
        hf.set(x, 32, 100.0 - 0.25 * x as f32 + 0.5);
    }
    let spill = hf.get(42, 32);
    let w = water::compute(&hf, &Params::default()).unwrap();
    let lake: Vec<usize> = (0..n * n).filter(|&i| w.bodies.class[i] == LAKE).collect();
    assert!(!lake.is_empty());
    for &i in &lake {
        assert_eq!(w.filled[i], spill, "cell {i} not at the spill level");
        assert!(w.bodies.depth[i] > 0.0);
    }
    assert_eq!(w.bodies.lakes.len(), 1);
    assert_eq!(w.bodies.lakes[0].level_m, spill);
    let centre = 32 * n + 32;
    assert_eq!(w.bodies.depth[centre], spill - hf.get(32, 32));
    // Cells outside the bowl are untouched.
    for i in (0..n * n).filter(|i| !lake.contains(i)) {
        assert_eq!(w.filled[i], hf.data()[i], "cell {i} moved");
    }
    // Everything in the bowl leaves through the notch's first cell.
    assert!(w.accumulation[32 * n + 42] as usize > lake.len());
    assert_every_cell_drains(&w);
    assert_accumulation_sums(&w);
}

#[test]
fn every_cell_of_a_real_dem_drains_and_accumulation_sums() {
    // The North German Plain: the flattest shared DEM, 18 % of it filled.
    let Some(ex) = common::dem::exemplar("north_german_plain", (0, 0, 512, 512), false) else {
        return;
    };
    let w = water::compute(&ex.heights, &Params::default()).unwrap();
    assert!(w.filled_cells > 10_000, "{} cells filled", w.filled_cells);
    assert_every_cell_drains(&w);
    assert_accumulation_sums(&w);
    // The same with a sea level: the sea ends flow, and nothing else does.
    let params = Params {
        sea_level: Some(40.0),
        ..Params::default()
    };
    let w = water::compute(&ex.heights, &params).unwrap();
    let sea = w.bodies.class.iter().filter(|&&c| c == SEA).count();
    assert!(sea > 1000, "{sea} sea cells");
    for (i, &c) in w.bodies.class.iter().enumerate() {
        if c == SEA {
            assert_eq!(w.receivers[i], OUTLET);
            assert_eq!(w.filled[i], 40.0);
        }
    }
    assert_every_cell_drains(&w);
    assert_accumulation_sums(&w);
}

#[test]
fn every_river_of_a_synthesized_terrain_reaches_a_lake_the_sea_or_the_border() {
    let db = common::db::default_db();
    let synth =
        terrasynth::synth::Synthesizer::new(db, terrasynth::synth::Params::default()).unwrap();
    let hf = synth.run(1024, 1024, 7).unwrap().heightfield;
    let params = Params {
        sea_level: Some(0.0),
        ..Params::default()
    };
    let w = water::compute(&hf, &params).unwrap();
    let s = w.summary();
    println!(
        "1024² seed 7: {} lakes, {} segments, orders up to {}, ends {:?}",
        s.lakes.count, s.rivers.segments, s.rivers.max_order, s.rivers.segment_ends
    );
    assert!(s.rivers.segments > 50 && s.rivers.max_order >= 3);
    let (width, height) = (w.width, w.height);
    // Segments by first cell: a confluence end continues there.
    let starts: std::collections::HashMap<u32, usize> = w
        .rivers
        .segments
        .iter()
        .enumerate()
        .map(|(k, s)| (s.cells[0], k))
        .collect();
    for seg in &w.rivers.segments {
        let mut s = seg;
        for _ in 0..w.rivers.segments.len() + 1 {
            let last = *s.cells.last().unwrap() as usize;
            match s.end {
                End::Lake => assert_eq!(w.bodies.class[last], LAKE),
                End::Sea => assert_eq!(w.bodies.class[last], SEA),
                End::Border => {
                    let (x, y) = (last % width, last / width);
                    assert!(x == 0 || y == 0 || x == width - 1 || y == height - 1);
                    assert_eq!(w.receivers[last], OUTLET);
                }
                End::Confluence => {
                    s = &w.rivers.segments[starts[&(last as u32)]];
                    continue;
                }
            }
            break;
        }
        assert!(s.end != End::Confluence, "a river that never ends");
        // Consecutive vertices are D8 steps.
        for p in seg.cells.windows(2) {
            assert_eq!(w.receivers[p[0] as usize], p[1]);
        }
    }
    assert_every_cell_drains(&w);
}

fn terrasynth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(args)
        .output()
        .unwrap()
}

fn run_tool(tool: &str, args: &[&str]) -> String {
    let out = Command::new(tool).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{tool} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn the_cli_writes_what_gdal_reads_in_the_inputs_georeference() {
    let dir = tempfile::tempdir().unwrap();
    // A georeferenced input (UTM 33N) with a bowl, so there is a lake.
    let mut hf = Heightfield::from_fn(200, 150, 30.0, |x, y| {
        let r = ((x as f32 - 100.0).powi(2) + (y as f32 - 75.0).powi(2)).sqrt();
        (300.0 + 0.8 * x as f32 + 25.0 * (y as f32 / 9.0).sin() - 60.0 * (-r * r / 400.0).exp())
            .max(250.0)
    })
    .unwrap();
    hf.set_georef(Some(terrasynth::Georef {
        crs: Some(terrasynth::georef::Crs::epsg(
            32633,
            terrasynth::georef::Units::Linear {
                metres_per_unit: 1.0,
            },
        )),
        origin_x: 500_000.0,
        origin_y: 5_300_000.0,
        pixel_x: 30.0,
        pixel_y: 30.0,
        pixel_is: terrasynth::georef::PixelIs::Area,
    }));
    let input = dir.path().join("in.tif");
    terrasynth::io::write(&hf, &input, &Default::default()).unwrap();
    let out_dir = dir.path().join("water");
    let out = terrasynth(&[
        "water",
        input.to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        "--river-area",
        "0.5",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["lakes"]["count"], 1, "{summary}");
    assert!(summary["rivers"]["segments"].as_u64().unwrap() > 0);
    for f in ["filled", "lakes", "flow", "rivers"] {
        let p = out_dir.join(format!("{f}.tif"));
        let back = terrasynth::io::read(&p, &Default::default()).unwrap();
        assert_eq!((back.width(), back.height()), (200, 150));
        let (g, want) = (back.georef().unwrap(), hf.georef().unwrap());
        assert_eq!(
            (g.origin_x, g.origin_y, g.pixel_x, g.pixel_y),
            (want.origin_x, want.origin_y, want.pixel_x, want.pixel_y),
            "{f}.tif georeference"
        );
        assert_eq!(g.crs.as_ref().and_then(|c| c.epsg), Some(32633));
    }
    let geojson = out_dir.join("rivers.geojson");
    let fc: serde_json::Value = serde_json::from_slice(&std::fs::read(&geojson).unwrap()).unwrap();
    let first = &fc["features"][0];
    let x = first["geometry"]["coordinates"][0][0].as_f64().unwrap();
    assert!((500_000.0..506_000.0).contains(&x), "UTM coordinates: {x}");
    assert!(first["properties"]["strahler"].as_u64().unwrap() >= 1);
    if !common::have_gdal() {
        return;
    }
    for f in ["filled", "lakes", "flow", "rivers"] {
        let info = run_tool(
            "gdalinfo",
            &[out_dir.join(format!("{f}.tif")).to_str().unwrap()],
        );
        assert!(info.contains("Size is 200, 150"), "{f}: {info}");
        assert!(info.contains("32633"), "{f}: {info}");
        assert!(info.contains("Origin = (500000.0"), "{f}: {info}");
        assert!(info.contains(",5300000.0"), "{f}: {info}");
    }
    let info = run_tool("ogrinfo", &["-so", "-al", geojson.to_str().unwrap()]);
    let count = fc["features"].as_array().unwrap().len();
    assert!(info.contains("Geometry: Line String"), "{info}");
    assert!(info.contains(&format!("Feature Count: {count}")), "{info}");
    assert!(info.contains("32633"), "{info}");
    assert!(info.contains("strahler: Integer"), "{info}");
}

#[test]
fn the_cli_refuses_nodata_and_its_own_input_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let mut hf = Heightfield::from_fn(32, 32, 30.0, |x, y| (x + y) as f32).unwrap();
    hf.set(5, 7, f32::NAN);
    let input = dir.path().join("holes.tif");
    terrasynth::io::write(&hf, &input, &Default::default()).unwrap();
    let d = dir.path().to_str().unwrap();
    let out = terrasynth(&["water", input.to_str().unwrap(), "--out-dir", d]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.starts_with("error: ") && err.contains("holes.tif") && err.contains("(5, 7)"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    // An input named like an output, in the output folder.
    let plain = Heightfield::from_fn(32, 32, 30.0, |x, y| (x * y) as f32).unwrap();
    let input = dir.path().join("filled.tif");
    terrasynth::io::write(&plain, &input, &Default::default()).unwrap();
    let before = std::fs::read(&input).unwrap();
    let out = terrasynth(&["water", input.to_str().unwrap(), "--out-dir", d]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("overwrite"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
    // Bad parameters are refused with the allowed range.
    let out = terrasynth(&[
        "water",
        input.to_str().unwrap(),
        "--out-dir",
        d,
        "--river-area",
        "0",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("expected a finite value > 0"),
        "{err}"
    );
    assert!(Path::new(d).join("filled.tif").exists());
}
