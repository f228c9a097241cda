//! Fuzzes the georeference parsers: an SRTM tile name (first line) and a
//! `.prj` WKT (the rest), alone and as the companion of a small ESRI grid.
//! Any bytes must give a CRS or a typed error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = terrasynth::io::place::ground::fuzz_georef(data);
});
