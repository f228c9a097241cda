//! Format features our writers never exercise: tiled, compressed,
//! big-endian and geographic GeoTIFFs, legacy Terragen files, ESRI grids with
//! centre corners, F16 EXR channels, SRTM tiles, raw size resolution, and
//! the refusals (nodata in formats without it, read-only formats).

use crate::common;
use std::path::PathBuf;
use terrasynth::Heightfield;
use terrasynth::io::{self, Format, FormatError, ReadOptions, WriteOptions};

fn fixture(name: &str) -> Heightfield {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures")).join(name);
    io::read(&p, &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn decode(bytes: &[u8], f: Format) -> Result<Heightfield, FormatError> {
    io::decode(bytes, f, None, &ReadOptions::default())
}

#[test]
fn tiff_tiles_int16_with_gdal_nodata() {
    let hf = fixture("tiled_i16.tif");
    assert_eq!((hf.width(), hf.height(), hf.cell_size()), (20, 18, 5.0));
    for y in 0..18 {
        for x in 0..20 {
            let want = if (x, y) == (3, 4) {
                f32::NAN
            } else {
                (x * 100) as f32 - (y * 7) as f32
            };
            let got = hf.get(x, y);
            assert!(
                got == want || (got.is_nan() && want.is_nan()),
                "({x}, {y}): {got} vs {want}"
            );
        }
    }
    let g = hf.georef().unwrap();
    assert_eq!((g.origin_x, g.origin_y), (1000.0, 2000.0));
}

#[test]
fn tiff_deflate_strips_uint16_in_feet_pixel_is_point() {
    let hf = fixture("strips_u16_deflate.tif");
    assert_eq!((hf.width(), hf.height()), (9, 7));
    assert!((hf.cell_size() - 3.048).abs() < 1e-12, "10 ft = 3.048 m");
    assert_eq!(hf.get(8, 6), 1086.0);
    assert_eq!(hf.nodata_count(), 0);
    // The tiepoint names the centre of pixel (0, 0): the corner is half a
    // cell out, in the CRS's own unit (feet).
    let g = hf.georef().unwrap();
    assert_eq!(
        (g.origin_x, g.origin_y, g.pixel_x),
        (95.0, 205.0, 10.0),
        "{g:?}"
    );
    assert_eq!(g.pixel_is, terrasynth::georef::PixelIs::Point);
    assert_eq!(g.metres_per_unit(), Some(0.3048));
}

/// A grid in degrees at 42° N is 1/cos(42°) too wide if its north–south
/// spacing is taken as square: it is resampled east–west instead.
#[test]
fn tiff_big_endian_geographic_float32_is_resampled_not_stretched() {
    let p = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures"))
        .join("geographic_f32_be.tif");
    let loaded = io::load(&p, &ReadOptions::default()).unwrap();
    let hf = &loaded.heightfield;
    // 6 columns of 69.0 m and 4 rows of 92.5 m → 4 columns of 92.5 m.
    let (dx, dy) = loaded.grid.native_spacing.unwrap();
    assert!(
        (dy - 92.56).abs() < 0.01 && (dx - 69.04).abs() < 0.01,
        "{dx} x {dy}"
    );
    assert_eq!((hf.width(), hf.height()), (4, 4));
    assert!((hf.cell_size() - dy).abs() < 1e-9, "{}", hf.cell_size());
    let g = hf.georef().unwrap();
    assert!(g.is_geographic());
    assert!(
        (g.pixel_x * 4.0 - 6.0 / 1200.0).abs() < 1e-15,
        "same extent"
    );
    assert!(
        loaded.grid.notes[0].contains("6x4 -> 4x4"),
        "{:?}",
        loaded.grid.notes
    );
    // Rows are untouched (v = 100.5 + x - 2 y); the void at (5, 0) only
    // drops out of its neighbours' weights.
    for x in 0..4 {
        let d = hf.get(x, 1) - hf.get(x, 2);
        assert!((d - 2.0).abs() < 1e-4, "column {x}: {d}");
    }
    assert_eq!(hf.nodata_count(), 0);
}

#[test]
fn terragen_legacy_layout_is_read_south_to_north() {
    let hf = fixture("legacy.ter");
    assert_eq!((hf.width(), hf.height(), hf.cell_size()), (5, 5, 10.0));
    for y in 0..5 {
        for x in 0..5 {
            let e = ((x as f64) - 2.0 * y as f64) * 1000.0;
            let want = 2.0 * (50.0 + e * 1000.0 / 65536.0);
            assert!((hf.get(x, y) as f64 - want).abs() < 1e-4, "({x}, {y})");
        }
    }
    // Old writers stop without "EOF ".
    let p = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/legacy.ter"
    ));
    let bytes = std::fs::read(p).unwrap();
    let cut = decode(&bytes[..bytes.len() - 6], Format::Ter).unwrap();
    assert_eq!(cut, hf);
}

