//! The disk cache of source features: a second preparation reads it and
//! gives the same bytes; a corrupted, truncated or foreign entry is rebuilt
//! (not a crash, not a wrong result); other parameters use another entry.

use crate::common;
use std::path::Path;
use terrasynth::Heightfield;
use terrasynth::patch::input::cache;
use terrasynth::patch::input::sketch::Sketch;
use terrasynth::patch::{self, Library, Params};
use terrasynth::progress::Silent;

/// A 256² crop of one shared DEM, or None (with a message) without it.
fn source() -> Option<Vec<(String, Heightfield)>> {
    let hf = common::dem::heights("thuringia_hills", "the patch cache tests")?;
    Some(vec![(
        "thuringia_hills".to_string(),
        hf.crop(100, 100, 256, 256).unwrap(),
    )])
}

fn params() -> Params {
    Params {
        patch: 32,
        ..Params::default()
    }
}

fn synth(lib: &Library) -> Vec<u32> {
    let json = br#"{"width": 128, "height": 128, "strokes": [
        {"kind": "ridge", "width": 6, "points": [[20, 30], [110, 90]]},
        {"kind": "valley", "width": 6, "points": [[20, 100], [70, 120]]}]}"#;
    let sketch = Sketch::from_json(json, Path::new("c.json")).unwrap();
    let s = patch::synthesize(lib, &sketch, 128, 128, &Silent).unwrap();
    s.heightfield.data().iter().map(|v| v.to_bits()).collect()
}

#[test]
fn the_cache_is_read_back_identically_and_damaged_entries_are_rebuilt() {
    let Some(src) = source() else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fresh = Library::prepare(&src, &params(), &Silent).unwrap();
    let (first, hits) = Library::prepare_cached(&src, &params(), d, &Silent).unwrap();
    assert_eq!(hits, 0, "an empty cache has nothing to read");
    let key = cache::key(&src[0].1, &params(), 1.0);
    let file = cache::path(d, key);
    assert!(file.exists(), "the entry was written");
    let (second, hits) = Library::prepare_cached(&src, &params(), d, &Silent).unwrap();
    assert_eq!(hits, 1, "the second preparation reads the cache");
    assert_eq!(second.sources[0].features(), fresh.sources[0].features());
    assert_eq!(second.sources[0].fill_cells, fresh.sources[0].fill_cells);
    let want = synth(&fresh);
    assert_eq!(synth(&first), want);
    assert_eq!(synth(&second), want, "cached features give the same bytes");

    // Damage the entry three ways: each is rebuilt, gives the same bytes,
    // and leaves a good entry behind.
    let good = std::fs::read(&file).unwrap();
    let mut flipped = good.clone();
    let mid = flipped.len() / 2;
    flipped[mid] ^= 0x40;
    let mut foreign = good.clone();
    foreign[8] ^= 1; // the stored key
    for bad in [
        flipped,
        good[..good.len() / 3].to_vec(),
        foreign,
        Vec::new(),
    ] {
        std::fs::write(&file, &bad).unwrap();
        let (lib, hits) = Library::prepare_cached(&src, &params(), d, &Silent).unwrap();
        assert_eq!(hits, 0, "a damaged entry is not used");
        assert_eq!(synth(&lib), want);
        assert_eq!(std::fs::read(&file).unwrap(), good, "and it is rewritten");
    }

    // Other parameters are another entry, never the old one.
    let other = Params {
        source_dip: 0.03,
        ..params()
    };
    assert_ne!(cache::key(&src[0].1, &other, 1.0), key);
    let (_, hits) = Library::prepare_cached(&src, &other, d, &Silent).unwrap();
    assert_eq!(hits, 0);
    // So is another DEM (one height changed).
    let mut changed = src[0].1.clone();
    changed.data_mut()[0] += 1.0;
    assert_ne!(cache::key(&changed, &params(), 1.0), key);
}

#[test]
fn fuzz_seeds_for_cache_entries_decode_or_are_refused() {
    // As fuzz/fuzz_targets/caches/patch_cache.rs, on every seed and every prefix
    // and single-bit flip of it: no panic, and what decodes re-encodes.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/patch_cache");
    let mut decoded = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let seed = std::fs::read(e.unwrap().path()).unwrap();
        let mut inputs: Vec<Vec<u8>> = (0..seed.len()).map(|k| seed[..k].to_vec()).collect();
        for bit in 0..seed.len() * 8 {
            let mut v = seed.clone();
            v[bit / 8] ^= 1 << (bit % 8);
            inputs.push(v);
        }
        inputs.push(seed);
        for data in &inputs {
            let key = data
                .get(8..16)
                .map_or(0, |b| u64::from_le_bytes(b.try_into().unwrap()));
            if let Some(f) = cache::decode(data, key) {
                assert_eq!(&cache::encode(&f, key), data);
                decoded += 1;
            }
        }
    }
    // The intact seeds decode; prefixes and flips (caught by the CRC or
    // the key) do not, except flips inside the stored key itself, which
    // the fuzz target then also reads as the key.
    assert!(decoded >= 1, "the corpus holds a valid entry");
}
