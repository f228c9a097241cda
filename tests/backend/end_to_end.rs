//! CPU ≡ GPU, byte for byte, end to end (DESIGN §6): whole syntheses
//! (from the default database and from a database of ../shared/dem crops),
//! a scene's editing session, and a sketch synthesis with stage `fill_ssd`
//! on each backend. Each stage on its own is checked by its `tests/stages/<x>.rs`.
//!
//! Needs `--features gpu` and a Vulkan adapter (lavapipe will do: Debian
//! package `mesa-vulkan-drivers`); without one every test prints why and
//! passes without checking anything.
#![cfg(feature = "gpu")]

use crate::common;
use std::path::Path;
use std::sync::Arc;
use terrasynth::backend::gpu::Context;
use terrasynth::database::Database;
use terrasynth::level::fixed::Coord;
use terrasynth::synth::{Params, Synthesizer};

use crate::common::db::{PYRENEES_JURA, default_db, two_dems};
use crate::common::dem;

/// The shared device, or `None` without an adapter (see `common::gpu`).
fn ctx() -> Option<Arc<Context>> {
    common::gpu::context()
}

fn assert_states_eq(gpu: &(Vec<Coord>, Vec<i32>), cpu: &(Vec<Coord>, Vec<i32>), what: &str) {
    if let Some(i) = (0..cpu.0.len()).find(|&i| gpu.0[i] != cpu.0[i] || gpu.1[i] != cpu.1[i]) {
        panic!(
            "{what}: first difference at pixel {i}: GPU {:?} V {} vs CPU {:?} V {}",
            gpu.0[i], gpu.1[i], cpu.0[i], cpu.1[i]
        );
    }
    assert_eq!(gpu, cpu, "{what}");
}

/// A whole synthesis (pieces of `start`, or of every exemplar): same
/// heights (bit patterns), same kept levels.
fn check_end_to_end(
    db: &Database,
    ctx: Arc<Context>,
    (w, h): (usize, usize),
    seed: u32,
    start: Option<usize>,
) {
    let params = Params {
        keep_levels: true,
        start_exemplar: start,
        ..Params::default()
    };
    let cpu = Synthesizer::new(db, params.clone()).unwrap();
    let mut gpu = Synthesizer::new(db, params).unwrap();
    gpu.use_gpu(ctx).unwrap();
    assert_eq!((cpu.backend_name(), gpu.backend_name()), ("cpu", "gpu"));
    let (a, b) = (cpu.run(w, h, seed).unwrap(), gpu.run(w, h, seed).unwrap());
    for (la, lb) in a.levels.iter().zip(&b.levels) {
        assert_states_eq(
            &(lb.coords.clone(), lb.offsets.clone()),
            &(la.coords.clone(), la.offsets.clone()),
            &format!("level {} after synthesis", la.level),
        );
    }
    let bits = |s: &terrasynth::synth::Synthesis| -> Vec<u32> {
        s.heightfield.data().iter().map(|v| v.to_bits()).collect()
    };
    assert_eq!(bits(&a), bits(&b), "output heights");
}

#[test]
fn end_to_end_synthesis_is_identical() {
    let Some(ctx) = ctx() else { return };
    check_end_to_end(default_db(), ctx.clone(), (256, 256), 1, None);
    check_end_to_end(default_db(), ctx.clone(), (173, 61), 77, None);
    // The Pyrenees alone: its start level takes twice the passes.
    let s = Synthesizer::new(
        default_db(),
        Params {
            start_exemplar: Some(2),
            ..Params::default()
        },
    );
    assert_eq!(s.unwrap().level_passes(200, 144), [2, 2, 4]);
    check_end_to_end(default_db(), ctx, (200, 144), 4, Some(2));
}

#[test]
fn end_to_end_synthesis_of_shared_dems_is_identical() {
    let Some(ctx) = ctx() else { return };
    let Some(db) = two_dems(PYRENEES_JURA, "real-DEM end-to-end cross-check") else {
        return;
    };
    check_end_to_end(db, ctx, (256, 200), 5, None);
}

