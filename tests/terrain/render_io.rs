//! The preview renderer's inputs and outputs: type masks read from PNG,
//! PNG output, overlays in cell coordinates, the shared DEMs and the CLI.

use crate::common;
use crate::common::render::plain;
use image::Rgba;
use std::path::{Path, PathBuf};
use std::process::Command;
use terrasynth::Heightfield;
use terrasynth::io::TypeMask;
use terrasynth::render::{Grid, RenderOptions, TypeOverlay, render};

fn dem_dir() -> Option<PathBuf> {
    common::dem::dir("the shared-DEM previews").map(Path::to_path_buf)
}

#[test]
fn type_masks_read_from_png_with_names() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.png");
    let mut img = image::GrayImage::new(3, 2);
    img.put_pixel(1, 0, image::Luma([4]));
    img.save(&path).unwrap();
    std::fs::write(dir.path().join("m.json"), r#"{"types": {"4": "canyon"}}"#).unwrap();
    let m = TypeMask::read(&path).unwrap();
    assert_eq!((m.width, m.height), (3, 2));
    assert_eq!(m.indices, &[0, 4, 0, 0, 0, 0]);
    assert_eq!(m.names[&4], "canyon");

    // Not 8-bit greyscale, truncated, or with bad names: a clear error.
    let rgb = dir.path().join("rgb.png");
    image::RgbImage::new(2, 2).save(&rgb).unwrap();
    let e = TypeMask::read(&rgb).unwrap_err().to_string();
    assert!(
        e.contains("rgb.png") && e.contains("8-bit greyscale"),
        "{e}"
    );
    let cut = dir.path().join("cut.png");
    std::fs::write(&cut, &std::fs::read(&path).unwrap()[..40]).unwrap();
    assert!(TypeMask::read(&cut).is_err());
    std::fs::write(dir.path().join("m.json"), "{").unwrap();
    let e = TypeMask::read(&path).unwrap_err().to_string();
    assert!(e.contains("m.json"), "{e}");
}

#[test]
fn png_output_is_written_atomically_and_reads_back() {
    let hf = Heightfield::from_fn(30, 20, 1.0, |x, y| (x + y) as f32).unwrap();
    let p = render(&hf, &RenderOptions::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.png");
    terrasynth::render::write_png(&path, &p.image).unwrap();
    let back = image::open(&path).unwrap().to_rgba8();
    assert_eq!(back, p.image);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    let missing = dir.path().join("no/such/dir.png");
    assert!(terrasynth::render::write_png(&missing, &p.image).is_err());
}

#[test]
fn overlays_draw_in_cell_coordinates() {
    let hf = Heightfield::from_fn(64, 64, 1.0, |_, _| 1.0).unwrap();
    let mut p = render(&hf, &plain()).unwrap();
    let before = p.image.clone();
    let red = Rgba([255, 0, 0, 255]);
    p.canvas().point((32.0, 32.0), 2.0, red);
    assert_eq!(p.image.get_pixel(32, 32).0, [255, 0, 0, 255]);
    assert_eq!(p.image.get_pixel(10, 10), before.get_pixel(10, 10));
}

#[test]
fn every_shared_dem_renders_with_its_types() {
    let Some(dir) = dem_dir() else { return };
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix("_types.png") else {
            continue;
        };
        let hf =
            terrasynth::io::read(&dir.join(format!("{stem}.png")), &Default::default()).unwrap();
        let mask = TypeMask::read(&path).unwrap();
        assert!(!mask.names.is_empty(), "{stem}: type names");
        let o = RenderOptions {
            types: Some(TypeOverlay::new(mask)),
            grid: Grid::Metres(5000.0),
            ..RenderOptions::default()
        };
        let p = render(&hf, &o).unwrap();
        assert_eq!(p.image.width() as usize, hf.width(), "{stem}");
        let i = &p.info;
        let (lo, hi) = i.height_range_m.unwrap();
        let lines = (hi - lo) / i.contour_interval_m.unwrap();
        assert!(
            (8.0..=20.0).contains(&lines),
            "{stem}: {lines} contour levels"
        );
        assert_eq!(
            i.sea_level_m.is_some(),
            lo < 0.0,
            "{stem}: water iff below 0 m"
        );
        // A real picture: many distinct colours.
        let mut colours: Vec<u32> = p.image.pixels().map(|c| u32::from_le_bytes(c.0)).collect();
        colours.sort_unstable();
        colours.dedup();
        assert!(
            colours.len() > 1000,
            "{stem}: only {} colours",
            colours.len()
        );
        seen += 1;
    }
    assert_eq!(seen, 8, "expected the 8 shared DEMs");
}

fn cli() -> Command {
    Command::new(env!("CARGO_BIN_EXE_terrasynth"))
}

#[test]
fn cli_renders_and_explains() {
    let help = cli().args(["render", "--help"]).output().unwrap();
    let text = String::from_utf8_lossy(&help.stdout);
    for flag in [
        "--contour",
        "--no-contours",
        "--grid",
        "--range",
        "--types",
        "--exaggeration",
        "--max-size",
    ] {
        assert!(text.contains(flag), "help lacks {flag}");
    }

    let dir = tempfile::tempdir().unwrap();
    let hf = Heightfield::from_fn(40, 30, 10.0, |x, y| (x * y) as f32 - 50.0).unwrap();
    let input = dir.path().join("t.png");
    terrasynth::io::write(&hf, &input, &Default::default()).unwrap();
    let out = dir.path().join("p.png");
    let run = cli()
        .args([
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--range", "-10:500", "--grid", "5", "--contour", "25"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{err}");
    assert!(err.contains("contours every 25 m"), "{err}");
    assert!(image::open(&out).is_ok());

    // A mask of the wrong size: non-zero exit, message names both sizes.
    let mask = dir.path().join("m.png");
    image::GrayImage::new(3, 3).save(&mask).unwrap();
    let run = cli()
        .args([
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--types", mask.to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(err.contains("3x3") && err.contains("40x30"), "{err}");
    assert!(!err.contains("panicked"), "{err}");

    let run = cli()
        .args([
            "render",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--range", "9:1"])
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("MIN:MAX"));
}
