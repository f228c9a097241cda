//! terrasynth against GDAL, the reference every GIS and terrain user trusts
//! (Debian's `gdal-bin` and `python3-gdal`, installed by `.ci/run`).
//!
//! GDAL writes the variants users have (ZSTD, LERC, Float64, Int32,
//! multi-band, scale/offset, ESRI ASCII with `nan` nodata and `dx`/`dy`,
//! geographic GeoTIFF, SRTM `.hgt`, pixel-is-point) and we read them; GDAL
//! reads what we write (`gdalinfo -json`, `gdallocationinfo`), and both must
//! agree on values, cell geometry and CRS — or we refuse with a message that
//! names the feature and what to do. Each case prints one line of the case
//! table.
//!
//! Without GDAL the tests skip with a message; with `TERRASYNTH_REQUIRE_GDAL`
//! set (`.ci/run` sets it) a missing GDAL fails them.

use std::path::{Path, PathBuf};
use std::process::Command;
use terrasynth::georef::{Crs, Georef, PixelIs, Units};
use terrasynth::io::{self, ReadOptions};
use terrasynth::{Heightfield, io::Format};

use crate::common::{gdal_python, have_gdal};

/// Runs a GDAL tool; panics with its stderr on failure.
fn run(tool: &str, args: &[&str]) -> String {
    let out = Command::new(tool).args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{tool} {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// What GDAL sees in a file: size, geotransform, EPSG code (if identified).
struct Seen {
    size: (u64, u64),
    gt: Vec<f64>,
    epsg: Option<u64>,
    wkt: String,
}

fn gdalinfo(p: &Path) -> Seen {
    let v: serde_json::Value = serde_json::from_str(&run("gdalinfo", &["-json", s(p)])).unwrap();
    let size = v["size"].as_array().unwrap();
    Seen {
        size: (size[0].as_u64().unwrap(), size[1].as_u64().unwrap()),
        gt: v["geoTransform"]
            .as_array()
            .map(|a| a.iter().map(|x| x.as_f64().unwrap()).collect())
            .unwrap_or_default(),
        epsg: v["stac"]["proj:epsg"].as_u64(),
        wkt: v["coordinateSystem"]["wkt"]
            .as_str()
            .unwrap_or_default()
            .to_string(),
    }
}

/// Band `band`'s raw values at pixels `(x, y)`, as GDAL reads them.
fn gdal_values(p: &Path, band: usize, pixels: &[(usize, usize)]) -> Vec<f64> {
    let mut cmd = Command::new("gdallocationinfo");
    cmd.args(["-valonly", "-b", &band.to_string(), s(p)]);
    let input: String = pixels.iter().map(|(x, y)| format!("{x} {y}\n")).collect();
    let mut child = cmd
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| l.trim().parse::<f64>().unwrap_or(f64::NAN))
        .collect()
}

/// Pixels to compare: corners, centre and a spread of others.
fn probes(w: usize, h: usize) -> Vec<(usize, usize)> {
    let mut v = vec![
        (0, 0),
        (w - 1, 0),
        (0, h - 1),
        (w - 1, h - 1),
        (w / 2, h / 2),
    ];
    v.extend((0..12).map(|i| ((i * 7 + 3) % w, (i * 5 + 1) % h)));
    v
}

fn case(name: &str, result: &str) {
    println!("| {name} | {result} |");
}

fn utm33() -> Crs {
    let mut c = Crs::epsg(
        32633,
        Units::Linear {
            metres_per_unit: 1.0,
        },
    );
    c.name = Some("WGS 84 / UTM zone 33N".into());
    c
}

/// A 40×30 UTM terrain with integer heights (so every integer type holds
/// it exactly) and a NaN hole, written by us as the variants' source.
fn base(dir: &Path, hole: bool) -> (PathBuf, Heightfield) {
    let mut hf = Heightfield::from_fn(40, 30, 10.0, |x, y| {
        (200 + 7 * x as i32 - 5 * y as i32 + ((x * y) % 13) as i32) as f32
    })
    .unwrap();
    if hole {
        hf.set(17, 9, f32::NAN);
    }
    hf.set_georef(Some(Georef {
        crs: Some(utm33()),
        origin_x: 500_000.0,
        origin_y: 4_650_000.0,
        pixel_x: 10.0,
        pixel_y: 10.0,
        pixel_is: PixelIs::Area,
    }));
    let p = dir.join(if hole { "base_hole.tif" } else { "base.tif" });
    io::write(&hf, &p, &Default::default()).unwrap();
    (p, hf)
}

fn assert_same_values(ours: &Heightfield, gdal_file: &Path, band: usize, map: impl Fn(f64) -> f64) {
    let px = probes(ours.width(), ours.height());
    let theirs = gdal_values(gdal_file, band, &px);
    assert_eq!(theirs.len(), px.len(), "{}", gdal_file.display());
    for (&(x, y), &t) in px.iter().zip(&theirs) {
        let o = ours.get(x, y) as f64;
        let t = map(t);
        assert!(
            (o.is_nan() && t.is_nan()) || (o - t).abs() <= 1e-4 * t.abs().max(1.0),
            "{}: ({x}, {y}): ours {o}, GDAL {t}",
            gdal_file.display()
        );
    }
}

fn assert_geometry(hf: &Heightfield, seen: &Seen, epsg: Option<u64>) {
    let g = hf.georef().expect("georeferenced");
    let want = [g.origin_x, g.pixel_x, 0.0, g.origin_y, 0.0, -g.pixel_y];
    for (a, b) in want.iter().zip(&seen.gt) {
        assert!(
            (a - b).abs() <= 1e-9 * a.abs().max(1.0),
            "{want:?} vs {:?}",
            seen.gt
        );
    }
    assert_eq!((hf.width() as u64, hf.height() as u64), seen.size);
    assert_eq!(seen.epsg, epsg, "{}", seen.wkt);
}

/// GDAL's GeoTIFF variants of one terrain: the same values, geotransform
/// and EPSG code come out of our reader.
#[test]
fn geotiff_variants_written_by_gdal() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (src, hf) = base(d, true);
    let (isrc, ihf) = base(d, false);
    // Our own file, as GDAL reads it.
    let seen = gdalinfo(&src);
    assert_geometry(&hf, &seen, Some(32633));
    assert_same_values(&hf, &src, 1, |v| v);
    case(
        "our GeoTIFF (UTM 33N, float32, NaN) -> gdalinfo/gdallocationinfo",
        "same values, geotransform, EPSG:32633",
    );
    for (name, args, from_int) in [
        (
            "GeoTIFF ZSTD + predictor 3",
            vec!["-co", "COMPRESS=ZSTD", "-co", "PREDICTOR=3"],
            false,
        ),
        (
            "GeoTIFF Deflate tiled",
            vec![
                "-co",
                "COMPRESS=DEFLATE",
                "-co",
                "TILED=YES",
                "-co",
                "BLOCKXSIZE=16",
                "-co",
                "BLOCKYSIZE=16",
            ],
            false,
        ),
        (
            "GeoTIFF LZW + predictor 2, Int16",
            vec!["-ot", "Int16", "-co", "COMPRESS=LZW", "-co", "PREDICTOR=2"],
            true,
        ),
        ("GeoTIFF Float64", vec!["-ot", "Float64"], false),
        ("GeoTIFF Int32", vec!["-ot", "Int32"], true),
        ("GeoTIFF UInt16", vec!["-ot", "UInt16"], true),
        (
            "GeoTIFF big-endian Float32",
            vec!["-co", "ENDIANNESS=BIG"],
            false,
        ),
        (
            "GeoTIFF pixel-is-point",
            vec!["-mo", "AREA_OR_POINT=Point"],
            false,
        ),
    ] {
        let out = d.join(format!("{}.tif", name.replace([' ', ',', '+'], "_")));
        let input = if from_int { &isrc } else { &src };
        let mut a = args.clone();
        a.extend(["-q", s(input), s(&out)]);
        run("gdal_translate", &a);
        let ours =
            io::read(&out, &ReadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let seen = gdalinfo(&out);
        assert_geometry(&ours, &seen, Some(32633));
        assert_same_values(&ours, &out, 1, |v| v);
        assert_eq!(ours.cell_size(), 10.0, "{name}");
        let want = if from_int { &ihf } else { &hf };
        assert_eq!(ours.nodata_count(), want.nodata_count(), "{name}");
        // Through our writer and back into GDAL: same geometry, same CRS.
        let back = d.join(format!("{}_back.tif", name.replace([' ', ',', '+'], "_")));
        io::write(&ours, &back, &Default::default()).unwrap();
        let seen_back = gdalinfo(&back);
        assert_eq!(seen_back.gt, seen.gt, "{name}: geotransform through us");
        assert_eq!(seen_back.epsg, Some(32633));
        assert_same_values(&ours, &back, 1, |v| v);
        case(
            &format!("{name} -> read; -> write -> GDAL"),
            "same values, geotransform, EPSG:32633",
        );
    }
    // LERC: read (tests/gdal/lerc.rs compares every sample with GDAL's).
    let lerc = d.join("lerc.tif");
    run(
        "gdal_translate",
        &["-q", "-co", "COMPRESS=LERC", s(&src), s(&lerc)],
    );
    let ours = io::read(&lerc, &ReadOptions::default()).unwrap();
    assert_geometry(&ours, &gdalinfo(&lerc), Some(32633));
    assert_same_values(&ours, &lerc, 1, |v| v);
    assert_eq!(ours.nodata_count(), hf.nodata_count());
    case("GeoTIFF LERC", "same values, geotransform, EPSG:32633");
}

/// Several bands (`--band`) and GDAL's scale/offset (decimetres in UInt16).
#[test]
fn bands_and_scale_offset() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let multi = d.join("multi.tif");
    let scaled = d.join("scaled.tif");
    gdal_python(&format!(
        r#"
from osgeo import gdal, osr
srs = osr.SpatialReference(); srs.ImportFromEPSG(32633)
ds = gdal.GetDriverByName('GTiff').Create('{m}', 20, 10, 3, gdal.GDT_Float32)
ds.SetGeoTransform([500000, 5, 0, 4650000, 0, -5]); ds.SetProjection(srs.ExportToWkt())
for b in range(3):
    ds.GetRasterBand(b + 1).WriteRaster(0, 0, 20, 10, bytes(__import__('struct').pack('<200f', *[100.0 * (b + 1) + i for i in range(200)])))
ds = None
ds = gdal.GetDriverByName('GTiff').Create('{s}', 20, 10, 1, gdal.GDT_UInt16)
ds.SetGeoTransform([500000, 5, 0, 4650000, 0, -5]); ds.SetProjection(srs.ExportToWkt())
band = ds.GetRasterBand(1); band.SetScale(0.1); band.SetOffset(-100.0)
band.WriteRaster(0, 0, 20, 10, bytes(__import__('struct').pack('<200H', *[12000 + 7 * i for i in range(200)])))
ds = None
"#,
        m = s(&multi),
        s = s(&scaled)
    ));
    let e = io::read(&multi, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("3 bands") && e.contains("--band"), "{e}");
    // Bands 1..3 of a file as GDAL reads them: sample i of band b is
    // 100·b + i (the first and last samples checked exactly as well).
    let bands_read_exactly = |file: &Path| {
        for band in 1..=3 {
            let opts = ReadOptions {
                band: Some(band),
                ..Default::default()
            };
            let hf = io::read(file, &opts).unwrap();
            assert_same_values(&hf, file, band, |v| v);
            let b = 100.0 * band as f32;
            assert_eq!(
                (hf.get(3, 0), hf.get(19, 9)),
                (b + 3.0, b + 199.0),
                "{file:?}"
            );
        }
    };
    bands_read_exactly(&multi);
    let e = io::read(
        &multi,
        &ReadOptions {
            band: Some(4),
            ..Default::default()
        },
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("band 4 does not exist") && e.contains("1..=3"),
        "{e}"
    );
    case(
        "GeoTIFF 3 bands (pixel-interleaved)",
        "refused without --band (names the count); --band 1..3 read exactly; --band 4 refused",
    );
    // The same bands interleaved by plane (how gdal_translate writes
    // multi-band files by default), in strips of 3 rows (the last one
    // short) and in 16² tiles (edge tiles padded).
    for (name, opts) in [
        ("planar.tif", "-co INTERLEAVE=BAND -co BLOCKYSIZE=3"),
        (
            "planar_tiled.tif",
            "-co INTERLEAVE=BAND -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 -co COMPRESS=DEFLATE",
        ),
    ] {
        let planar = d.join(name);
        let o = Command::new("gdal_translate")
            .args(["-q"])
            .args(opts.split(' '))
            .arg(&multi)
            .arg(&planar)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        bands_read_exactly(&planar);
    }
    case(
        "GeoTIFF 3 bands (band-interleaved, 3-row strips and 16² tiles)",
        "--band 1..3 read exactly",
    );
    let hf = io::read(&scaled, &ReadOptions::default()).unwrap();
    assert_same_values(&hf, &scaled, 1, |raw| raw * 0.1 - 100.0);
    assert!((hf.get(0, 0) - 1100.0).abs() < 1e-3, "{}", hf.get(0, 0));
    case(
        "GeoTIFF UInt16 with scale 0.1, offset -100",
        "heights = raw x 0.1 - 100 (as GDAL's unscaled values)",
    );
}

