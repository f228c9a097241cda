//! Fuzzes the PNG (16- and 8-bit: the decoder takes the file's own depth) reader: any bytes must give a heightfield or a typed
//! error, never a panic or an allocation the input cannot justify.
#![no_main]

use libfuzzer_sys::fuzz_target;
use terrasynth::io::{Format, ReadOptions, decode};

fuzz_target!(|data: &[u8]| {
    let _ = decode(data, Format::Png16, None, &ReadOptions::default());
});
