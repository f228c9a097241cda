//! Windowed synthesis of scenes (issue 17): a window of a scene with every
//! kind of control — points, a curve, painted types (with an eraser),
//! frozen strokes, a terrain paste, an exemplar paste and a terrain paste
//! that copies the first one's target — is byte for byte the same crop as
//! the scene synthesized whole (`synth --scene`: an editing session's
//! first step), whether or not the window holds a control, a paste's
//! target or its source.

use serde_json::json;
use std::path::Path;
use std::sync::OnceLock;
use terrasynth::Heightfield;
use terrasynth::database::{Database, default};
use terrasynth::progress::Silent;
use terrasynth::scene::{Scene, SceneEdits, WindowedScene};
use terrasynth::synth::cone::Rect;
use terrasynth::synth::session::Session;
use terrasynth::synth::{SynthError, Synthesizer, WindowControls, WindowError};

fn db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

fn scene(v: serde_json::Value) -> Scene {
    Scene::parse(v.to_string().as_bytes(), Path::new("test.json")).unwrap()
}

/// Every control at once on a 320 × 256 world.
fn everything() -> serde_json::Value {
    json!({
        "size": [320, 256], "seed": 17,
        "points": [
            {"id": "peak", "at": [70, 60], "height_m": 2600, "radius_px": 30},
            {"id": "pit", "at": [250, 200], "height_m": 300, "slope_deg": 10, "radius_px": 20}
        ],
        "curves": [{"id": "ridge", "points": [[10, 150], [120, 120], [200, 170], [310, 140]],
            "widgets": [
                {"at": 0.0, "height_m": 1800, "slope_deg": [-20, -20], "reach_px": [25, 25]},
                {"at": 1.0, "height_m": 1500, "slope_deg": [-10, -30], "reach_px": [15, 30]}]}],
        "types": {"strokes": [
            {"type": "mountains", "points": [[200, 40], [300, 60]], "radius_px": 25},
            {"type": "flat", "points": [[40, 220]], "radius_px": 30},
            {"erase": true, "points": [[260, 50]], "radius_px": 8}]},
        "freeze": {"strokes": [{"points": [[150, 30], [170, 90]], "radius_px": 12}]},
        "pastes": [
            {"id": "copy", "source": "terrain", "lasso": [[20, 20], [60, 25], [50, 70], [15, 60]], "to": [240, 110]},
            {"id": "dome", "source": "exemplar", "exemplar": 2, "lasso": [[100, 100], [160, 100], [130, 150]],
             "to": [100, 200], "delta_m": 150},
            {"id": "again", "source": "terrain", "lasso": [[225, 95], [255, 95], [255, 125], [225, 125]],
             "to": [290, 230], "delta_m": -50}
        ]
    })
}

/// The whole scene through an editing session, as `synth --scene` does.
fn whole(s: &Scene) -> Heightfield {
    let mut edits = SceneEdits::new();
    let first = edits.edits(s, db()).unwrap();
    let mut session = Session::new(db(), SceneEdits::params(s), s.width, s.height, s.seed).unwrap();
    session.apply(first).unwrap().heightfield
}

fn check(s: &Scene, windows: &[Rect]) {
    let all = whole(s);
    let ws = WindowedScene::new(s, db()).unwrap();
    let synth = Synthesizer::new(db(), ws.params()).unwrap();
    for &win in windows {
        let got = ws.synthesize_window(&synth, win).unwrap();
        let want = all.crop(win.x0, win.y0, win.width(), win.height()).unwrap();
        let bits = |h: &Heightfield| -> Vec<u32> { h.data().iter().map(|v| v.to_bits()).collect() };
        let (g, w) = (bits(&got), bits(&want));
        if let Some(k) = (0..g.len()).find(|&k| g[k] != w[k]) {
            panic!(
                "window {win:?}: pixel ({}, {}) is {} m, the whole scene has {} m",
                win.x0 + k % win.width(),
                win.y0 + k / win.width(),
                got.data()[k],
                want.data()[k]
            );
        }
    }
}

