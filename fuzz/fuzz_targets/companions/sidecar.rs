//! Fuzzes the JSON sidecar parser, and the R16 reader that trusts its size
//! and mapping: the first byte splits the input into sidecar and raw data.
#![no_main]

use libfuzzer_sys::fuzz_target;
use terrasynth::io::{Format, ReadOptions, Sidecar, decode};

fuzz_target!(|data: &[u8]| {
    let Some((&split, rest)) = data.split_first() else {
        return;
    };
    let (json, raw) = rest.split_at((split as usize).min(rest.len()));
    if Sidecar::parse(json).is_ok() {
        let _ = decode(raw, Format::R16, Some(json), &ReadOptions::default());
    }
});
