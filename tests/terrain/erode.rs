//! The local erosion filter (issue 41, `terrasynth erode`, `synth
//! --erode`): a window eroded from its halo is the same bytes as the crop
//! of the whole world eroded (library and CLI, at corners, edges, inside,
//! windows smaller and larger than the halo); it erodes — real DEMs made
//! noisy move back towards themselves on `eval`'s pit and drainage terms
//! and its realism ratio; bad input is refused cleanly.

use crate::common;
use std::process::{Command, Output};
use terrasynth::Heightfield;
use terrasynth::erode::{self, ErodeError, HALO};
use terrasynth::synth::cone::Rect;

/// A test world (281 × 203) falling west (2 m a cell, so flow runs in long
/// lines), with valleys and hash noise.
fn world() -> Heightfield {
    Heightfield::from_fn(281, 203, 30.0, |x, y| {
        let (fx, fy) = (x as f32, y as f32);
        400.0 + 2.0 * fx + 20.0 * (fy / 17.0).sin() * (fx / 23.0).cos() + noise(y * 281 + x, 1.0)
    })
    .unwrap()
}

/// Deterministic noise in ±amp/2 for cell `i`.
fn noise(i: usize, amp: f32) -> f32 {
    let mut x = (i as u32).wrapping_mul(0x9E37_79B1) ^ 0x85EB_CA6B;
    x ^= x >> 15;
    x = x.wrapping_mul(0x2C1B_3C6D);
    x ^= x >> 12;
    amp * ((x & 0xFFFF) as f32 / 65535.0 - 0.5)
}

fn bits(hf: &Heightfield) -> Vec<u32> {
    hf.data().iter().map(|v| v.to_bits()).collect()
}

#[test]
fn windows_erode_to_the_bytes_of_the_eroded_worlds_crops() {
    let hf = world();
    let size = (hf.width(), hf.height());
    for strength in [1.0, 4.5] {
        let whole = erode::erode(&hf, strength).unwrap();
        assert_ne!(
            bits(&whole),
            bits(&hf),
            "strength {strength} changed nothing"
        );
        for win in [
            Rect::new(0, 0, 281, 203),
            Rect::new(0, 0, 1, 1),
            Rect::new(280, 202, 1, 1),
            Rect::new(100, 80, 7, 5),
            Rect::new(HALO + 3, HALO + 1, 97, 64),
            Rect::new(37, 0, 150, 20),
            Rect::new(200, 150, 81, 53),
            Rect::new(0, 90, 281, 2),
        ] {
            let ext = erode::extent(size, win);
            let part = hf.crop(ext.x0, ext.y0, ext.width(), ext.height()).unwrap();
            let got = erode::window(&part, ext, win, strength).unwrap();
            let want = whole
                .crop(win.x0, win.y0, win.width(), win.height())
                .unwrap();
            assert!(bits(&got) == bits(&want), "{win:?} at strength {strength}");
        }
    }
    // The halo is needed: the window eroded on its own differs.
    let tight = hf.crop(120, 90, 20, 20).unwrap();
    let want = erode::erode(&hf, 1.0)
        .unwrap()
        .crop(120, 90, 20, 20)
        .unwrap();
    assert!(bits(&erode::erode(&tight, 1.0).unwrap()) != bits(&want));
}