#[test]
fn windows_of_a_scene_with_every_control_are_its_crops() {
    check(
        &scene(everything()),
        &[
            // The first paste's target and the third's source.
            Rect::new(210, 80, 60, 60),
            // The third paste's target at the world's corner.
            Rect::new(270, 205, 50, 51),
            // The exemplar paste, a point and types.
            Rect::new(60, 170, 90, 70),
            // The freeze stroke and the mountains paint, straddling a tile
            // border of 128.
            Rect::new(120, 20, 97, 81),
            // Everything.
            Rect::new(0, 0, 320, 256),
            // Far from every control, odd-sized.
            Rect::new(5, 101, 33, 17),
        ],
    );
}

/// Version 2: the same pastes land on the ground, each lifted by the
/// median step along its whole rim — a window that sees part of a target
/// must find the same lift as the whole scene.
#[test]
fn windows_of_a_scene_with_ground_pastes_are_its_crops() {
    let mut v = everything();
    v["version"] = json!(2);
    check(
        &scene(v),
        &[
            // Part of the first paste's target, and the third's source.
            Rect::new(245, 100, 40, 40),
            // A corner of the third paste's target.
            Rect::new(300, 240, 20, 16),
            // Part of the exemplar paste.
            Rect::new(60, 170, 50, 40),
            // Everything.
            Rect::new(0, 0, 320, 256),
        ],
    );
}

#[test]
fn scenes_without_pastes_take_one_frame() {
    let mut v = everything();
    v["pastes"] = json!([]);
    v["size"] = json!([317, 250]);
    check(
        &scene(v),
        &[Rect::new(0, 0, 317, 250), Rect::new(101, 33, 150, 150)],
    );
}

#[test]
fn bad_paint_is_a_typed_error() {
    let synth = Synthesizer::new(db(), Default::default()).unwrap();
    let short = |_: Rect| vec![0u8; 3];
    let c = WindowControls {
        constraints: &[],
        types: Some(&short),
        freeze: None,
        pastes: &[],
    };
    let e = synth.synthesize_window_with((100, 100), Rect::new(0, 0, 10, 10), 1, &c);
    assert!(
        matches!(
            e,
            Err(SynthError::Window(WindowError::Paint { got: 3, .. }))
        ),
        "{e:?}"
    );
    let wild = |r: Rect| vec![40u8; r.pixels()];
    let c = WindowControls {
        types: Some(&wild),
        ..c
    };
    let e = synth.synthesize_window_with((100, 100), Rect::new(0, 0, 10, 10), 1, &c);
    assert!(
        matches!(
            e,
            Err(SynthError::Window(WindowError::TypeId { id: 40, .. }))
        ),
        "{e:?}"
    );
}

/// The GPU makes the same scene windows (type seeding at absolute
/// coordinates, guides over the cone, the paste frame).
#[cfg(feature = "gpu")]
#[test]
fn gpu_scene_windows_match_the_cpu() {
    use crate::common::gpu;
    let Some(ctx) = gpu::context() else { return };
    let s = scene(everything());
    let ws = WindowedScene::new(&s, db()).unwrap();
    let cpu = Synthesizer::new(db(), ws.params()).unwrap();
    let mut gpu = Synthesizer::new(db(), ws.params()).unwrap();
    gpu.use_gpu(ctx).unwrap();
    let win = Rect::new(190, 30, 110, 100);
    let bits = |h: &Heightfield| -> Vec<u32> { h.data().iter().map(|v| v.to_bits()).collect() };
    let (a, b) = (
        ws.synthesize_window(&cpu, win).unwrap(),
        ws.synthesize_window(&gpu, win).unwrap(),
    );
    assert!(bits(&a) == bits(&b), "GPU window differs");
}
