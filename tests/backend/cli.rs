//! `--backend` on the CLI: `cpu`, `gpu` and `auto` write the same bytes
//! (heightfield and preview, which the GPU also shades);
//! `auto` without a GPU says so in one line and uses the CPU; `gpu` where
//! there is none fails cleanly (no panic, no output file).

use std::path::Path;
use std::process::{Command, Output};

fn terrasynth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(args)
        .env("RUST_BACKTRACE", "1")
        .env("NODEVICE_SELECT", "1")
        .output()
        .unwrap()
}

/// Runs `synth` with a preview; returns the heightfield and preview bytes
/// (when written), concatenated.
fn synth(dir: &Path, backend: &str) -> (Output, Option<Vec<u8>>) {
    let path = dir.join(format!("{backend}.png"));
    let preview = dir.join(format!("{backend}-preview.png"));
    let out = terrasynth(&[
        "synth",
        "--size",
        "96x64",
        "--seed",
        "7",
        "--backend",
        backend,
        "-o",
        path.to_str().unwrap(),
        "--preview",
        preview.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&path)
        .ok()
        .map(|b| [b, std::fs::read(&preview).unwrap()].concat());
    (out, bytes)
}

fn notes(out: &Output) -> Vec<String> {
    String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.starts_with("note: "))
        .map(str::to_owned)
        .collect()
}

#[test]
fn backends_write_the_same_bytes_and_auto_falls_back_with_a_notice() {
    let dir = tempfile::tempdir().unwrap();
    let (cpu, cpu_bytes) = synth(dir.path(), "cpu");
    assert!(cpu.status.success(), "{cpu:?}");
    assert!(notes(&cpu).is_empty());
    let cpu_bytes = cpu_bytes.unwrap();

    let (auto, auto_bytes) = synth(dir.path(), "auto");
    assert!(auto.status.success(), "{auto:?}");
    assert_eq!(auto_bytes.unwrap(), cpu_bytes, "auto must match cpu");
    let auto_notes = notes(&auto);
    assert!(auto_notes.len() <= 1, "{auto_notes:?}");
    if !cfg!(feature = "gpu") {
        assert_eq!(
            auto_notes.len(),
            1,
            "auto without a GPU backend must say so"
        );
        assert!(
            auto_notes[0].contains("--features gpu") && auto_notes[0].ends_with("using the CPU")
        );
    }

    let (gpu, gpu_bytes) = synth(dir.path(), "gpu");
    let err = String::from_utf8_lossy(&gpu.stderr);
    assert!(!err.contains("panicked"), "{err}");
    if gpu.status.success() {
        assert_eq!(gpu_bytes.unwrap(), cpu_bytes, "gpu must match cpu");
        assert!(
            auto_notes.is_empty(),
            "auto found no GPU but gpu ran: {auto_notes:?}"
        );
    } else {
        assert!(
            !cfg!(feature = "gpu") || std::env::var_os("TERRASYNTH_REQUIRE_GPU").is_none(),
            "TERRASYNTH_REQUIRE_GPU is set but --backend gpu failed: {err}"
        );
        assert!(err.starts_with("error: "), "{err}");
        if cfg!(feature = "gpu") {
            assert!(err.contains("no usable GPU adapter"), "{err}");
        } else {
            assert!(err.contains("--features gpu"), "{err}");
        }
        assert!(gpu_bytes.is_none(), "no output file on failure");
        assert_eq!(auto_notes.len(), 1);
    }
}

#[test]
fn bench_reports_the_backend_and_its_clock() {
    let out = terrasynth(&[
        "bench",
        "--sizes",
        "64x64",
        "--runs",
        "1",
        "--json",
        "--backend",
        "auto",
    ]);
    assert!(out.status.success(), "{out:?}");
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let s = &v["sizes"][0];
    let gpu = notes(&out).is_empty() && cfg!(feature = "gpu");
    assert_eq!(s["backend"], if gpu { "gpu" } else { "cpu" });
    if !gpu {
        assert_eq!(s["clock"], "wall clock");
    }
    assert!(s["stages"]["correct"].as_f64().unwrap() > 0.0);
}

/// Runs `edit` over the example scene and its edit; returns the frames'
/// heightfield bytes, or None when the run failed.
fn edit(dir: &Path, backend: &str) -> (Output, Option<Vec<u8>>) {
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes");
    let out_dir = dir.join(backend);
    let out = terrasynth(&[
        "edit",
        scenes.join("coast_range.json").to_str().unwrap(),
        scenes.join("coast_range_edit1.json").to_str().unwrap(),
        "--out-dir",
        out_dir.to_str().unwrap(),
        "--ext",
        "r32",
        "--backend",
        backend,
    ]);
    let frames = (0..2)
        .map(|k| std::fs::read(out_dir.join(format!("frame_{k:03}.r32"))).ok())
        .collect::<Option<Vec<_>>>()
        .map(|f| f.concat());
    (out, frames)
}

/// A controlled editing session (curves, points, paint, freeze, paste, a
/// coherent second frame) writes the same frames on every backend.
#[test]
fn edit_sessions_write_the_same_frames_on_every_backend() {
    let dir = tempfile::tempdir().unwrap();
    let (cpu, cpu_frames) = edit(dir.path(), "cpu");
    assert!(cpu.status.success(), "{cpu:?}");
    let cpu_frames = cpu_frames.unwrap();
    let (gpu, gpu_frames) = edit(dir.path(), "gpu");
    let err = String::from_utf8_lossy(&gpu.stderr);
    assert!(!err.contains("panicked"), "{err}");
    if gpu.status.success() {
        assert!(
            gpu_frames.unwrap() == cpu_frames,
            "gpu frames must match cpu"
        );
    } else {
        assert!(
            std::env::var_os("TERRASYNTH_REQUIRE_GPU").is_none(),
            "TERRASYNTH_REQUIRE_GPU is set but the GPU session failed: {err}"
        );
        eprintln!("no GPU: only the CPU session ran ({})", err.trim());
        assert!(err.starts_with("error: "), "{err}");
        assert!(gpu_frames.is_none(), "no frames on failure");
    }
}
