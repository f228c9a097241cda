//! Windowed synthesis (issue 17): any window of a world is byte for byte
//! the same crop of the whole world's synthesis — at random offsets and
//! sizes, odd, straddling tile borders, at the world's edges, for every
//! kind of start (blocks, the centre without jitter, worlds smaller than
//! the database's coarsest level) — and bad worlds or windows are typed
//! errors. Scenes are in `tests/backend/window_scene.rs`, tiles in `tests/synth/tiles.rs`.

use proptest::prelude::*;
use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};
use terrasynth::database::{Database, default};
use terrasynth::progress::Silent;
use terrasynth::size::GridWindow;
use terrasynth::synth::cone::Rect;
use terrasynth::synth::{Params, SynthError, Synthesizer, WindowError};

fn db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

/// Parameter sets the windows are checked under: the default (block
/// start), no jitter (the exemplar centre, levels above L), one pass, and
/// blocks from one exemplar with the paper's relative heights — the
/// Pyrenees, whose start level takes twice the passes (checked by
/// `every_start_and_pass_count`), so its cone widens more there.
fn params(kind: usize) -> Params {
    let d = Params::default();
    match kind {
        0 => d,
        1 => Params { jitter: 0.0, ..d },
        2 => Params { passes: 1, ..d },
        _ => Params {
            start_exemplar: Some(2),
            prior: 0,
            ..d
        },
    }
}

/// Bit patterns of the whole `w × h` world (cached: many windows per world).
fn whole(kind: usize, w: usize, h: usize, seed: u32) -> std::sync::Arc<Vec<u32>> {
    type Cache = Mutex<HashMap<(usize, usize, usize, u32), std::sync::Arc<Vec<u32>>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(Default::default);
    if let Some(v) = cache.lock().unwrap().get(&(kind, w, h, seed)) {
        return v.clone();
    }
    let s = Synthesizer::new(db(), params(kind)).unwrap();
    let hf = s.synthesize(w, h, seed).unwrap();
    let v = std::sync::Arc::new(hf.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>());
    cache.lock().unwrap().insert((kind, w, h, seed), v.clone());
    v
}

/// Synthesizes `win` of a `w × h` world and compares it with the whole
/// world's crop, bit for bit.
fn check(kind: usize, (w, h): (usize, usize), win: Rect, seed: u32) {
    let s = Synthesizer::new(db(), params(kind)).unwrap();
    let got = s.synthesize_window((w, h), win, seed).unwrap();
    assert_eq!((got.width(), got.height()), (win.width(), win.height()));
    let all = whole(kind, w, h, seed);
    for y in 0..win.height() {
        for x in 0..win.width() {
            let want = all[(win.y0 + y) * w + win.x0 + x];
            let v = got.data()[y * win.width() + x].to_bits();
            assert_eq!(
                v, want,
                "params {kind}, world {w}x{h}, window {win:?}, seed {seed}: pixel ({x}, {y}) differs"
            );
        }
    }
}

#[test]
fn corners_edges_and_the_whole_world() {
    let (w, h) = (301, 257);
    for win in [
        Rect::new(0, 0, w, h),
        Rect::new(0, 0, 1, 1),
        Rect::new(w - 1, h - 1, 1, 1),
        Rect::new(w - 37, 0, 37, 19),
        Rect::new(0, h - 5, 64, 5),
        Rect::new(128, 128, 64, 64),
        Rect::new(127, 63, 65, 129),
    ] {
        check(0, (w, h), win, 9);
    }
}

#[test]
fn every_start_and_pass_count() {
    let pyrenees = Synthesizer::new(db(), params(3)).unwrap();
    assert_eq!(pyrenees.level_passes(256, 256), [2, 2, 4]);
    for kind in 1..4 {
        for (world, win) in [
            ((256, 256), Rect::new(100, 37, 61, 90)),
            ((200, 333), Rect::new(0, 300, 200, 33)),
        ] {
            check(kind, world, win, 3);
        }
    }
}

#[test]
fn tiny_worlds_below_the_coarsest_level() {
    // Smaller than 2^L: the centre start at the world's top level, levels
    // of 2×2 (level sizes are at least 2, one more than a 1-pixel world).
    for (world, win) in [
        ((1, 1), Rect::new(0, 0, 1, 1)),
        ((3, 2), Rect::new(1, 1, 2, 1)),
        ((17, 40), Rect::new(5, 3, 7, 30)),
    ] {
        check(0, world, win, 11);
    }
}

#[test]
fn tiles_straddling_a_grid_rebuild_the_world() {
    // A 3 × 3 grid of 100 px tiles with 7 px of overlap over a 300 × 290
    // world, each tile windowed on its own.
    let (w, h) = (300, 290);
    for ty in 0..3 {
        for tx in 0..3 {
            let (x0, y0) = (
                (tx * 100usize).saturating_sub(7),
                (ty * 100usize).saturating_sub(7),
            );
            let (x1, y1) = ((tx * 100 + 107).min(w), (ty * 100 + 107).min(h));
            check(0, (w, h), Rect::new(x0, y0, x1 - x0, y1 - y0), 21);
        }
    }
}

