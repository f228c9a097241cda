//! Stage `reduce_types`: the CPU stage and, with `--features gpu` and an
//! adapter, `kernels/reduce_types.wgsl` give the same type-set pyramids —
//! on random rasters (proptest, odd and even sizes, every value a u32 can
//! hold) and on the type masks of every ../shared/dem DEM, reduced to the
//! top of the pyramid as a session does; mis-sized rasters are a typed
//! error on every backend. Without a GPU the cross-checks say so and pass.

use proptest::prelude::*;
use std::path::Path;
use terrasynth::backend::{Backend, cpu::Cpu};
use terrasynth::io::type_mask::TypeMask;
use terrasynth::stages::correct::ALL_TYPES;
use terrasynth::synth::control::UNCONSTRAINED;

mod common;
use common::db::default_db;
use common::dem::{DEM, typed_stems};
use common::variants::{assert_agree, assert_mis_sized, gpu_or_skip, rig};

/// Every level of the pyramid of `r0` must agree; returns how many levels
/// were compared.
fn check(r0: &[u32], size: (usize, usize), full: u32, what: &str) -> usize {
    let levels = rig(default_db()).reduce_types(r0, size, full);
    for (k, runs) in levels.iter().enumerate() {
        assert_agree(runs, &format!("{what}: reduce_types to level {}", k + 1));
    }
    levels.len()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// Sets drawn so that every branch is hit: ALL_TYPES, `full` itself,
    /// supersets of `full`, single types, empty sets and arbitrary words.
    #[test]
    fn reduce_types_agrees_on_random_rasters(
        w in 1usize..70, h in 1usize..70, types in 1u32..=32,
        picks in prop::collection::vec((0u32..6, any::<u32>()), 1..128),
    ) {
        if !gpu_or_skip("reduce_types") {
            return Ok(());
        }
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
        check(&r0, (w, h), full, &format!("random {w}×{h}, {types} types"));
    }
}

/// A type-set raster whose length is not width × height is a typed error
/// on every backend, never an out-of-bounds read.
#[test]
fn mis_sized_type_rasters_are_rejected() {
    // The CPU backend reads no database for this: bind none.
    let cpu = Cpu {
        atlas: &[],
        heights: &[],
    };
    assert_mis_sized(cpu.upload_types(&[0; 5], 2, 3).map(|_| ()));
    #[cfg(feature = "gpu")]
    if let Some(gpu) = &rig(default_db()).gpu {
        assert_mis_sized(gpu.upload_types(&[0; 5], 2, 3).map(|_| ()));
    }
}

/// The type mask of every shared DEM as a session paints it (R⁰ = one type
/// per pixel, unconstrained where the mask has none), reduced to the top
/// of the pyramid.
#[test]
fn reduce_types_agrees_on_shared_dem_type_masks() {
    if !gpu_or_skip("reduce_types") {
        return;
    }
    let Some(stems) = typed_stems("real-mask reduce_types cross-check") else {
        return;
    };
    for stem in &stems {
        let m = TypeMask::read(&Path::new(DEM).join(format!("{stem}_types.png"))).unwrap();
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
        let levels = check(&r0, (m.width, m.height), full, stem);
        assert!(levels >= 6, "{stem}: only {levels} levels");
    }
    assert!(stems.len() >= 4, "only {} type masks in {DEM}", stems.len());
}
