//! LERC GeoTIFFs (compression 34887) written by GDAL from a real DEM, read
//! by terrasynth: the heights must equal, bit for bit, GDAL's own decoding
//! of the same file (`gdal_translate -ot Float32` to an uncompressed TIFF,
//! read back by our plain TIFF reader), nodata included, with the same
//! georeference — for LERC (lossless), LERC_DEFLATE and LERC_ZSTD (1 m
//! error, as GLO-30 COG mirrors), tiles and strips with short last ones,
//! Int16 / UInt16 / Float32 / Float64, and bands of multi-band files.
//!
//! Skips with a message without GDAL or the shared DEMs; fails instead
//! under `TERRASYNTH_REQUIRE_GDAL` / `TERRASYNTH_REQUIRE_DEM`.

use std::path::{Path, PathBuf};
use std::process::Command;
use terrasynth::Heightfield;
use terrasynth::georef::{Crs, Georef, PixelIs, Units};
use terrasynth::io::{self, FormatError, ReadOptions};

use crate::common::{dem, have_gdal};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs a GDAL tool or Debian's Python; panics with its stderr on failure.
fn run(tool: &str, args: &[&str]) {
    let out = Command::new(tool).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{tool} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A 500×380 window of the Pyrenees DEM placed in UTM 31N, with a 30×20
/// nodata hole (NaN) touching a tile and a strip boundary, written as an
/// uncompressed Float32 GeoTIFF; plus an Int16 copy (nodata -32768) and a
/// two-band Float32 file whose second band alone has the hole.
fn sources(d: &Path) -> Option<[PathBuf; 3]> {
    let dir = dem::dir("the LERC GeoTIFF tests")?;
    let full = io::read(&dir.join("pyrenees_andorra.png"), &ReadOptions::default()).unwrap();
    let mut hf = full.crop(200, 300, 500, 380).unwrap();
    for y in 40..60 {
        for x in 240..270 {
            hf.set(x, y, f32::NAN);
        }
    }
    let mut crs = Crs::epsg(
        32631,
        Units::Linear {
            metres_per_unit: 1.0,
        },
    );
    crs.name = Some("WGS 84 / UTM zone 31N".into());
    hf.set_georef(Some(Georef {
        crs: Some(crs),
        origin_x: 380_000.0,
        origin_y: 4_740_000.0,
        pixel_x: hf.cell_size(),
        pixel_y: hf.cell_size(),
        pixel_is: PixelIs::Area,
    }));
    let f32_src = d.join("src_f32.tif");
    io::write(&hf, &f32_src, &Default::default()).unwrap();
    let (i16_src, two) = (d.join("src_i16.tif"), d.join("src_two_bands.tif"));
    run(
        "/usr/bin/python3",
        &[
            "-c",
            r#"
import sys
import numpy as np
from osgeo import gdal
src = gdal.Open(sys.argv[1]); h = src.ReadAsArray().astype(np.float64)
def create(path, bands, kind):
    ds = gdal.GetDriverByName('GTiff').Create(path, src.RasterXSize, src.RasterYSize, bands, kind)
    ds.SetGeoTransform(src.GetGeoTransform()); ds.SetProjection(src.GetProjection())
    return ds
ds = create(sys.argv[2], 1, gdal.GDT_Int16)
b = ds.GetRasterBand(1); b.SetNoDataValue(-32768)
b.WriteArray(np.where(np.isnan(h), -32768, np.round(h)).astype(np.int16))
ds = None
ds = create(sys.argv[3], 2, gdal.GDT_Float32)
ds.GetRasterBand(1).WriteArray(np.where(np.isnan(h), 1234.5, h).astype(np.float32))
ds.GetRasterBand(2).WriteArray((h + 1000.25).astype(np.float32))
ds = None
"#,
            s(&f32_src),
            s(&i16_src),
            s(&two),
        ],
    );
    Some([f32_src, i16_src, two])
}

/// GDAL's geotransform of a file.
fn geotransform(p: &Path) -> Vec<f64> {
    let out = Command::new("gdalinfo")
        .args(["-json", s(p)])
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    v["geoTransform"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

/// Reads band `band` of `lerc` with terrasynth and checks it against GDAL's
/// decoding of the same band: the same bits in every sample (NaN for
/// nodata on both sides), the same georeference and cell size. Returns the
/// nodata count.
fn same_as_gdal(lerc: &Path, band: usize) -> usize {
    let opts = ReadOptions {
        band: Some(band),
        ..Default::default()
    };
    let ours = io::read(lerc, &opts).unwrap_or_else(|e| panic!("{}: {e}", lerc.display()));
    let reference = lerc.with_extension(format!("gdal_b{band}.tif"));
    let b = band.to_string();
    run(
        "gdal_translate",
        &[
            "-q",
            "-b",
            &b,
            "-ot",
            "Float32",
            "-co",
            "COMPRESS=NONE",
            s(lerc),
            s(&reference),
        ],
    );
    let theirs = io::read(&reference, &ReadOptions::default()).unwrap();
    assert_eq!(
        (ours.width(), ours.height()),
        (theirs.width(), theirs.height())
    );
    let differ = ours
        .data()
        .iter()
        .zip(theirs.data())
        .position(|(a, b)| a.to_bits() != b.to_bits());
    if let Some(i) = differ {
        let (x, y) = (i % ours.width(), i / ours.width());
        panic!(
            "{} band {band}: ({x}, {y}) is {} here, {} in GDAL",
            lerc.display(),
            ours.data()[i],
            theirs.data()[i]
        );
    }
    assert_eq!(ours.georef(), theirs.georef(), "{}", lerc.display());
    assert_eq!(ours.cell_size(), theirs.cell_size());
    let g = ours.georef().unwrap();
    let want = [g.origin_x, g.pixel_x, 0.0, g.origin_y, 0.0, -g.pixel_y];
    assert_eq!(geotransform(lerc), want, "{}", lerc.display());
    assert_eq!(g.crs.as_ref().and_then(|c| c.epsg), Some(32631));
    ours.nodata_count()
}

fn translate(src: &Path, out: &Path, options: &str) {
    let mut args = vec!["-q"];
    args.extend(options.split_whitespace());
    args.extend([s(src), s(out)]);
    run("gdal_translate", &args);
}

/// The compression 34887 itself: GDAL wrote it and no other codec.
fn assert_lerc(p: &Path, additional: &str) {
    let out = Command::new("gdalinfo").arg(p).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains(&format!("COMPRESSION={additional}")),
        "{}: {text}",
        p.display()
    );
}

const TILES: &str = "-co TILED=YES -co BLOCKXSIZE=256 -co BLOCKYSIZE=256";
/// 48-row strips: the last of 380 rows has 44.
const STRIPS: &str = "-co BLOCKYSIZE=48";

#[test]
fn lerc_geotiffs_read_as_gdal_decodes_them() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let Some([f32_src, i16_src, two]) = sources(d) else {
        return;
    };
    let hole = 30 * 20;
    let cases: [(&str, &Path, &str, &str, usize); 9] = [
        (
            "lerc_f32_strips",
            &f32_src,
            "-co COMPRESS=LERC -co MAX_Z_ERROR=0",
            STRIPS,
            hole,
        ),
        (
            "lerc_f32_tiles",
            &f32_src,
            "-co COMPRESS=LERC -co MAX_Z_ERROR=0",
            TILES,
            hole,
        ),
        (
            "deflate_f32_tiles",
            &f32_src,
            "-co COMPRESS=LERC_DEFLATE -co MAX_Z_ERROR=1",
            TILES,
            hole,
        ),
        (
            "zstd_f32_tiles",
            &f32_src,
            "-co COMPRESS=LERC_ZSTD -co MAX_Z_ERROR=1",
            TILES,
            hole,
        ),
        (
            "zstd_f32_strips",
            &f32_src,
            "-co COMPRESS=LERC_ZSTD -co MAX_Z_ERROR=1",
            STRIPS,
            hole,
        ),
        (
            "zstd_f64_tiles",
            &f32_src,
            "-ot Float64 -co COMPRESS=LERC_ZSTD -co MAX_Z_ERROR=1",
            TILES,
            hole,
        ),
        (
            "zstd_i16_tiles",
            &i16_src,
            "-co COMPRESS=LERC_ZSTD -co MAX_Z_ERROR=1",
            TILES,
            hole,
        ),
        (
            "deflate_i16_strips",
            &i16_src,
            "-co COMPRESS=LERC_DEFLATE -co MAX_Z_ERROR=1",
            STRIPS,
            hole,
        ),
        (
            "zstd_u16_strips",
            &i16_src,
            "-ot UInt16 -a_nodata 0 -co COMPRESS=LERC_ZSTD -co MAX_Z_ERROR=1",
            STRIPS,
            // -32768 clamps to 0, GDAL's UInt16 nodata here.
            hole,
        ),
    ];
    for (name, src, codec, layout, nodata) in cases {
        let out = d.join(format!("{name}.tif"));
        translate(src, &out, &format!("{codec} {layout}"));
        let additional = codec
            .split_whitespace()
            .find_map(|w| w.strip_prefix("COMPRESS="))
            .unwrap();
        assert_lerc(&out, additional);
        assert_eq!(same_as_gdal(&out, 1), nodata, "{name}: nodata samples");
        println!("| {name} | {codec} {layout} | same bits and georeference as GDAL |");
    }
    // Two bands, the hole in band 2 only, band- and pixel-interleaved. In
    // one pixel-interleaved blob of depth 2, GDAL 3.6 stores band 2's NaNs
    // as a Lerc2 no-data value and decodes them to -FLT_MAX, not nodata:
    // the same bits are all that is asked there.
    for (name, layout, hole_2) in [
        ("zstd_two_bands_planar", "-co INTERLEAVE=BAND", Some(hole)),
        ("zstd_two_bands_pixel", "-co INTERLEAVE=PIXEL", None),
    ] {
        let out = d.join(format!("{name}.tif"));
        let options = format!("-co COMPRESS=LERC_ZSTD -co MAX_Z_ERROR=1 {TILES} {layout}");
        translate(&two, &out, &options);
        assert_eq!(same_as_gdal(&out, 1), 0, "{name} band 1");
        let nodata_2 = same_as_gdal(&out, 2);
        if let Some(n) = hole_2 {
            assert_eq!(nodata_2, n, "{name} band 2");
        }
        println!("| {name} | --band 1, --band 2 | same bits and georeference as GDAL |");
    }
}

/// A LERC file whose chunks are damaged fails with an error that names the
/// file and the chunk, never a panic: bytes cut off the end, and a blob
/// whose bytes are flipped.
#[test]
fn damaged_lerc_chunks_fail_cleanly() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let hf = Heightfield::from_fn(64, 40, 10.0, |x, y| (x * 3 + y * 7) as f32).unwrap();
    let src = d.join("src.tif");
    io::write(&hf, &src, &Default::default()).unwrap();
    for (codec, corrupt) in [
        ("LERC", "Lerc2"),
        ("LERC_ZSTD", "zstd layer"),
        ("LERC_DEFLATE", "deflate layer"),
    ] {
        let good = d.join(format!("{codec}.tif"));
        translate(
            &src,
            &good,
            &format!("-co COMPRESS={codec} -co BLOCKYSIZE=16 -co MAX_Z_ERROR=0.5"),
        );
        let bytes = std::fs::read(&good).unwrap();
        // GDAL writes the strips' data after the directory: the last bytes
        // belong to the last strip, so flipping the ones 20 to 30 from the
        // end damages strip 2.
        let mut flipped = bytes.clone();
        let n = flipped.len();
        for b in &mut flipped[n - 30..n - 20] {
            *b ^= 0x5a;
        }
        let bad = d.join(format!("{codec}_flipped.tif"));
        std::fs::write(&bad, &flipped).unwrap();
        let e = io::read(&bad, &ReadOptions::default()).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e.format_error(), Some(FormatError::Corrupt(_)))
                && msg.contains("LERC strip 2")
                && msg.contains(&format!("{codec}_flipped.tif")),
            "{codec}: {msg}"
        );
        assert!(msg.contains(corrupt) || msg.contains("Lerc2"), "{msg}");
        let cut = d.join(format!("{codec}_cut.tif"));
        std::fs::write(&cut, &bytes[..n - 5]).unwrap();
        let msg = io::read(&cut, &ReadOptions::default())
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("LERC strip 2") && msg.contains("past the end"),
            "{codec}: {msg}"
        );
    }
}
