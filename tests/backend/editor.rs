//! The editor on the GPU (`serve --backend gpu`): a session whose terrain
//! is synthesized and whose preview is shaded on the GPU shows the same
//! heights and the same preview, byte for byte, as one on the CPU — its
//! first frame, an edit of a point and a curve, and an undo (the
//! restricted re-synthesis of an edit runs on the session's engine).
#![cfg(all(feature = "gpu", feature = "serve"))]

use crate::common::{self, editor, http};
use serde_json::{Value, json};
use terrasynth::backend::engine::Engine;
use terrasynth::server::Running;

const N: usize = 192;

fn doc(height: f64) -> Value {
    json!({"version": 2, "size": [N, N], "seed": 5,
        "points": [{"id": "p", "at": [50, 60], "height_m": height, "radius_px": 18}],
        "curves": [{"id": "c", "points": [[20, 140], [100, 120], [180, 150]],
            "widgets": [{"at": 0.5, "height_m": 1500, "slope_deg": [-20, -20], "reach_px": [16, 16]}]}]})
}

/// Heights and preview of every step on one server: the first frame, a
/// point moved up, the curve raised, an undo. Every frame says it ran on
/// `backend`.
fn steps(server: &Running, backend: &str) -> Vec<(Vec<f32>, Vec<u8>)> {
    let addr = server.addr;
    let (s, first) = editor::create_with(addr, &doc(1200.0));
    assert_eq!(first["backend"], backend);
    let mut out = Vec::new();
    let look = |out: &mut Vec<(Vec<f32>, Vec<u8>)>| {
        let preview = http::get(addr, &format!("/api/sessions/{s}/preview.png"));
        assert_eq!(preview.status, 200);
        out.push((editor::heights(addr, &s), preview.body));
    };
    look(&mut out);
    let mut d = doc(1900.0);
    let edited = |r: http::Response| {
        assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
        assert_eq!(r.json()["backend"], backend);
    };
    edited(editor::put_scene(addr, &s, &d, true));
    look(&mut out);
    d["curves"][0]["widgets"][0]["height_m"] = json!(2100);
    edited(editor::put_scene(addr, &s, &d, true));
    look(&mut out);
    edited(http::post(addr, &format!("/api/sessions/{s}/undo"), None));
    look(&mut out);
    out
}

#[test]
fn an_editor_session_on_the_gpu_shows_the_cpus_bytes() {
    let Some(ctx) = common::gpu::context() else {
        return;
    };
    let on = |engine: Engine| editor::serve_with(N, None, |c| c.engine = engine);
    let cpu = steps(&on(Engine::default()), "cpu");
    let gpu = steps(&on(Engine::Gpu(ctx)), "gpu");
    assert_ne!(cpu[0].0, cpu[1].0, "the edit changes the terrain");
    for (k, (c, g)) in cpu.iter().zip(&gpu).enumerate() {
        let same =
            c.0.iter()
                .zip(&g.0)
                .all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(
            same && c.0.len() == g.0.len(),
            "step {k}: the heights differ"
        );
        assert!(c.1 == g.1, "step {k}: the previews differ");
    }
}