#[test]
fn esri_centre_corners_crlf_nodata_and_wrapped_rows() {
    let hf = fixture("centre.asc");
    assert_eq!((hf.width(), hf.height(), hf.cell_size()), (4, 3, 10.0));
    let want = [
        1.0,
        2.0,
        3.0,
        4.0,
        5.5,
        f32::NAN,
        7.0,
        8.0,
        f32::NAN,
        10.0,
        11.0,
        12.0,
    ];
    for (i, (&g, &w)) in hf.data().iter().zip(&want).enumerate() {
        assert!(
            g == w || (g.is_nan() && w.is_nan()),
            "sample {i}: {g} vs {w}"
        );
    }
    // Lower-left centre (105, 205) → corner (100, 200) → top-left (100, 230).
    assert_eq!(hf.georef(), Some(&common::placed(100.0, 230.0, 10.0)));
}

#[test]
fn exr_f16_single_channel_and_y_among_many() {
    use exr::prelude::*;
    let (w, h) = (5usize, 3usize);
    let values: Vec<f32> = (0..w * h).map(|i| i as f32 * 0.5 - 2.0).collect();
    let f16s: Vec<f16> = values.iter().map(|&v| f16::from_f32(v)).collect();
    let write = |channels: Vec<AnyChannel<FlatSamples>>| {
        let layer = Layer::new(
            (w, h),
            LayerAttributes::default(),
            Encoding::FAST_LOSSLESS,
            AnyChannels::sort(SmallVec::from_vec(channels)),
        );
        let mut out = std::io::Cursor::new(Vec::new());
        Image::from_layer(layer)
            .write()
            .to_buffered(&mut out)
            .unwrap();
        out.into_inner()
    };
    // One F16 channel with any name: widened exactly; no cell attribute → default.
    let only = write(vec![AnyChannel::new(
        "height",
        FlatSamples::F16(f16s.clone()),
    )]);
    let hf = decode(&only, Format::Exr).unwrap();
    assert_eq!(hf.data(), &values[..]);
    assert_eq!(hf.cell_size(), io::DEFAULT_CELL_SIZE_M);
    // Several channels: Y is chosen.
    let decoy = vec![9.0f32; w * h];
    let many = write(vec![
        AnyChannel::new("A", FlatSamples::F32(decoy.clone())),
        AnyChannel::new("Y", FlatSamples::F32(values.clone())),
        AnyChannel::new("Z", FlatSamples::F32(decoy)),
    ]);
    assert_eq!(decode(&many, Format::Exr).unwrap().data(), &values[..]);
    // A colour image (Houdini's height in R): R is read, with a notice;
    // RGBA too; a colour image with another channel is still refused.
    let load = |bytes: &[u8]| {
        io::load_bytes(
            bytes,
            Format::Exr,
            &Default::default(),
            &ReadOptions::default(),
        )
    };
    let zeros = vec![0.0f32; w * h];
    for alpha in [false, true] {
        let mut ch = vec![
            AnyChannel::new("B", FlatSamples::F32(zeros.clone())),
            AnyChannel::new("G", FlatSamples::F32(zeros.clone())),
            AnyChannel::new("R", FlatSamples::F32(values.clone())),
        ];
        if alpha {
            ch.push(AnyChannel::new("A", FlatSamples::F32(vec![1.0; w * h])));
        }
        let l = load(&write(ch)).unwrap();
        assert_eq!(l.heightfield.data(), &values[..]);
        assert!(
            l.grid.notes.iter().any(|n| n.contains("channel R")),
            "{:?}",
            l.grid.notes
        );
    }
    let odd = write(vec![
        AnyChannel::new("B", FlatSamples::F32(zeros.clone())),
        AnyChannel::new("G", FlatSamples::F32(zeros.clone())),
        AnyChannel::new("R", FlatSamples::F32(values.clone())),
        AnyChannel::new("Z", FlatSamples::F32(zeros.clone())),
    ]);
    let e = load(&odd).unwrap_err().to_string();
    assert!(e.contains("B, G, R, Z") || e.contains("R of an RGB"), "{e}");
    // Heights in 0..1 (Gaea's Raw range) are read as metres, with a notice;
    // a single-channel file in metres gets none.
    let unit: Vec<f32> = (0..w * h).map(|i| i as f32 / (w * h) as f32).collect();
    let l = load(&write(vec![AnyChannel::new(
        "Y",
        FlatSamples::F32(unit.clone()),
    )]))
    .unwrap();
    assert_eq!(l.heightfield.data(), &unit[..]);
    assert!(
        l.grid.notes.iter().any(|n| n.contains("normalised")),
        "{:?}",
        l.grid.notes
    );
    let metres = write(vec![AnyChannel::new("Y", FlatSamples::F32(values.clone()))]);
    assert!(load(&metres).unwrap().grid.notes.is_empty());
}

