//! Helpers shared by the integration tests.
#![allow(dead_code)]

#[cfg(feature = "serve")]
pub mod browser;
pub mod crop;
pub mod db;
pub mod dem;
#[cfg(feature = "serve")]
pub mod editor;
#[cfg(feature = "gpu")]
pub mod gpu;
#[cfg(feature = "serve")]
pub mod http;
pub mod render;
pub mod states;
pub mod variants;

use std::process::{Command, Output};
use terrasynth::io::Format;
use terrasynth::{Georef, Heightfield};

/// A placement without CRS (as an ESRI grid without `.prj` has): top-left
/// corner (x, y), square cells of `cell` metres.
pub fn placed(x: f64, y: f64, cell: f64) -> Georef {
    Georef {
        crs: None,
        origin_x: x,
        origin_y: y,
        pixel_x: cell,
        pixel_y: cell,
        pixel_is: terrasynth::georef::PixelIs::Area,
    }
}

/// Every format that can be written.
pub fn writable() -> Vec<Format> {
    Format::ALL
        .iter()
        .copied()
        .filter(|f| f.can_write())
        .collect()
}

/// The file extension we use for a format.
pub fn extension(f: Format) -> &'static str {
    match f {
        Format::Png16 | Format::Png8 => "png",
        Format::Exr => "exr",
        Format::Tiff => "tif",
        Format::Hgt => "hgt",
        Format::Asc => "asc",
        Format::R16 => "r16",
        Format::R32 => "r32",
        Format::Ter => "ter",
    }
}

/// Whether a format keeps nodata through a round trip.
pub fn stores_nodata(f: Format) -> bool {
    !matches!(f, Format::R16 | Format::Ter)
}

/// The largest error a round trip through `f` may introduce, in metres, for
/// valid heights in `[min, max]` with cell size `cell`:
/// - exr, tiff, asc, r32: exact (0);
/// - png16, r16: half a quantization step, (max − min) / 65535 / 2 (65534
///   with nodata), plus f32 rounding of the result;
/// - ter: half a step of HeightScale / 65536 terrain units, where the
///   writer's HeightScale covers (max − min + cell) / 2 on each side of the
///   base height, plus f32 rounding.
pub fn precision(f: Format, min: f32, max: f32, cell: f64) -> f64 {
    let range = (max - min) as f64;
    let f32_eps = (min.abs().max(max.abs()) as f64) * f32::EPSILON as f64;
    match f {
        Format::Exr | Format::Tiff | Format::Asc | Format::R32 => 0.0,
        Format::Png16 | Format::R16 => range / 65534.0 / 2.0 + 2.0 * f32_eps,
        Format::Ter => {
            let unit = cell as f32 as f64;
            let scale = ((range / unit / 2.0 + 1.0) * 65536.0 / 32767.0)
                .ceil()
                .max(1.0);
            scale / 65536.0 * unit / 2.0 + 4.0 * f32_eps
        }
        other => panic!("{other} is not writable"),
    }
}

/// Asserts that `b` equals `a` within `tol` (NaN must match NaN).
pub fn assert_close(a: &Heightfield, b: &Heightfield, tol: f64, what: &str) {
    assert_eq!(
        (a.width(), a.height()),
        (b.width(), b.height()),
        "{what}: size"
    );
    for (i, (&x, &y)) in a.data().iter().zip(b.data()).enumerate() {
        if x.is_nan() || y.is_nan() {
            assert!(x.is_nan() && y.is_nan(), "{what}: sample {i}: {x} vs {y}");
        } else {
            let d = (x as f64 - y as f64).abs();
            assert!(
                d <= tol,
                "{what}: sample {i}: {x} vs {y} (|d| = {d} > {tol})"
            );
        }
    }
}

/// A small heightfield with structure: negative and positive heights, a
/// fractional part, and an optional nodata hole.
pub fn sample(width: usize, height: usize, cell: f64, nodata: bool) -> Heightfield {
    let mut hf = Heightfield::from_fn(width, height, cell, |x, y| {
        let (x, y) = (x as f32, y as f32);
        -12.5 + 3.25 * x - 1.75 * y
            + 0.125 * (x * y)
            + if (x + y) as usize % 3 == 0 { 0.3 } else { 0.0 }
    })
    .unwrap();
    if nodata {
        hf.set(width / 2, height / 2, f32::NAN);
    }
    hf
}

