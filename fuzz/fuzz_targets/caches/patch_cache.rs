#![no_main]
//! Source-feature cache entries: any bytes either decode or are refused
//! (then rebuilt), never a panic; what decodes re-encodes to the same bytes.
use libfuzzer_sys::fuzz_target;
use terrasynth::patch::input::cache::{decode, encode};

fuzz_target!(|data: &[u8]| {
    // The key the entry claims (bytes 8..16), so the fuzzer reaches the payload.
    let key = data
        .get(8..16)
        .map_or(0, |b| u64::from_le_bytes(b.try_into().unwrap()));
    if let Some(f) = decode(data, key) {
        assert_eq!(encode(&f, key), data);
    }
});
