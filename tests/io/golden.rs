//! Golden files: the exact bytes every writer produces for a fixed 7×5
//! heightfield, and that reading them back gives the heightfield within the
//! format's precision. A change in any writer (or in a codec dependency)
//! shows up here as a byte difference.
//!
//! After an intended change, regenerate with
//! `TERRASYNTH_BLESS=1 cargo test --release --test io golden::` and review the diff.

use crate::common;
use std::path::PathBuf;
use terrasynth::Heightfield;
use terrasynth::georef::{Crs, Units};
use terrasynth::io::{self, Format, ReadOptions, WriteOptions};

fn golden_dir() -> PathBuf {
    PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/golden"))
}

/// The golden input for a format: nodata where the format keeps it, a
/// georeference where it keeps one.
fn input(f: Format) -> Heightfield {
    let mut hf = common::sample(7, 5, 2.5, common::stores_nodata(f));
    if matches!(f, Format::Tiff | Format::Asc) {
        let mut g = common::placed(500_000.0, 4_650_012.5, 2.5);
        let mut crs = Crs::epsg(
            32633,
            Units::Linear {
                metres_per_unit: 1.0,
            },
        );
        crs.name = Some("WGS 84 / UTM zone 33N".into());
        g.crs = Some(crs);
        hf.set_georef(Some(g));
    }
    hf
}

#[test]
fn writers_match_golden_bytes_and_read_back() {
    let bless = std::env::var_os("TERRASYNTH_BLESS").is_some();
    for f in common::writable() {
        let hf = input(f);
        let path = golden_dir().join(format!("{}.{}", f.name(), common::extension(f)));
        let enc = io::encode(&hf, f, &WriteOptions::default()).unwrap();
        let sidecar_path = io::sidecar_path(&path);
        if bless {
            std::fs::write(&path, &enc.bytes).unwrap();
            if let Some(sc) = &enc.sidecar {
                std::fs::write(&sidecar_path, sc).unwrap();
            }
        }
        let golden = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert!(
            golden == enc.bytes,
            "{f}: written bytes differ from {}",
            path.display()
        );
        match &enc.sidecar {
            Some(sc) => assert_eq!(&std::fs::read(&sidecar_path).unwrap(), sc, "{f}: sidecar"),
            None => assert!(
                !sidecar_path.exists(),
                "{f}: unexpected {}",
                sidecar_path.display()
            ),
        }

        let back = io::read(&path, &ReadOptions::default()).unwrap();
        let s = hf.stats().unwrap();
        let tol = common::precision(f, s.min, s.max, hf.cell_size());
        common::assert_close(&hf, &back, tol, f.name());
        assert_eq!(back.cell_size(), hf.cell_size(), "{f}: cell size");
        if let Some(g) = hf.georef() {
            let b = back.georef().expect("georeference kept");
            assert!(
                (b.origin_x - g.origin_x).abs() < 1e-6,
                "{f}: {b:?} vs {g:?}"
            );
            assert!(
                (b.origin_y - g.origin_y).abs() < 1e-6,
                "{f}: {b:?} vs {g:?}"
            );
        }
    }
}

/// The pinned bytes are not just stable but right: spot-check a few fields
/// against the format specifications by hand.
#[test]
fn golden_headers_follow_the_specs() {
    let read = |name: &str| std::fs::read(golden_dir().join(name)).unwrap();
    // Terragen: magic, SIZE = min(7, 5) - 1, XPTS 7, YPTS 5, SCAL 2.5 ×3, ALTW, EOF.
    let ter = read("ter.ter");
    assert_eq!(&ter[..16], b"TERRAGENTERRAIN ");
    assert_eq!(&ter[16..24], b"SIZE\x04\x00\x00\x00");
    assert_eq!(&ter[24..40], b"XPTS\x07\x00\x00\x00YPTS\x05\x00\x00\x00");
    assert_eq!(&ter[40..44], b"SCAL");
    assert_eq!(f32::from_le_bytes(ter[44..48].try_into().unwrap()), 2.5);
    assert_eq!(&ter[56..60], b"ALTW");
    assert_eq!(
        ter.len(),
        60 + 4 + 35 * 2 + 2 + 4,
        "odd sample count gets 2 pad bytes"
    );
    assert_eq!(&ter[ter.len() - 4..], b"EOF ");
    // The first stored row is the southern one: our row 4, column 0.
    let hf = input(Format::Ter);
    let (scale, base) = (
        i16::from_le_bytes([ter[60], ter[61]]) as f64,
        i16::from_le_bytes([ter[62], ter[63]]) as f64,
    );
    let e = i16::from_le_bytes([ter[64], ter[65]]) as f64;
    let h = 2.5 * (base + e * scale / 65536.0);
    assert!(
        (h - hf.get(0, 4) as f64).abs() < 1e-3,
        "{h} vs {}",
        hf.get(0, 4)
    );
    // R32: row-major little-endian f32, NaN kept.
    let r32 = read("r32.r32");
    assert_eq!(r32.len(), 35 * 4);
    assert_eq!(
        f32::from_le_bytes(r32[..4].try_into().unwrap()),
        input(Format::R32).get(0, 0)
    );
    assert!(f32::from_le_bytes(r32[17 * 4..18 * 4].try_into().unwrap()).is_nan());
    // ESRI ASCII: the lower-left corner is the top-left one minus 5 rows of 2.5 m.
    let asc = String::from_utf8(read("asc.asc")).unwrap();
    assert!(asc.starts_with("ncols 7\nnrows 5\nxllcorner 500000\nyllcorner 4650000\ncellsize 2.5\nNODATA_value -9999\n"), "{asc}");
    // TIFF: little-endian classic header.
    assert_eq!(&read("tiff.tif")[..4], b"II*\x00");
    // EXR: magic number.
    assert_eq!(&read("exr.exr")[..4], &[0x76, 0x2f, 0x31, 0x01]);
}
