//! CPU ≡ GPU, byte for byte, for the control pyramids (DESIGN §6): stages
//! `reduce_types` and `reduce_weights` on random rasters (proptest, odd and
//! even sizes, every value a u8/u32 can hold) and on real ones (the type
//! masks of every ../shared/dem DEM, reduced to the top of the pyramid as a
//! session does), and a scene's editing session end to end. The guided
//! `correct` stage has its own file, `backend_guided.rs`.
//!
//! Needs `--features gpu` and a Vulkan adapter (lavapipe will do: Debian
//! package `mesa-vulkan-drivers`); without one every test prints why and
//! passes without checking anything.
#![cfg(feature = "gpu")]

use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;
use terrasynth::backend::gpu::Gpu;
use terrasynth::backend::{Backend, BackendError, cpu::Cpu};
use terrasynth::database::{Database, default};
use terrasynth::io::type_mask::TypeMask;
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::control::UNCONSTRAINED;
use terrasynth::synth::stages::correct::{ALL_TYPES, W_FREE};
use terrasynth::synth::state::{level_size, top_level};

mod common;
use common::dem::DEM;

/// Both backends over the default database (the reductions read none of
/// it, but a backend is bound to one).
struct Pair {
    atlas: Vec<AtlasLevel<'static>>,
    heights: &'static [u16],
    gpu: Gpu,
}

impl Pair {
    fn cpu(&self) -> Cpu<'_, 'static> {
        Cpu {
            atlas: &self.atlas,
            heights: self.heights,
        }
    }
}

/// The default database, built once.
static DB_DEFAULT: OnceLock<Database> = OnceLock::new();

/// The shared pair, or `None` without an adapter (see `common::gpu`).
fn pair() -> Option<&'static Pair> {
    static PAIR: OnceLock<Option<Pair>> = OnceLock::new();
    PAIR.get_or_init(|| {
        let ctx = common::gpu::context()?;
        let db = DB_DEFAULT.get_or_init(|| default::build_default(&Silent).unwrap());
        let atlas: Vec<_> = (0..db.level_count())
            .map(|i| AtlasLevel::new(db, i))
            .collect();
        let gpu = Gpu::new(ctx, &atlas, db.heights()).unwrap();
        Some(Pair {
            atlas,
            heights: db.heights(),
            gpu,
        })
    })
    .as_ref()
}

/// Reduces `r0` (`w × h`) level by level on both backends, with the level
/// sizes of a synthesis (`level_size`, at least 2 × 2, so the top levels
/// have pixels without children) one past its top, the GPU's rasters staying
/// on the device; every level must match. Returns how many levels were
/// compared.
fn check_types(pair: &Pair, r0: &[u32], (w, h): (usize, usize), full: u32, what: &str) -> usize {
    let cpu = pair.cpu();
    let mut c = cpu.upload_types(r0, w, h).unwrap();
    let mut g = pair.gpu.upload_types(r0, w, h).unwrap();
    assert_eq!(pair.gpu.download_types(&g).unwrap(), r0, "{what}: upload");
    let top = top_level(w, h) + 1;
    for level in 1..=top {
        let (lw, lh) = level_size(w, h, level);
        c = cpu.reduce_types(&c, lw, lh, full).unwrap();
        g = pair.gpu.reduce_types(&g, lw, lh, full).unwrap();
        let gd = pair.gpu.download_types(&g).unwrap();
        if let Some(i) = (0..c.data.len()).find(|&i| gd[i] != c.data[i]) {
            panic!(
                "{what}: reduce_types to level {level} ({lw}×{lh}): pixel {i}: GPU {:#x} vs CPU {:#x}",
                gd[i], c.data[i]
            );
        }
        assert_eq!(gd, c.data, "{what}: level {level}");
    }
    top
}

