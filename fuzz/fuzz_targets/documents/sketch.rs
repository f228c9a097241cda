#![no_main]
//! Sketch reader: JSON polylines and images must never panic; a JSON sketch
//! that parses must rasterise.
use libfuzzer_sys::fuzz_target;
use std::path::Path;
use terrasynth::patch::input::sketch::Sketch;

fuzz_target!(|data: &[u8]| {
    if let Ok(s) = Sketch::from_json(data, Path::new("fuzz")) {
        let _ = s.raster(32, 32);
    }
    let _ = Sketch::from_image(data, Path::new("fuzz"));
});