fn terrasynth(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_terrasynth"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn synth_windows_with_erosion_are_crops_of_the_eroded_world() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let base = ["synth", "--size", "300x260", "--seed", "3", "--erode", "2"];
    let out = terrasynth(&[&base[..], &["-o", &p("whole.tif")]].concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let plain = terrasynth(&[
        "synth",
        "--size",
        "300x260",
        "--seed",
        "3",
        "-o",
        &p("plain.tif"),
    ]);
    assert!(plain.status.success());
    let read =
        |n: &str| terrasynth::io::read(dir.path().join(n).as_path(), &Default::default()).unwrap();
    let whole = read("whole.tif");
    assert_ne!(
        bits(&whole),
        bits(&read("plain.tif")),
        "--erode changed nothing"
    );
    for (i, (x, y, w, h)) in [(0, 0, 64, 64), (101, 77, 90, 50), (250, 200, 50, 60)]
        .into_iter()
        .enumerate()
    {
        let name = format!("win{i}.tif");
        let arg = format!("{x},{y},{w},{h}");
        let out = terrasynth(&[&base[..], &["--window", &arg, "-o", &p(&name)]].concat());
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let want = whole.crop(x, y, w, h).unwrap();
        assert!(bits(&read(&name)) == bits(&want), "window {arg}");
    }
}

#[test]
fn noisy_real_dems_erode_back_towards_themselves() {
    for name in ["pyrenees_andorra", "thuringia_hills"] {
        let Some(real) = common::dem::heights(name, "erosion against a real DEM") else {
            return;
        };
        let mut noisy = real.clone();
        for (i, v) in noisy.data_mut().iter_mut().enumerate() {
            *v += noise(i, 8.0);
        }
        let eroded = erode::erode(&noisy, erode::DEFAULT_STRENGTH).unwrap();
        let before = terrasynth::eval::compare(&noisy, &real).unwrap();
        let after = terrasynth::eval::compare(&eroded, &real).unwrap();
        let d = |c: &terrasynth::eval::Comparison, id: &str| {
            c.descriptors.iter().find(|x| x.id == id).unwrap().distance
        };
        println!(
            "{name}: ratio {:.3} -> {:.3}; pits {:.4} -> {:.4}; drainage {:.4} -> {:.4}; olsen {:.4} -> {:.4}",
            before.ratio,
            after.ratio,
            d(&before, "pits"),
            d(&after, "pits"),
            d(&before, "drainage"),
            d(&after, "drainage"),
            d(&before, "olsen"),
            d(&after, "olsen")
        );
        for id in ["pits", "drainage"] {
            assert!(d(&after, id) < d(&before, id), "{name}: {id} moved away");
        }
        assert!(after.ratio < 0.75 * before.ratio, "{name}: realism ratio");
    }
}

#[test]
fn bad_input_is_refused_cleanly() {
    let mut hf = world();
    assert!(matches!(
        erode::erode(&hf, f32::NAN),
        Err(ErodeError::Strength(_))
    ));
    assert!(matches!(
        erode::erode(&hf, 10.5),
        Err(ErodeError::Strength(_))
    ));
    let same = erode::erode(&hf, 0.0).unwrap();
    assert_eq!(same.data(), hf.data(), "strength 0 changes nothing");
    let win = Rect::new(10, 10, 5, 5);
    let e = erode::window(&hf, Rect::new(12, 0, 100, 100), win, 1.0).unwrap_err();
    assert!(matches!(e, ErodeError::Window { .. }), "{e}");
    hf.set(7, 9, f32::NAN);
    let e = erode::erode(&hf, 1.0).unwrap_err();
    assert!(e.to_string().contains("(7, 9)"), "{e}");
    // The CLI: nodata, the input as output, a bad strength.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("holes.tif");
    terrasynth::io::write(&hf, &input, &Default::default()).unwrap();
    let out_path = dir.path().join("out.tif");
    let (i, o) = (input.to_str().unwrap(), out_path.to_str().unwrap());
    let out = terrasynth(&["erode", i, "-o", o]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("holes.tif") && err.contains("(7, 9)"),
        "{err}"
    );
    assert!(!err.contains("panicked") && !out_path.exists(), "{err}");
    let before = std::fs::read(&input).unwrap();
    let out = terrasynth(&["erode", i, "-o", i, "--strength", "0"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("overwrite"), "{err}");
    assert_eq!(
        std::fs::read(&input).unwrap(),
        before,
        "the input is untouched"
    );
    let out = terrasynth(&["erode", i, "-o", o, "--strength", "11"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("0..=10"), "{err}");
    let out = terrasynth(&["synth", "--size", "64x64", "--erode", "-1", "-o", o]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && !err.contains("panicked"), "{err}");
    assert!(!out_path.exists());
}
