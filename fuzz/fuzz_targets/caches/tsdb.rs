//! Fuzzes the `.tsdb` database loader: container, checksums, metadata JSON
//! and the content checks (coordinates in bounds, interior similarity
//! entries, type ids) must refuse anything malformed without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use terrasynth::database::Database;

fuzz_target!(|data: &[u8]| {
    let _ = Database::from_bytes(data, Path::new("fuzz.tsdb"));
});
