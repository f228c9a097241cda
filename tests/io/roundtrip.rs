//! read(write(x)) == x within each format's precision (see
//! `common::precision`), over random sizes, values, cell sizes, nodata and
//! georeferences; and every real DEM in ../shared/dem through every
//! writable format and back.

use crate::common;
use proptest::prelude::*;
use terrasynth::Heightfield;
use terrasynth::io::{self, Format, ReadOptions, WriteOptions};

/// A random heightfield: 1..=40 per side, heights in a random band of up to
/// 9 km anywhere in -500..9000 m, cell size 0.5..100 m, some NaN holes.
fn heightfield() -> impl Strategy<Value = Heightfield> {
    (
        1usize..=40,
        1usize..=40,
        0.5f64..100.0,
        -500.0f32..4500.0,
        0.0f32..4500.0,
    )
        .prop_flat_map(|(w, h, cell, lo, span)| {
            let value = prop_oneof![
                8 => lo..=lo + span,
                1 => Just(f32::NAN),
            ];
            (Just((w, h, cell)), proptest::collection::vec(value, w * h))
        })
        .prop_map(|((w, h, cell), data)| Heightfield::from_vec(w, h, cell, data).unwrap())
}

fn check_roundtrip(
    mut hf: Heightfield,
    f: Format,
    georef: Option<(f64, f64)>,
) -> Result<(), TestCaseError> {
    let georef = georef.map(|(x, y)| common::placed(x, y, hf.cell_size()));
    if !common::stores_nodata(f) {
        for v in hf.data_mut() {
            if v.is_nan() {
                *v = 0.0;
            }
        }
    }
    hf.set_georef(georef.clone());
    let enc = io::encode(&hf, f, &WriteOptions::default())
        .map_err(|e| TestCaseError::fail(format!("{f}: {e}")))?;
    let back = io::decode(
        &enc.bytes,
        f,
        enc.sidecar.as_deref(),
        &ReadOptions::default(),
    )
    .map_err(|e| TestCaseError::fail(format!("{f}: {e}")))?;
    let Some(s) = hf.stats() else {
        // All nodata: only the mask must survive.
        prop_assert_eq!(back.nodata_count(), hf.len());
        return Ok(());
    };
    common::assert_close(
        &hf,
        &back,
        common::precision(f, s.min, s.max, hf.cell_size()),
        f.name(),
    );
    // Terragen stores the cell size as f32; everything else keeps the f64.
    let cell = if f == Format::Ter {
        hf.cell_size() as f32 as f64
    } else {
        hf.cell_size()
    };
    prop_assert_eq!(back.cell_size(), cell, "{} cell size", f);
    if let (Some(g), true) = (georef, matches!(f, Format::Tiff | Format::Asc)) {
        let b = back.georef().unwrap();
        prop_assert!((b.origin_x - g.origin_x).abs() <= 1e-9 * g.origin_x.abs().max(1.0));
        prop_assert!((b.origin_y - g.origin_y).abs() <= 1e-9 * g.origin_y.abs().max(1.0));
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 64,
        // Failing inputs are printed; no regression file is written.
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn every_writable_format_round_trips(
        hf in heightfield(),
        georef in proptest::option::of((-1e6f64..1e6, -1e7f64..1e7)),
    ) {
        for f in common::writable() {
            check_roundtrip(hf.clone(), f, georef)?;
        }
    }

    /// Exact formats are bit-exact for any finite f32, not just plausible heights.
    #[test]
    fn float_formats_are_bit_exact(bits in proptest::collection::vec(any::<u32>(), 1..64)) {
        let data: Vec<f32> = bits.iter().map(|&b| f32::from_bits(b)).map(|v| if v.is_infinite() { 0.0 } else { v }).collect();
        let hf = Heightfield::from_vec(data.len(), 1, 1.0, data).unwrap();
        for f in [Format::Exr, Format::Tiff, Format::Asc, Format::R32] {
            let enc = io::encode(&hf, f, &WriteOptions::default()).unwrap();
            let back = io::decode(&enc.bytes, f, enc.sidecar.as_deref(), &ReadOptions::default()).unwrap();
            for (a, b) in hf.data().iter().zip(back.data()) {
                prop_assert!(a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()), "{}: {} vs {}", f, a, b);
            }
        }
    }
}

/// Every DEM of ../shared/dem: read it (PNG16 + sidecar), then through every
/// writable format and back within that format's precision.
#[test]
fn shared_dems_convert_through_every_format() {
    let Some(dir) = common::dem::dir("the shared-DEM round trips") else {
        return;
    };
    let entries = std::fs::read_dir(dir).unwrap();
    let mut dems: Vec<_> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            name.ends_with(".png") && !name.ends_with("_types.png")
        })
        .collect();
    dems.sort();
    assert!(!dems.is_empty(), "no DEMs in {}", dir.display());
    for path in dems {
        let hf = io::read(&path, &ReadOptions::default()).unwrap();
        let s = hf.stats().unwrap();
        assert!(
            hf.cell_size() > 20.0 && hf.cell_size() < 100.0,
            "{}: sidecar cell size",
            path.display()
        );
        for f in common::writable() {
            let enc = io::encode(&hf, f, &WriteOptions::default()).unwrap();
            let back = io::decode(
                &enc.bytes,
                f,
                enc.sidecar.as_deref(),
                &ReadOptions::default(),
            )
            .unwrap();
            let what = format!("{} via {f}", path.display());
            common::assert_close(
                &hf,
                &back,
                common::precision(f, s.min, s.max, hf.cell_size()),
                &what,
            );
        }
    }
}
