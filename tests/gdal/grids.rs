//! The GIS corners of issue 44, each against GDAL writing the input and
//! reading our output: a projected grid in US survey feet, a GLO-90-style
//! geographic grid of 4.5″ × 3″ cells, and a compound CRS (horizontal +
//! EGM2008 height).
//!
//! Each test drives Debian's GDAL through its Python bindings (one script
//! that prints JSON) and terrasynth through the library, so what is compared
//! is what a GIS user sees. Without GDAL the tests skip with a message; with
//! `TERRASYNTH_REQUIRE_GDAL` set (`.ci/run` sets it) a missing GDAL fails
//! them.

use serde_json::Value;
use std::path::Path;
use terrasynth::io::{self, ReadOptions};

use crate::common::{gdal_python, have_gdal};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A rough, multi-scale height pattern in Python (ridges at several
/// wavelengths plus a hashed metre-scale texture): any sub-cell slip in a
/// resampling shows as errors of metres.
const HEIGHTS: &str = r#"
import numpy as np
def heights(w, h):
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    z = 300 * np.sin(x / 23.0) * np.cos(y / 17.0) + 80 * np.sin((x + 2 * y) / 5.3)
    z += 25 * np.sin(x * 1.7 + y * 0.9) + ((x * 7919 + y * 104729) % 97) / 9.7
    return (z + 1000).astype(np.float32)
"#;

/// GDAL writes a 64×48 Float32 GeoTIFF of [`HEIGHTS`] in `crs` (any
/// `SetFromUserInput` text), 30-unit cells, top-left corner `origin`.
fn gdal_writes_64x48(path: &Path, crs: &str, origin: [f64; 2]) {
    gdal_python(&format!(
        r#"{HEIGHTS}
from osgeo import gdal, osr
srs = osr.SpatialReference(); srs.SetFromUserInput('{crs}')
ds = gdal.GetDriverByName('GTiff').Create('{f}', 64, 48, 1, gdal.GDT_Float32)
ds.SetGeoTransform([{x}, 30.0, 0, {y}, 0, -30.0]); ds.SetSpatialRef(srs)
ds.GetRasterBand(1).WriteArray(heights(64, 48)); ds = None
"#,
        f = s(path),
        x = origin[0],
        y = origin[1]
    ));
}

/// A GLO-90-style tile (4.5″ east–west × 3″ north–south, pixel-is-point as
/// Copernicus writes it) is resampled to square cells that match GDAL's own
/// bilinear warp of the same file to the same grid within float rounding —
/// reducing columns at 55° N (4.5″ = 80 m < 92.8 m), adding them at 40° N
/// (107 m > 92.5 m).
#[test]
fn glo90_grid_matches_gdal_bilinear_warp() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for (lat, want_width) in [(55.0, 346), (40.0, 462)] {
        let input = dir.path().join(format!("glo90_{lat}.tif"));
        gdal_python(&format!(
            r#"{HEIGHTS}
from osgeo import gdal, osr
srs = osr.SpatialReference(); srs.ImportFromEPSG(4326)
ds = gdal.GetDriverByName('GTiff').Create('{f}', 400, 300, 1, gdal.GDT_Float32)
ds.SetGeoTransform([11.0, 4.5 / 3600, 0, {lat}, 0, -3.0 / 3600]); ds.SetProjection(srs.ExportToWkt())
ds.SetMetadataItem('AREA_OR_POINT', 'Point')
ds.GetRasterBand(1).WriteArray(heights(400, 300)); ds = None
"#,
            f = s(&input)
        ));
        let loaded = io::load(&input, &ReadOptions::default()).unwrap();
        let hf = &loaded.heightfield;
        assert_eq!((hf.width(), hf.height()), (want_width, 300), "at {lat}° N");
        let ours = dir.path().join(format!("ours_{lat}.tif"));
        io::write(hf, &ours, &Default::default()).unwrap();
        // GDAL warps the input onto our output's grid and compares.
        let seen: Value = serde_json::from_str(&gdal_python(&format!(
            r#"
from osgeo import gdal
import numpy as np, json
o = gdal.Open('{o}'); gt = o.GetGeoTransform(); W, H = o.RasterXSize, o.RasterYSize
r = gdal.Warp('', '{i}', format='MEM', width=W, height=H, resampleAlg='bilinear',
              outputBounds=(gt[0], gt[3] + H * gt[5], gt[0] + W * gt[1], gt[3]))
d = np.abs(r.GetRasterBand(1).ReadAsArray().astype(np.float64) - o.GetRasterBand(1).ReadAsArray())
print(json.dumps({{'median': float(np.median(d)), 'p99': float(np.percentile(d, 99)), 'max': float(d.max())}}))
"#,
            o = s(&ours),
            i = s(&input)
        )))
        .unwrap();
        let (median, max) = (
            seen["median"].as_f64().unwrap(),
            seen["max"].as_f64().unwrap(),
        );
        println!(
            "| GLO-90-style 4.5″ x 3″ grid at {lat}° N, 400x300 | resampled to {want_width}x300 square cells: |ours - GDAL bilinear| median {median:.1e} m, p99 {:.1e} m, max {max:.1e} m |",
            seen["p99"].as_f64().unwrap()
        );
        // Heights near 1000 m in f32 are spaced 6e-5 m apart.
        assert!(median <= 1e-4 && max <= 2e-3, "at {lat}° N: {seen}");
    }
}