/// End to end: the Fig. 11-style design of `data/scenes/` (curves with
/// junctions, a point, painted types, a frozen region, a paste) and its
/// edit, as an editing session on each backend: every frame's heights and
/// every level's per-pass results must be the same bytes. The second frame
/// is a restricted coherent re-synthesis, so the window path of `correct`
/// (pixels outside take the previous result) runs on the device too.
#[test]
fn scene_session_matches_end_to_end() {
    use terrasynth::scene::{Scene, SceneEdits};
    use terrasynth::synth::session::Session;
    let Some(ctx) = ctx() else { return };
    let db = default_db();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes");
    let scenes: Vec<Scene> = ["coast_range.json", "coast_range_edit1.json"]
        .iter()
        .map(|f| Scene::read(&dir.join(f)).unwrap())
        .collect();
    let base = &scenes[0];
    let run = |gpu: bool| {
        let mut session = Session::new(
            db,
            SceneEdits::params(base),
            base.width,
            base.height,
            base.seed,
        )
        .unwrap();
        if gpu {
            session.synthesizer_mut().use_gpu(ctx.clone()).unwrap();
        }
        assert_eq!(
            session.synthesizer().backend_name(),
            if gpu { "gpu" } else { "cpu" }
        );
        let mut edits = SceneEdits::new();
        scenes
            .iter()
            .map(|s| {
                let list = edits.edits(s, db).unwrap();
                let f = session.apply(list).unwrap();
                (f, session.frames().cloned().unwrap())
            })
            .collect::<Vec<_>>()
    };
    let cpu = run(false);
    let gpu = run(true);
    for (k, ((c, cf), (g, gf))) in cpu.iter().zip(&gpu).enumerate() {
        let (a, b) = (c.heightfield.data(), g.heightfield.data());
        if let Some(i) = (0..a.len()).find(|&i| a[i].to_bits() != b[i].to_bits()) {
            panic!("frame {k}: pixel {i}: GPU {} m vs CPU {} m", b[i], a[i]);
        }
        for (level, (cl, gl)) in cf.levels().iter().zip(gf.levels()).enumerate() {
            assert!(
                cl == gl,
                "frame {k}: level {level}: per-pass results differ"
            );
        }
        assert_eq!(c.change, g.change, "frame {k}: change report");
    }
    let changed = cpu[1].0.change.as_ref().unwrap().pixels;
    assert!(changed > 0, "the edit must change the terrain");
}

/// End to end: a Y-branch sketch built from two shared-DEM crops, with
/// stage `fill_ssd` on each backend, writes the same heights.
#[test]
fn sketch_synthesis_matches_end_to_end() {
    use terrasynth::backend::Choice;
    use terrasynth::backend::engine::Engine;
    use terrasynth::patch::fill::fill_ssd::FillCost;
    use terrasynth::patch::input::sketch::Sketch;
    use terrasynth::patch::{self, Library, Params};
    use terrasynth::progress::Silent;
    if common::gpu::context().is_none() {
        return;
    }
    let mut src = Vec::new();
    // Two sources of ranges' relief (1.68 km and 905 m), so both take part.
    for name in ["pyrenees_andorra", "riviera_coast"] {
        let Some(hf) = dem::heights(name, "the real-DEM sketch cross-check") else {
            return;
        };
        src.push((name.to_string(), hf.crop(200, 200, 256, 256).unwrap()));
    }
    let params = Params {
        patch: 32,
        ..Params::default()
    };
    let lib = Library::prepare(&src, &params, &Silent).unwrap();
    assert_eq!(lib.sources.len(), 2, "left out: {:?}", lib.left_out);
    let sketch = Sketch::from_json(
        br#"{"width": 160, "height": 160, "strokes": [
        {"kind": "ridge", "width": 8, "points": [[80, 90], [30, 20]]},
        {"kind": "ridge", "width": 8, "points": [[80, 90], [130, 20]]},
        {"kind": "valley", "width": 8, "points": [[20, 80], [45, 150]]}]}"#,
        Path::new("y.json"),
    )
    .unwrap();
    let run = |choice| {
        let (engine, notice) = Engine::choose(choice).unwrap();
        assert!(notice.is_none(), "{notice:?}");
        let cost = FillCost::new(&engine, &lib).unwrap();
        let s = patch::synthesize_with(&lib, &sketch, 160, 160, &cost, &Silent).unwrap();
        (cost.name(), s)
    };
    let (cpu_name, cpu) = run(Choice::Cpu);
    let (gpu_name, gpu) = run(Choice::Gpu);
    assert_eq!((cpu_name, gpu_name), ("cpu", "gpu"));
    assert!(gpu.stats.fill_patches > 0, "the fill stage must have run");
    let (a, b) = (cpu.heightfield.data(), gpu.heightfield.data());
    if let Some(i) = (0..a.len()).find(|&i| a[i].to_bits() != b[i].to_bits()) {
        panic!("pixel {i}: GPU {} vs CPU {}", b[i], a[i]);
    }
}
