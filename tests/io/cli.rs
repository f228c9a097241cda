//! The CLI on bad input and on nodata: a message and a non-zero exit, no
//! panic, no backtrace, no partial output file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn terrasynth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(args)
        // A panic would print a backtrace with this set; we must not panic.
        .env("RUST_BACKTRACE", "1")
        .output()
        .unwrap()
}

fn repo(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

fn assert_clean_failure(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected failure: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(err.contains(needle), "{err} should mention {needle}");
    assert!(
        !err.contains("panicked") && !err.contains("backtrace"),
        "{err}"
    );
}

#[test]
fn info_and_convert_report_malformed_files() {
    let bad = repo("tests/malformed/asc/asc_bad_number.asc");
    let out = terrasynth(&["info", bad.to_str().unwrap()]);
    assert_clean_failure(&out, "asc_bad_number.asc: line 7: invalid number \"1.2.3\"");
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("out.exr");
    let bad = repo("tests/malformed/tiff/samples/tiff_huge.tif");
    let out = terrasynth(&["convert", bad.to_str().unwrap(), target.to_str().unwrap()]);
    assert_clean_failure(&out, "100000x100000 is too large");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "no output left behind"
    );
}

#[test]
fn convert_refuses_nodata_where_the_format_cannot_keep_it() {
    let src = repo("tests/fixtures/centre.asc");
    let dir = tempfile::tempdir().unwrap();
    let ter = dir.path().join("out.ter");
    let out = terrasynth(&["convert", src.to_str().unwrap(), ter.to_str().unwrap()]);
    assert_clean_failure(
        &out,
        "ter cannot store nodata, and the heightfield has 2 nodata samples",
    );
    assert!(!ter.exists());
    // A format that keeps nodata takes it as it is.
    let exr = dir.path().join("out.exr");
    let out = terrasynth(&["convert", src.to_str().unwrap(), exr.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = terrasynth(&["info", "--json", exr.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (v["width"].as_u64(), v["nodata"].as_u64()),
        (Some(4), Some(2))
    );
}

#[test]
fn convert_fills_nodata_on_request() {
    let src = repo("tests/fixtures/centre.asc");
    let dir = tempfile::tempdir().unwrap();
    let ter = dir.path().join("filled.ter");
    let out = terrasynth(&[
        "convert",
        "--fill-nodata",
        src.to_str().unwrap(),
        ter.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("filled 2 nodata samples"), "{err}");
    let hf = terrasynth::io::read(&ter, &Default::default()).unwrap();
    assert_eq!(hf.nodata_count(), 0);
    // Harmonic fill stays within the heights around each hole (1..12 m).
    let s = hf.stats().unwrap();
    assert!(s.min >= 0.99 && s.max <= 12.01, "{s:?}");
}

/// `synth --scene X.json -o X.png` would write the PNG's sidecar over the
/// scene: refused before anything is written, the scene intact.
#[test]
fn synth_never_overwrites_its_scene_and_checks_memory_first() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("x.json");
    let text = std::fs::read(repo("data/scenes/coast_range.json")).unwrap();
    std::fs::write(&scene, &text).unwrap();
    let png = dir.path().join("x.png");
    let out = terrasynth(&[
        "synth",
        "--scene",
        scene.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_clean_failure(&out, "refusing to overwrite the input");
    assert_eq!(
        std::fs::read(&scene).unwrap(),
        text,
        "the scene is untouched"
    );
    assert!(!png.exists());
    // A scene far beyond memory is refused up front with the numbers.
    let mut v: serde_json::Value = serde_json::from_slice(&text).unwrap();
    v["size"] = serde_json::json!([30000, 30000]);
    let big = dir.path().join("big.json");
    std::fs::write(&big, serde_json::to_vec(&v).unwrap()).unwrap();
    let out = terrasynth(&[
        "synth",
        "--scene",
        big.to_str().unwrap(),
        "-o",
        dir.path().join("big.exr").to_str().unwrap(),
    ]);
    if terrasynth::io::available_memory().is_some() {
        assert_clean_failure(&out, "a 30000x30000 synthesis needs about");
    }
}

/// `info` says when the cell size is a default and prints both spacings
/// and the CRS; `convert --for unity` prints the import settings.
#[test]
fn info_spacings_and_engine_settings() {
    let dir = tempfile::tempdir().unwrap();
    let hf = terrasynth::Heightfield::from_fn(40, 30, 10.0, |x, y| (x + y) as f32).unwrap();
    let png = dir.path().join("plain.png");
    terrasynth::io::write(&hf, &png, &Default::default()).unwrap();
    std::fs::remove_file(dir.path().join("plain.json")).unwrap();
    let out = terrasynth(&["info", png.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("10 m (default"), "{text}");
    assert!(
        text.contains("spacing:   10.000 m east-west x 10.000 m north-south"),
        "{text}"
    );
    assert!(text.contains("crs:       none"), "{text}");
    let out = terrasynth(&["info", "--json", png.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["cell_size_default"], true);
    let raw = dir.path().join("t.raw");
    let out = terrasynth(&[
        "convert",
        "--for",
        "unity",
        png.to_str().unwrap(),
        raw.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    for want in [
        "40x30 -> 65x65",
        "Resolution: 65",
        "Byte Order: Windows",
        "Flip Vertically: off",
        "Terrain Size: X = 393.846, Y = 6553.500, Z = 295.385",
    ] {
        assert!(err.contains(want), "{want}: {err}");
    }
    assert_eq!(std::fs::metadata(&raw).unwrap().len(), 65 * 65 * 2);
    let bad = dir.path().join("t.exr");
    let out = terrasynth(&[
        "convert",
        "--for",
        "unity",
        png.to_str().unwrap(),
        bad.to_str().unwrap(),
    ]);
    assert_clean_failure(&out, "--for unity writes a 16-bit .raw");
    // masks: every file, sized like the heightfield.
    let masks = dir.path().join("masks");
    let out = terrasynth(&[
        "masks",
        png.to_str().unwrap(),
        "--out-dir",
        masks.to_str().unwrap(),
        "--splat",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "slope.png",
        "flow.png",
        "types.png",
        "types.json",
        "splat.png",
        "masks.json",
    ] {
        assert!(masks.join(f).exists(), "{f}");
    }
}

#[test]
fn a_closed_stdout_ends_a_command_without_a_panic() {
    // `terrasynth … | head -1`: the reader is gone before anything is
    // written (Rust ignores SIGPIPE by default, and println! panicked).
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args([
            "info",
            repo("data/exemplars/thuringia_hills/thuringia_hills.png")
                .to_str()
                .unwrap(),
        ])
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        !out.status.success(),
        "a command that could not write succeeded"
    );
}

/// An 8-bit PNG's size, channels and samples.
fn png8(path: &Path) -> (u32, u32, usize, Vec<u8>) {
    let mut r = png::Decoder::new(std::io::Cursor::new(std::fs::read(path).unwrap()))
        .read_info()
        .unwrap();
    let mut buf = vec![0; r.output_buffer_size().unwrap()];
    let info = r.next_frame(&mut buf).unwrap();
    assert_eq!(info.bit_depth, png::BitDepth::Eight, "{}", path.display());
    buf.truncate(info.buffer_size());
    let channels = info.color_type.samples();
    (info.width, info.height, channels, buf)
}

/// `masks --for`: the masks of the heightmap `convert --for` writes (the
/// engine's size), the splat as Unreal's per-layer weightmaps or Unity's
/// per-cell control texture, each equal to the library's splat of that
/// heightmap and summing to 255.
#[test]
fn masks_for_an_engine_are_at_its_size_in_its_layout() {
    use terrasynth::io::engine::{self, Engine};
    use terrasynth::masks;
    let dem = repo("data/exemplars/pyrenees_andorra/pyrenees_andorra.png");
    let hf = terrasynth::io::read(&dem, &Default::default()).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for (e, side) in [(Engine::Unreal, 1009u32), (Engine::Unity, 513)] {
        let out = dir.path().join(e.name());
        let o = terrasynth(
            &["masks", dem.to_str().unwrap(), "--splat", "--for", e.name()]
                .into_iter()
                .chain(["--out-dir", out.to_str().unwrap()])
                .collect::<Vec<_>>(),
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{err}");
        let want = masks::compute(&engine::prepare(&hf, e).unwrap().heightfield, true)
            .unwrap()
            .splat
            .unwrap();
        assert_eq!(png8(&out.join("slope.png")).0, side);
        match e {
            Engine::Unreal => {
                assert!(err.contains("target layers"), "{err}");
                assert!(!out.join("splat.png").exists());
                let layers = masks::splat_layers(&want);
                let mut sums = vec![0u32; (side * side) as usize];
                for (name, w) in masks::SPLAT_LAYERS.iter().zip(&layers) {
                    let (pw, ph, ch, got) = png8(&out.join(format!("splat_{name}.png")));
                    assert_eq!((pw, ph, ch), (side, side, 1), "{name}");
                    assert!(&got == w, "splat_{name}.png differs from the splat's layer");
                    for (s, &v) in sums.iter_mut().zip(&got) {
                        *s += u32::from(v);
                    }
                }
                assert!(sums.iter().all(|&s| s == 255));
                // Mountains: some rock, some grass.
                assert!(layers[1].iter().any(|&v| v > 128) && layers[0].iter().any(|&v| v > 128));
            }
            Engine::Unity => {
                assert!(err.contains("Control Texture Resolution 512"), "{err}");
                let (pw, ph, ch, got) = png8(&out.join("splat.png"));
                assert_eq!((pw, ph, ch), (512, 512, 4));
                let cells = masks::splat_cells(&want, side as usize, side as usize);
                assert!(
                    got == cells.as_flattened(),
                    "splat.png differs from the cell splat"
                );
                assert!(
                    got.chunks(4)
                        .all(|p| p.iter().map(|&v| u32::from(v)).sum::<u32>() == 255)
                );
            }
        }
    }
}