#[test]
fn overlapping_windows_of_a_huge_world_agree() {
    // 65536² cannot be synthesized whole here; two windows far from the
    // origin (hash inputs past 2^15 at every level) that overlap must agree
    // where they do, and a window inside both must be the same again.
    let s = Synthesizer::new(db(), Params::default()).unwrap();
    let world = (65536, 65536);
    let a = s
        .synthesize_window(world, Rect::new(40_001, 50_000, 96, 80), 5)
        .unwrap();
    let b = s
        .synthesize_window(world, Rect::new(40_050, 50_031, 90, 77), 5)
        .unwrap();
    let c = s
        .synthesize_window(world, Rect::new(40_060, 50_040, 20, 20), 5)
        .unwrap();
    for y in 0..20 {
        for x in 0..20 {
            let va = a.data()[(y + 40) * 96 + x + 59].to_bits();
            let vb = b.data()[(y + 9) * 90 + x + 10].to_bits();
            let vc = c.data()[y * 20 + x].to_bits();
            assert_eq!((va, vb), (vc, vc), "({x}, {y})");
        }
    }
    let g = c.georef().expect("a window is placed in its world");
    assert_eq!(g.origin_x, 40_060.0 * s.cell_size_m());
    assert_eq!(g.origin_y, (65536.0 - 50_040.0) * s.cell_size_m());
}

#[test]
fn bad_worlds_and_windows_are_typed_errors() {
    let s = Synthesizer::new(db(), Params::default()).unwrap();
    let window = |world, win| match s.synthesize_window(world, win, 1) {
        Err(SynthError::Window(e)) => e,
        other => panic!("{world:?} {win:?}: {other:?}"),
    };
    let e = window((100, 100), Rect::new(90, 0, 11, 10));
    assert!(
        matches!(e, WindowError::Window(GridWindow { x: 90, w: 11, .. })),
        "{e}"
    );
    assert!(e.to_string().contains("inside the 100x100 world"), "{e}");
    let e = window((100, 100), Rect::new(10, 10, 0, 5));
    assert!(
        matches!(e, WindowError::Window(GridWindow { w: 0, h: 5, .. })),
        "{e}"
    );
    let e = window((100, 100), Rect::new(usize::MAX, 0, 5, 5));
    assert!(matches!(e, WindowError::Window(_)), "{e}");
    let e = window((0, 100), Rect::new(0, 0, 1, 1));
    assert!(matches!(e, WindowError::World { width: 0, .. }), "{e}");
    let e = window((1 << 21, 100), Rect::new(0, 0, 1, 1));
    assert!(e.to_string().contains("1..=1048576"), "{e}");
    // A window too large to allocate is refused before anything is.
    let big = s.synthesize_window((1 << 20, 1 << 20), Rect::new(0, 0, 1 << 20, 1 << 20), 1);
    assert!(matches!(big, Err(SynthError::Size(_))), "{big:?}");
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(16))]

    /// Random worlds (odd sizes included), windows and seeds.
    #[test]
    fn random_windows_are_crops_of_the_whole_world(
        world in (1usize..=4, 1usize..=4),
        seed in 0u32..3,
        corner in (0.0..1.0f64, 0.0..1.0f64),
        size in (0.0..1.0f64, 0.0..1.0f64),
    ) {
        // A few world sizes so the whole-world cache is reused.
        let sides = [97, 128, 255, 384];
        let (w, h) = (sides[world.0 - 1], sides[world.1 - 1]);
        let (x0, y0) = ((corner.0 * w as f64) as usize, (corner.1 * h as f64) as usize);
        let ww = 1 + (size.0 * (w - x0) as f64) as usize;
        let wh = 1 + (size.1 * (h - y0) as f64) as usize;
        check(0, (w, h), Rect::new(x0, y0, ww.min(w - x0), wh.min(h - y0)), seed);
    }
}

/// The GPU computes the same windows (crop on the device, origins in the
/// kernels' parameters).
#[cfg(feature = "gpu")]
#[test]
fn gpu_windows_match_the_cpu() {
    use crate::common::gpu;
    let Some(ctx) = gpu::context() else { return };
    let cpu = Synthesizer::new(db(), Params::default()).unwrap();
    let mut gpu = Synthesizer::new(db(), Params::default()).unwrap();
    gpu.use_gpu(ctx).unwrap();
    for (world, win) in [
        ((200, 170), Rect::new(61, 33, 77, 100)),
        ((65536, 4096), Rect::new(30_001, 1_000, 64, 48)),
    ] {
        let a = cpu.synthesize_window(world, win, 4).unwrap();
        let b = gpu.synthesize_window(world, win, 4).unwrap();
        let bits = |h: &terrasynth::Heightfield| -> Vec<u32> {
            h.data().iter().map(|v| v.to_bits()).collect()
        };
        assert!(
            bits(&a) == bits(&b),
            "{world:?} {win:?}: the GPU window differs"
        );
    }
}