/// Whether GDAL's tools are here; panics when `TERRASYNTH_REQUIRE_GDAL` is
/// set and they are absent (CI installs them, so a skip there is a failure).
pub fn have_gdal() -> bool {
    const REQUIRE: &str = "TERRASYNTH_REQUIRE_GDAL";
    let ok = std::process::Command::new("gdalinfo")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        assert!(
            std::env::var_os(REQUIRE).is_none(),
            "{REQUIRE} is set but gdalinfo is missing (apt-get install gdal-bin python3-gdal)"
        );
        println!("SKIP: GDAL is absent (apt-get install gdal-bin python3-gdal)");
    }
    ok
}

/// Runs a script with Debian's Python (the one `python3-gdal` installs
/// into); panics with its stderr on failure; its stdout.
pub fn gdal_python(script: &str) -> String {
    let out = Command::new("/usr/bin/python3")
        .args(["-c", script])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "python: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Every `.rs` file under `dir`.
pub fn rust_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// Pearson's correlation of pairs.
pub fn correlation(p: &[(f64, f64)]) -> f64 {
    let n = p.len() as f64;
    let (ma, mb) = (
        p.iter().map(|q| q.0).sum::<f64>() / n,
        p.iter().map(|q| q.1).sum::<f64>() / n,
    );
    let cov: f64 = p.iter().map(|q| (q.0 - ma) * (q.1 - mb)).sum();
    let va: f64 = p.iter().map(|q| (q.0 - ma).powi(2)).sum();
    let vb: f64 = p.iter().map(|q| (q.1 - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// Distance from (x, y) to the nearest edge of a closed polygon.
pub fn distance_to(poly: &[(f64, f64)], x: f64, y: f64) -> f64 {
    let mut best = f64::INFINITY;
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        let (ex, ey) = (b.0 - a.0, b.1 - a.1);
        let t = (((x - a.0) * ex + (y - a.1) * ey) / (ex * ex + ey * ey)).clamp(0.0, 1.0);
        best = best.min((x - a.0 - t * ex).hypot(y - a.1 - t * ey));
    }
    best
}

/// Fraction of pixels farther than `reach` from (x, y) whose height moved
/// by more than 1% of relief.
pub fn moved_outside(
    a: &Heightfield,
    b: &Heightfield,
    (x, y): (f64, f64),
    reach: f64,
    rel: f64,
) -> f64 {
    let (mut n, mut moved) = (0, 0);
    for v in 0..a.height() {
        for u in 0..a.width() {
            if (u as f64 + 0.5 - x).hypot(v as f64 + 0.5 - y) > reach {
                n += 1;
                moved += ((a.get(u, v) - b.get(u, v)).abs() as f64 > 0.01 * rel) as usize;
            }
        }
    }
    moved as f64 / n as f64
}

/// Runs `cmd`; panics with its stderr unless it succeeds.
pub fn run_ok(cmd: &mut Command) -> Output {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{cmd:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Runs the CLI; panics with its stderr unless it succeeds.
pub fn terrasynth(args: &[&str]) -> Output {
    run_ok(Command::new(env!("CARGO_BIN_EXE_terrasynth")).args(args))
}

/// A proptest configuration of `cases` cases that keeps its failures
/// beside the test's own file (`tests/<target>/<module>.proptest-regressions`,
/// where the committed ones are). Why: proptest's default
/// (`SourceParallel`) finds the `main.rs` of a test target's folder and
/// would read and write `tests/proptest-regressions/<module>.txt` instead,
/// away from the test, and one file for same-named modules of two targets.
pub fn proptest_cases(cases: u32) -> proptest::test_runner::Config {
    proptest::test_runner::Config {
        cases,
        failure_persistence: Some(Box::new(
            proptest::test_runner::FileFailurePersistence::WithSource("proptest-regressions"),
        )),
        ..proptest::test_runner::Config::default()
    }
}