/// [`check_types`] for coherence weights.
fn check_weights(pair: &Pair, w0: &[u8], (w, h): (usize, usize), what: &str) -> usize {
    let cpu = pair.cpu();
    let mut c = cpu.upload_weights(w0, w, h).unwrap();
    let mut g = pair.gpu.upload_weights(w0, w, h).unwrap();
    assert_eq!(pair.gpu.download_weights(&g).unwrap(), w0, "{what}: upload");
    let top = top_level(w, h) + 1;
    for level in 1..=top {
        let (lw, lh) = level_size(w, h, level);
        c = cpu.reduce_weights(&c, lw, lh).unwrap();
        g = pair.gpu.reduce_weights(&g, lw, lh).unwrap();
        let gd = pair.gpu.download_weights(&g).unwrap();
        if let Some(i) = (0..c.data.len()).find(|&i| gd[i] != c.data[i]) {
            panic!(
                "{what}: reduce_weights to level {level} ({lw}×{lh}): pixel {i}: GPU {} vs CPU {}",
                gd[i], c.data[i]
            );
        }
        assert_eq!(gd, c.data, "{what}: level {level}");
    }
    top
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// Sets drawn so that every branch is hit: ALL_TYPES, `full` itself,
    /// supersets of `full`, single types, empty sets and arbitrary words.
    #[test]
    fn reduce_types_matches_on_random_rasters(
        w in 1usize..70, h in 1usize..70, types in 1u32..=32,
        picks in prop::collection::vec((0u32..6, any::<u32>()), 1..128),
    ) {
        let Some(pair) = pair() else { return Ok(()) };
        let full = if types == 32 { u32::MAX } else { (1u32 << types) - 1 };
        let r0: Vec<u32> = (0..w * h)
            .map(|i| {
                let (kind, bits) = picks[(i * 7 + i / w) % picks.len()];
                let bits = bits ^ (i as u32).wrapping_mul(0x9E37_79B9);
                match kind {
                    0 => ALL_TYPES,
                    1 => full,
                    2 => full | bits,
                    3 => 1 << (bits % types),
                    4 => 0,
                    _ => bits,
                }
            })
            .collect();
        check_types(pair, &r0, (w, h), full, &format!("random {w}×{h}, {types} types"));
    }

    /// Weights over 0..=6 (values above 4 clamp) and any byte, with ties of
    /// every kind among the 2×2 children.
    #[test]
    fn reduce_weights_matches_on_random_rasters(
        w in 1usize..70, h in 1usize..70, wide in any::<bool>(),
        picks in prop::collection::vec(any::<u8>(), 1..128),
    ) {
        let Some(pair) = pair() else { return Ok(()) };
        let w0: Vec<u8> = (0..w * h)
            .map(|i| {
                let b = picks[(i * 5 + i / w) % picks.len()] ^ (i as u8).wrapping_mul(37);
                if wide { b } else { b % 7 }
            })
            .collect();
        check_weights(pair, &w0, (w, h), &format!("random {w}×{h}"));
    }
}

/// Raster lengths that are not width × height are a typed error on both
/// backends, never an out-of-bounds read.
#[test]
fn mis_sized_rasters_are_rejected() {
    let Some(pair) = pair() else { return };
    let cpu = pair.cpu();
    let bad = |r: Result<(), BackendError>| {
        assert!(
            matches!(
                r,
                Err(BackendError::RasterSize {
                    len: 5,
                    width: 2,
                    height: 3,
                    ..
                })
            ),
            "{r:?}"
        )
    };
    bad(cpu.upload_types(&[0; 5], 2, 3).map(|_| ()));
    bad(pair.gpu.upload_types(&[0; 5], 2, 3).map(|_| ()));
    bad(cpu.upload_weights(&[0; 5], 2, 3).map(|_| ()));
    bad(pair.gpu.upload_weights(&[0; 5], 2, 3).map(|_| ()));
}

/// The type mask of every shared DEM as a session paints it (R⁰ = one type
/// per pixel, unconstrained where the mask has none), and a W⁰ drawn from
/// the same regions (type 0 frozen, type 1 free, the rest coherent), both
/// reduced to the top of the pyramid on both backends.
#[test]
fn reductions_match_on_shared_dem_type_masks() {
    let Some(pair) = pair() else { return };
    let dir = Path::new(DEM);
    if !dir.exists() {
        eprintln!("{DEM} not found: real-mask reduction cross-check skipped");
        return;
    }
    let mut used = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if !name.ends_with("_types.png") {
            continue;
        }
        let m = TypeMask::read(&path).unwrap();
        let types = m.indices.iter().filter(|&&t| t != UNCONSTRAINED).max();
        let count = types.map_or(1, |&t| t as u32 + 1).min(32);
        let full = if count == 32 {
            u32::MAX
        } else {
            (1 << count) - 1
        };
        let r0: Vec<u32> = m
            .indices
            .iter()
            .map(|&t| {
                if t == UNCONSTRAINED || t >= 32 {
                    ALL_TYPES
                } else {
                    1 << t
                }
            })
            .collect();
        let w0: Vec<u8> = m
            .indices
            .iter()
            .map(|&t| match t {
                0 => 0,
                1 => W_FREE,
                _ => 1,
            })
            .collect();
        let size = (m.width, m.height);
        let levels = check_types(pair, &r0, size, full, &name);
        assert_eq!(check_weights(pair, &w0, size, &name), levels);
        assert!(levels >= 6, "{name}: only {levels} levels");
        used += 1;
    }
    assert!(used >= 4, "only {used} type masks in {DEM}");
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
    let Some(pair) = pair() else { return };
    let db = DB_DEFAULT.get_or_init(|| default::build_default(&Silent).unwrap());
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes");
    let scenes: Vec<Scene> = ["canyonlands.json", "canyonlands_edit1.json"]
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
            session
                .synthesizer_mut()
                .use_gpu(pair.gpu.context().clone())
                .unwrap();
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
        for (level, (cl, gl)) in cf.levels.iter().zip(&gf.levels).enumerate() {
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
