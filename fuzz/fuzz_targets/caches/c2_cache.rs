#![no_main]
//! C₂ table files (`database::c2_cache`): any bytes either decode or are
//! refused (the tables are then gathered instead), never a panic; what
//! decodes re-encodes to the same bytes.
use libfuzzer_sys::fuzz_target;
use terrasynth::database::c2::Quad;
use terrasynth::database::c2_cache::{Fingerprint, decode, encode};

fuzz_target!(|data: &[u8]| {
    // The database and level sizes the file claims (bytes 8..20 and the
    // counts from 32), so the fuzzer reaches the entries; counts are
    // capped so that a claim cannot ask for more than the input holds.
    let u32_at = |i: usize| {
        data.get(i..i + 4)
            .map_or(0, |b| u32::from_le_bytes(b.try_into().unwrap()))
    };
    let u64_at = |i: usize| {
        data.get(i..i + 8)
            .map_or(0, |b| u64::from_le_bytes(b.try_into().unwrap()))
    };
    let db = Fingerprint {
        crc: u32_at(8),
        len: u64_at(12),
    };
    let n = (u32_at(20) as usize).min(64);
    let counts: Vec<usize> = (0..n)
        .map(|i| (u64_at(32 + 8 * i) as usize).min(data.len() / 32))
        .collect();
    if let Ok(ranges) = decode(data, db, &counts) {
        let tables: Vec<Vec<Quad>> = ranges
            .iter()
            .map(|r| {
                data[r.clone()]
                    .chunks_exact(32)
                    .map(|q| {
                        Quad(std::array::from_fn(|k| {
                            u64::from_le_bytes(q[8 * k..8 * k + 8].try_into().unwrap())
                        }))
                    })
                    .collect()
            })
            .collect();
        let views: Vec<&[Quad]> = tables.iter().map(|t| t.as_slice()).collect();
        assert_eq!(encode(db, &views), data);
    }
});
