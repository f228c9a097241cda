//! CPU ≡ GPU, byte for byte, for the control pyramids (DESIGN §6): stages
//! `reduce_types` and `reduce_weights` on random rasters (proptest, odd and
//! even sizes, every value a u8/u32 can hold) and on real ones (the type
//! masks of every ../shared/dem DEM, reduced to the top of the pyramid as a
//! session does).
//!
//! Needs `--features gpu` and a Vulkan adapter (lavapipe will do: Debian
//! package `mesa-vulkan-drivers`); without one every test prints why and
//! passes without checking anything.
#![cfg(feature = "gpu")]

use proptest::prelude::*;
use std::path::Path;
use std::sync::{Arc, OnceLock};
use terrasynth::backend::gpu::{Context, Gpu};
use terrasynth::backend::{Backend, BackendError, cpu::Cpu};
use terrasynth::database::{Database, default};
use terrasynth::io::type_mask::TypeMask;
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::control::UNCONSTRAINED;
use terrasynth::synth::stages::correct::{ALL_TYPES, W_FREE};
use terrasynth::synth::state::{level_size, top_level};

const DEM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/dem");

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

/// The shared pair, or `None` (with the reason printed) without an adapter.
fn pair() -> Option<&'static Pair> {
    static PAIR: OnceLock<Result<Pair, String>> = OnceLock::new();
    static DB: OnceLock<Database> = OnceLock::new();
    let r = PAIR.get_or_init(|| {
        let ctx: Arc<Context> = Context::new().map_err(|e| e.to_string())?;
        let db = DB.get_or_init(|| default::build_default(&Silent).unwrap());
        let atlas: Vec<_> = (0..db.level_count())
            .map(|i| AtlasLevel::new(db, i))
            .collect();
        let gpu = Gpu::new(ctx, &atlas, db.heights()).map_err(|e| e.to_string())?;
        Ok(Pair {
            atlas,
            heights: db.heights(),
            gpu,
        })
    });
    match r {
        Ok(p) => Some(p),
        Err(e) => {
            eprintln!("skipping the GPU cross-check: {e}");
            None
        }
    }
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
