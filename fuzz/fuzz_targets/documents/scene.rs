//! Fuzzes the scene-file parser, then builds the curves of small scenes
//! (junction search, distance fields and envelopes on hostile geometry)
//! and paints their type and freeze strokes (never their image forms,
//! which would read files).
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::path::Path;
use terrasynth::scene::{Freeze, Scene, TypePaint};
use terrasynth::synth::control::curve::{FieldCache, build};

fuzz_target!(|data: &[u8]| {
    let Ok(scene) = Scene::parse(data, Path::new("fuzz.json")) else {
        return;
    };
    let small = scene.width * scene.height <= 256 * 256
        && scene.curves.len() <= 8
        && scene
            .curves
            .iter()
            .all(|c| c.spec.widgets.iter().all(|w| w.reach_px[0] <= 64.0 && w.reach_px[1] <= 64.0));
    if small {
        let _ = build(&scene.curve_specs(), &scene.junctions, 10.0, &FieldCache::new());
        if matches!(scene.types, Some(TypePaint::Strokes(_))) {
            let _ = scene.type_raster(&["ridge".into(), "slope".into()]);
        }
        if matches!(scene.freeze, Some(Freeze::Strokes(_))) {
            let _ = scene.freeze_raster();
        }
    }
});