/// Geographic inputs are resampled to square metric cells, keep EPSG:4326
/// and their footprint, and rows (north–south) are untouched.
#[test]
fn geographic_geotiff_and_srtm_tile() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A 3″ grid at 49.5° N, heights by row only (resampling east–west keeps them).
    let geo = d.join("geo.tif");
    gdal_python(&format!(
        r#"
from osgeo import gdal, osr
import struct
srs = osr.SpatialReference(); srs.ImportFromEPSG(4326)
ds = gdal.GetDriverByName('GTiff').Create('{g}', 300, 120, 1, gdal.GDT_Int16)
ds.SetGeoTransform([11.0, 1/1200, 0, 49.55, 0, -1/1200]); ds.SetProjection(srs.ExportToWkt())
ds.GetRasterBand(1).WriteRaster(0, 0, 300, 120, struct.pack('<36000h', *[1000 - 3 * (i // 300) for i in range(36000)]))
ds = None
"#,
        g = s(&geo)
    ));
    let loaded = io::load(&geo, &ReadOptions::default()).unwrap();
    let hf = &loaded.heightfield;
    let (dx, dy) = loaded.grid.native_spacing.unwrap();
    // GDAL/PROJ agree on the ground spacing: 3″ of latitude at 49.5° N.
    assert!(
        (dy - 92.68).abs() < 0.02 && (dx - 60.36).abs() < 0.05,
        "{dx} x {dy}"
    );
    assert_eq!((hf.width(), hf.height()), (195, 120));
    for y in [0, 60, 119] {
        assert_eq!(hf.get(100, y), 1000.0 - 3.0 * y as f32);
    }
    let out = d.join("geo_out.tif");
    io::write(hf, &out, &Default::default()).unwrap();
    let seen = gdalinfo(&out);
    assert_geometry(hf, &seen, Some(4326));
    // Same footprint as the input in degrees.
    assert!((seen.gt[1] * 195.0 - 300.0 / 1200.0).abs() < 1e-12);
    assert_same_values(hf, &out, 1, |v| v);
    case(
        "GeoTIFF EPSG:4326 at 49.5 N, 300x120",
        "resampled E-W to square 92.68 m cells (195x120), EPSG:4326 and footprint kept; GDAL reads it back",
    );
    // ESRI ASCII written by GDAL from our square-metre (so non-square
    // degree) grid: dx/dy in degrees, nan nodata, .prj.
    let nan_src = d.join("geo_f32.tif");
    run(
        "gdal_translate",
        &[
            "-q",
            "-ot",
            "Float32",
            "-a_nodata",
            "nan",
            s(&out),
            s(&nan_src),
        ],
    );
    let asc = d.join("geo.asc");
    run(
        "gdal_translate",
        &[
            "-q",
            "-of",
            "AAIGrid",
            "-co",
            "FORCE_CELLSIZE=NO",
            s(&nan_src),
            s(&asc),
        ],
    );
    let text = std::fs::read_to_string(&asc).unwrap();
    let header: String = text.lines().take(8).collect::<Vec<_>>().join("\n");
    assert!(header.contains("dx") && header.contains("dy"), "{header}");
    assert!(header.to_ascii_lowercase().contains("nan"), "{header}");
    let a = io::load(&asc, &ReadOptions::default()).unwrap();
    assert_eq!((a.heightfield.width(), a.heightfield.height()), (195, 120));
    assert_eq!(
        a.heightfield.georef().unwrap().crs.as_ref().unwrap().epsg,
        Some(4326)
    );
    assert_eq!(a.heightfield.data(), hf.data());
    case(
        "ESRI ASCII from GDAL (dx/dy in degrees, NODATA_value nan, .prj)",
        "CRS from .prj, resampled like the GeoTIFF (same samples)",
    );
    // Our ASC + .prj, read by GDAL.
    let ours_asc = d.join("ours.asc");
    io::write(hf, &ours_asc, &Default::default()).unwrap();
    let seen = gdalinfo(&ours_asc);
    assert_geometry(hf, &seen, Some(4326));
    case(
        "our ESRI ASCII of a geographic grid",
        "GDAL reads dx/dy geometry and EPSG:4326 from our .prj",
    );
    // An SRTM tile written by GDAL: placed by its name, resampled.
    let tile_src = d.join("tile.tif");
    gdal_python(&format!(
        r#"
from osgeo import gdal, osr
import struct
srs = osr.SpatialReference(); srs.ImportFromEPSG(4326)
ds = gdal.GetDriverByName('GTiff').Create('{t}', 1201, 1201, 1, gdal.GDT_Int16)
r = 1/1200
ds.SetGeoTransform([11 - r/2, r, 0, 50 + r/2, 0, -r]); ds.SetProjection(srs.ExportToWkt())
ds.GetRasterBand(1).WriteRaster(0, 0, 1201, 1201, struct.pack('<%dh' % (1201*1201), *[200 + (i // 1201) for i in range(1201*1201)]))
ds = None
"#,
        t = s(&tile_src)
    ));
    let hgt = d.join("N49E011.hgt");
    run(
        "gdal_translate",
        &["-q", "-of", "SRTMHGT", s(&tile_src), s(&hgt)],
    );
    let seen_hgt = gdalinfo(&hgt);
    let loaded = io::load(&hgt, &ReadOptions::default()).unwrap();
    let t = &loaded.heightfield;
    let g = t.georef().unwrap();
    assert!(
        (g.origin_x - seen_hgt.gt[0]).abs() < 1e-12 && (g.origin_y - seen_hgt.gt[3]).abs() < 1e-12
    );
    assert_eq!(g.pixel_is, PixelIs::Point);
    // 1201 columns of 60.4 m (at 49.5° N) -> 782 square 92.7 m cells, as the shared DEM's README did.
    assert!((t.width() as i64 - 782).abs() <= 1, "{}", t.width());
    assert_eq!(t.height(), 1201);
    assert_eq!(t.get(400, 600), 800.0);
    case(
        "SRTM .hgt N49E011 from GDAL",
        "placed by its name like GDAL (pixel-is-point), 1201 -> 782 columns",
    );
}

/// What we write for terrain with no place on Earth, as GDAL sees it; and
/// the Unity / Unreal exports' layouts.
#[test]
fn synthesized_terrain_and_engine_exports() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let hf = Heightfield::from_fn(50, 40, 12.5, |x, y| (x * 3 + y * 11) as f32 * 0.5).unwrap();
    let tif = d.join("synth.tif");
    io::write(&hf, &tif, &Default::default()).unwrap();
    let seen = gdalinfo(&tif);
    assert_eq!(seen.gt, vec![0.0, 12.5, 0.0, 40.0 * 12.5, 0.0, -12.5]);
    assert_eq!(seen.epsg, None, "no invented EPSG code");
    assert!(seen.wkt.contains("terrasynth local grid"), "{}", seen.wkt);
    assert!(
        seen.wkt.starts_with("ENGCRS"),
        "a local engineering CRS: {}",
        seen.wkt
    );
    assert_same_values(&hf.clone(), &tif, 1, |v| v);
    case(
        "synthesized terrain -> GeoTIFF",
        "local CRS named terrasynth local grid, 12.5 m cells, lower-left at (0, 0), no EPSG",
    );
    // ESRI ASCII of it: no .prj (it is nowhere), GDAL reads the cells.
    let asc = d.join("synth.asc");
    io::write(&hf, &asc, &Default::default()).unwrap();
    assert!(!io::prj_path(&asc).exists());
    assert_eq!(gdalinfo(&asc).gt, seen.gt);
    case(
        "synthesized terrain -> ESRI ASCII",
        "no .prj; same geotransform in GDAL",
    );
    // Unity: rows south to north in a 2^n+1 R16; GDAL reads it as ENVI-less raw via a VRT-free check of the bytes.
    use terrasynth::io::engine::{Engine, prepare};
    let p = prepare(&hf, Engine::Unity).unwrap();
    assert_eq!(p.heightfield.width(), 65);
    let raw = d.join("unity.raw");
    let opts = io::WriteOptions {
        south_up: true,
        ..Default::default()
    };
    io::write(&p.heightfield, &raw, &opts).unwrap();
    let bytes = std::fs::read(&raw).unwrap();
    assert_eq!(bytes.len(), 65 * 65 * 2);
    // File row 0 is our southern row: the highest there (heights grow south).
    let first = u16::from_le_bytes([bytes[64 * 2], bytes[64 * 2 + 1]]);
    let last = u16::from_le_bytes([bytes[bytes.len() - 2], bytes[bytes.len() - 1]]);
    assert!(first > last, "{first} vs {last}");
    let back = io::read(&raw, &ReadOptions::default()).unwrap();
    assert!((back.get(64, 64) - p.heightfield.get(64, 64)).abs() < 0.01);
    case(
        "--for unity",
        "65x65 R16 LE, rows south to north (Flip Vertically off), sidecar row_order; reads back north-up",
    );
    let p = prepare(&hf, Engine::Unreal).unwrap();
    assert_eq!(p.heightfield.width(), 127);
    let png = d.join("unreal.png");
    io::write(&p.heightfield, &png, &Default::default()).unwrap();
    let seen = gdalinfo(&png);
    assert_eq!(seen.size, (127, 127));
    let v = gdal_values(&png, 1, &[(0, 0), (126, 126)]);
    assert_eq!(
        (v[0], v[1]),
        (0.0, 65535.0),
        "min at 0, max at 65535, north-west first"
    );
    case(
        "--for unreal",
        "127x127 16-bit PNG (GDAL: 0 at the NW corner, 65535 at SE), Z scale printed",
    );
    let _ = Format::Png16;
}
