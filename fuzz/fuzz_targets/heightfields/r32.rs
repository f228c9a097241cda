//! Fuzzes the raw R32 (size inferred from the byte count) reader: any bytes must give a heightfield or a typed
//! error, never a panic or an allocation the input cannot justify.
#![no_main]

use libfuzzer_sys::fuzz_target;
use terrasynth::io::{Format, ReadOptions, decode};

fuzz_target!(|data: &[u8]| {
    let _ = decode(data, Format::R32, None, &ReadOptions::default());
});
