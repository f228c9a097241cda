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
    let bad = repo("tests/malformed/asc_bad_number.asc");
    let out = terrasynth(&["info", bad.to_str().unwrap()]);
    assert_clean_failure(&out, "asc_bad_number.asc: line 7: invalid number \"1.2.3\"");
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("out.exr");
    let bad = repo("tests/malformed/tiff_huge.tif");
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
