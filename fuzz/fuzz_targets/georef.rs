//! Fuzzes the georeference parsers: an SRTM tile name (first line) and a
//! `.prj` WKT (the rest), alone and as the companion of a small ESRI grid.
//! Any bytes must give a CRS or a typed error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use terrasynth::io::{Companions, Format, ReadOptions, ground, load_bytes, wkt};

const GRID: &[u8] = b"ncols 3\nnrows 2\nxllcorner 1\nyllcorner 41\ndx 0.001\ndy 0.0008\n1 2 3\n4 5 6\n";

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == b'\n').unwrap_or(data.len());
    let name = String::from_utf8_lossy(&data[..split]);
    let _ = ground::hgt_georef(&name, 1201);
    let prj = data.get(split + 1..).unwrap_or_default();
    let _ = wkt::parse(prj);
    let companions = Companions {
        prj: Some(prj),
        ..Default::default()
    };
    let _ = load_bytes(GRID, Format::Asc, &companions, &ReadOptions::default());
});