/// A synthetic SRTM tile: size from the byte count, big-endian, void → NaN.
#[test]
fn srtm_tiles_of_both_resolutions() {
    for (side, cell) in [(1201usize, 92.766), (3601, 30.922)] {
        let mut bytes = Vec::with_capacity(side * side * 2);
        for i in 0..side * side {
            let v: i16 = if i == 7 {
                -32768
            } else {
                (i % 9000) as i16 - 500
            };
            bytes.extend_from_slice(&v.to_be_bytes());
        }
        let hf = decode(&bytes, Format::Hgt).unwrap();
        assert_eq!((hf.width(), hf.height()), (side, side));
        assert!((hf.cell_size() - cell).abs() < 0.001, "{}", hf.cell_size());
        assert!(hf.get(7, 0).is_nan());
        assert_eq!(hf.get(8, 0), -492.0);
        assert_eq!(
            hf.get(side - 1, side - 1),
            ((side * side - 1) % 9000) as f32 - 500.0
        );
        assert_eq!(hf.nodata_count(), 1);
    }
}

#[test]
fn raw_size_from_options_sidecar_or_square() {
    let hf = common::sample(6, 4, 3.0, false);
    let enc = io::encode(&hf, Format::R32, &WriteOptions::default()).unwrap();
    // The sidecar gives size and cell size.
    let back = io::decode(
        &enc.bytes,
        Format::R32,
        enc.sidecar.as_deref(),
        &ReadOptions::default(),
    )
    .unwrap();
    assert_eq!(back, hf);
    // Explicit dimensions, without a sidecar: same samples, default cell size.
    let opts = ReadOptions {
        size: Some((6, 4)),
        ..Default::default()
    };
    let back = io::decode(&enc.bytes, Format::R32, None, &opts).unwrap();
    assert_eq!(back.data(), hf.data());
    assert_eq!(back.cell_size(), io::DEFAULT_CELL_SIZE_M);
    // Transposed dimensions fit the byte count too, and are taken as given.
    let opts = ReadOptions {
        size: Some((4, 6)),
        ..Default::default()
    };
    assert_eq!(
        io::decode(&enc.bytes, Format::R32, None, &opts)
            .unwrap()
            .width(),
        4
    );
    // Wrong explicit dimensions: a mismatch naming both sizes.
    let opts = ReadOptions {
        size: Some((5, 5)),
        ..Default::default()
    };
    let e = io::decode(&enc.bytes, Format::R32, None, &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("5x5 from the given size needs 100 bytes") && e.contains("has 96"),
        "{e}"
    );
    // Explicit dimensions that disagree with the sidecar.
    let e = io::decode(&enc.bytes, Format::R32, enc.sidecar.as_deref(), &opts).unwrap_err();
    assert!(matches!(e, FormatError::InvalidSidecar(_)), "{e}");
    // A square sample count needs nothing else.
    let sq = common::sample(5, 5, 1.0, false);
    let enc = io::encode(&sq, Format::R16, &WriteOptions::default()).unwrap();
    let back = decode(&enc.bytes, Format::R16).unwrap();
    assert_eq!((back.width(), back.height()), (5, 5));
}

