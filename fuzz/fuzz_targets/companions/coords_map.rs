//! Fuzzes the coordinates-map reader (`synth --coords`, read by `eval
//! --coords`): a 16-bit RGB PNG is decoded or refused, never a panic; what
//! decodes re-encodes to a map that decodes the same.
#![no_main]

use libfuzzer_sys::fuzz_target;
use terrasynth::io::CoordsMap;

fuzz_target!(|data: &[u8]| {
    if let Ok(map) = CoordsMap::decode(data) {
        assert_eq!(CoordsMap::decode(&map.encode_png()).unwrap(), map);
    }
});
