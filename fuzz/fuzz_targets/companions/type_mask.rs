//! Fuzzes the type-mask reader (8-bit index PNG + names JSON): the first
//! byte splits the input into names JSON and PNG bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use terrasynth::io::TypeMask;

fuzz_target!(|data: &[u8]| {
    let Some((&split, rest)) = data.split_first() else {
        return;
    };
    let (json, png) = rest.split_at((split as usize).min(rest.len()));
    let names = (!json.is_empty()).then_some(json);
    let _ = TypeMask::decode(png, names);
});