/// A GeoTIFF in NY State Plane, US survey feet (EPSG:2263) keeps its origin
/// and pixel size in feet when we write it back (GeoTIFF with its CRS; ESRI
/// ASCII without a `.prj`, for which we hold no WKT), and its cells are
/// measured in metres by the survey foot (1200/3937 m).
#[test]
fn us_survey_feet_keep_their_origin() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("ftus.tif");
    gdal_writes_64x48(&input, "EPSG:2263", [1_000_000.0, 250_000.0]);
    let hf = io::load(&input, &ReadOptions::default())
        .unwrap()
        .heightfield;
    assert!(
        (hf.cell_size() - 30.0 * 1200.0 / 3937.0).abs() < 1e-9,
        "{} m",
        hf.cell_size()
    );
    for ext in ["tif", "asc"] {
        let out = dir.path().join(format!("ours.{ext}"));
        io::write(&hf, &out, &Default::default()).unwrap();
        let seen: Value = serde_json::from_str(&gdal_python(&format!(
            r#"
from osgeo import gdal
import json
d = gdal.Open('{o}'); s = d.GetSpatialRef()
print(json.dumps({{'gt': d.GetGeoTransform(), 'epsg': s and s.GetAuthorityCode(None), 'unit': s and s.GetLinearUnits()}}))
"#,
            o = s(&out)
        )))
        .unwrap();
        let gt: Vec<f64> = serde_json::from_value(seen["gt"].clone()).unwrap();
        println!("| GeoTIFF EPSG:2263 (US survey feet) → ours .{ext} | GDAL reads {seen} |");
        for (a, b) in gt
            .iter()
            .zip([1_000_000.0, 30.0, 0.0, 250_000.0, 0.0, -30.0])
        {
            assert!((a - b).abs() < 1e-6, ".{ext}: {seen}");
        }
        if ext == "tif" {
            assert_eq!(seen["epsg"], "2263", "{seen}");
            assert!((seen["unit"].as_f64().unwrap() - 1200.0 / 3937.0).abs() < 1e-12);
        } else {
            // No WKT for EPSG:2263 without a PROJ database: the .asc is
            // written without a .prj (with a notice), never with a wrong one.
            assert!(seen["epsg"].is_null(), "{seen}");
            assert!(!out.with_extension("prj").exists());
        }
    }
}

/// A compound CRS (UTM 33N + EGM2008 height) written back keeps its vertical
/// part exactly as GDAL keeps it in a file GDAL writes itself: both files
/// read as the compound CRS under `GTIFF_REPORT_COMPD_CS=YES` (GDAL's
/// switch for reporting it) and as the horizontal CRS without it.
#[test]
fn compound_crs_is_written_back_as_gdal_writes_it() {
    if !have_gdal() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("compound.tif");
    gdal_writes_64x48(&input, "EPSG:32633+3855", [500_000.0, 5_000_000.0]);
    let hf = io::load(&input, &ReadOptions::default())
        .unwrap()
        .heightfield;
    let crs = hf.georef().unwrap().crs.clone().unwrap();
    assert_eq!((crs.epsg, crs.vertical_epsg), (Some(32633), Some(3855)));
    let ours = dir.path().join("ours.tif");
    io::write(&hf, &ours, &Default::default()).unwrap();
    let seen: Value = serde_json::from_str(&gdal_python(&format!(
        r#"
from osgeo import gdal
import json
out = {{}}
for name, f in [('gdal', '{i}'), ('ours', '{o}')]:
    for rep in ['NO', 'YES']:
        gdal.SetConfigOption('GTIFF_REPORT_COMPD_CS', rep)
        s = gdal.Open(f).GetSpatialRef()
        v = s.GetAuthorityCode('COMPD_CS|VERT_CS') if s.IsCompound() else None
        out[name + '_' + rep] = [bool(s.IsCompound()), s.GetName(), s.GetAuthorityCode('PROJCS'), v]
print(json.dumps(out))
"#,
        i = s(&input),
        o = s(&ours)
    )))
    .unwrap();
    println!("| GeoTIFF EPSG:32633+3855 (compound) → ours | GDAL reads {seen} |");
    assert_eq!(seen["ours_YES"], seen["gdal_YES"], "{seen}");
    assert_eq!(seen["ours_NO"], seen["gdal_NO"], "{seen}");
    assert_eq!(seen["ours_YES"][0], true, "{seen}");
    assert_eq!(seen["ours_YES"][3], "3855", "{seen}");
    assert_eq!(seen["ours_NO"][2], "32633", "{seen}");
}