/// R16 without a sidecar uses the documented 16-bit default (decimetres).
#[test]
fn r16_default_mapping_is_decimetres() {
    let bytes: Vec<u8> = [0u16, 1, 10, 65535]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let hf = decode(&bytes, Format::R16).unwrap();
    assert_eq!(hf.data(), &[0.0, 0.1, 1.0, 6553.5]);
}

#[test]
fn formats_without_nodata_refuse_it_and_say_how_to_fill() {
    let hf = common::sample(4, 4, 1.0, true);
    for f in [Format::R16, Format::Ter] {
        let e = io::encode(&hf, f, &WriteOptions::default()).unwrap_err();
        assert!(
            matches!(e, FormatError::NodataUnwritable { count: 1, .. }),
            "{f}: {e}"
        );
        assert!(e.to_string().contains("--fill-nodata"), "{e}");
    }
    for f in [
        Format::Png16,
        Format::Exr,
        Format::Tiff,
        Format::Asc,
        Format::R32,
    ] {
        let enc = io::encode(&hf, f, &WriteOptions::default()).unwrap();
        let back = io::decode(
            &enc.bytes,
            f,
            enc.sidecar.as_deref(),
            &ReadOptions::default(),
        )
        .unwrap();
        assert!(
            back.get(2, 2).is_nan() && back.nodata_count() == 1,
            "{f} keeps nodata"
        );
    }
}

#[test]
fn read_only_formats_refuse_to_write() {
    let hf = common::sample(2, 2, 1.0, false);
    for f in [Format::Png8, Format::Hgt] {
        assert!(!f.can_write());
        let e = io::encode(&hf, f, &WriteOptions::default()).unwrap_err();
        assert!(matches!(e, FormatError::Unwritable(_)), "{f}: {e}");
    }
}

#[test]
fn extensions_choose_formats() {
    for (name, f) in [
        ("a.png", Format::Png16),
        ("a.EXR", Format::Exr),
        ("a.tif", Format::Tiff),
        ("a.tiff", Format::Tiff),
        ("N41E001.hgt", Format::Hgt),
        ("a.asc", Format::Asc),
        ("a.r16", Format::R16),
        ("a.raw", Format::R16),
        ("a.r32", Format::R32),
        ("a.ter", Format::Ter),
    ] {
        assert_eq!(
            Format::from_path(std::path::Path::new(name)),
            Some(f),
            "{name}"
        );
        assert_eq!(Format::from_name(f.name()), Some(f));
    }
    assert_eq!(Format::from_path(std::path::Path::new("a.jpg")), None);
}

/// Terragen's HeightScale is the smallest that covers the data, so the
/// samples span nearly the whole i16 range, and a tiny relief gets the
/// finest step the format has (HeightScale 1 = 1/65536 terrain unit).
#[test]
fn terragen_height_scale_uses_the_i16_range() {
    for (relief, min_span) in [(300.0f32, 55_000), (2.55, 5_000)] {
        let hf = Heightfield::from_fn(16, 16, 30.0, |x, y| {
            1200.0 + relief * (x * 16 + y) as f32 / 255.0
        })
        .unwrap();
        let enc = io::encode(&hf, Format::Ter, &WriteOptions::default()).unwrap();
        let back = decode(&enc.bytes, Format::Ter).unwrap();
        let s = hf.stats().unwrap();
        let tol = common::precision(Format::Ter, s.min, s.max, 30.0);
        common::assert_close(&hf, &back, tol, "ter");
        let scale = i16::from_le_bytes([enc.bytes[60], enc.bytes[61]]);
        let samples: Vec<i16> = enc.bytes[64..64 + 512]
            .chunks_exact(2)
            .map(|c| i16::from_le_bytes([c[0], c[1]]))
            .collect();
        let span = *samples.iter().max().unwrap() as i32 - *samples.iter().min().unwrap() as i32;
        assert!(span > min_span, "relief {relief}: span {span}");
        if relief < 30.0 {
            assert_eq!(scale, 1, "a relief under one cell gets the finest scale");
        } else {
            // One less would not cover the data around the base height.
            let base = i16::from_le_bytes([enc.bytes[62], enc.bytes[63]]) as f64;
            let dev = ((s.max as f64 / 30.0) - base).max(base - s.min as f64 / 30.0);
            assert!(
                dev * 65536.0 / (scale as f64 - 1.0) > 32767.0,
                "scale {scale} is not minimal"
            );
        }
    }
}
