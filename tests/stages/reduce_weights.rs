//! Stage `reduce_weights`: the CPU stage and, with `--features gpu` and an
//! adapter, `kernels/reduce_weights.wgsl` give the same coherence-weight
//! pyramids — on random rasters (proptest, odd and even sizes, every value
//! a u8 can hold) and on weights drawn from the type masks of every
//! ../shared/dem DEM, reduced to the top of the pyramid as a session does;
//! mis-sized rasters are a typed error on every backend. Without a GPU the
//! cross-checks say so and pass.

use proptest::prelude::*;
use std::path::Path;
use terrasynth::backend::{Backend, cpu::Cpu};
use terrasynth::io::maps::type_mask::TypeMask;
use terrasynth::stages::correct::W_FREE;

use crate::common::db::default_db;
use crate::common::dem::{DEM, typed_stems};
use crate::common::variants::{assert_agree, assert_mis_sized, gpu_or_skip, rig};

/// Every level of the pyramid of `w0` must agree; returns how many levels
/// were compared.
fn check(w0: &[u8], size: (usize, usize), what: &str) -> usize {
    let levels = rig(default_db()).reduce_weights(w0, size);
    for (k, runs) in levels.iter().enumerate() {
        assert_agree(runs, &format!("{what}: reduce_weights to level {}", k + 1));
    }
    levels.len()
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(32))]

    /// Weights over 0..=6 (values above 4 clamp) and any byte, with ties of
    /// every kind among the 2×2 children.
    #[test]
    fn reduce_weights_agrees_on_random_rasters(
        w in 1usize..70, h in 1usize..70, wide in any::<bool>(),
        picks in prop::collection::vec(any::<u8>(), 1..128),
    ) {
        if !gpu_or_skip("reduce_weights") {
            return Ok(());
        }
        let w0: Vec<u8> = (0..w * h)
            .map(|i| {
                let b = picks[(i * 5 + i / w) % picks.len()] ^ (i as u8).wrapping_mul(37);
                if wide { b } else { b % 7 }
            })
            .collect();
        check(&w0, (w, h), &format!("random {w}×{h}"));
    }
}

/// A weight raster whose length is not width × height is a typed error on
/// every backend, never an out-of-bounds read.
#[test]
fn mis_sized_weight_rasters_are_rejected() {
    // The CPU backend reads no database for this: bind none.
    let cpu = Cpu::new(&[], &[]);
    assert_mis_sized(cpu.upload_weights(&[0; 5], 2, 3).map(|_| ()));
    #[cfg(feature = "gpu")]
    if let Some(gpu) = &rig(default_db()).gpu {
        assert_mis_sized(gpu.upload_weights(&[0; 5], 2, 3).map(|_| ()));
    }
}

/// A W⁰ drawn from the regions of every shared DEM's type mask (type 0
/// frozen, type 1 free, the rest coherent), reduced to the top of the
/// pyramid.
#[test]
fn reduce_weights_agrees_on_shared_dem_type_masks() {
    if !gpu_or_skip("reduce_weights") {
        return;
    }
    let Some(stems) = typed_stems("real-mask reduce_weights cross-check") else {
        return;
    };
    for stem in &stems {
        let m = TypeMask::read(&Path::new(DEM).join(format!("{stem}_types.png"))).unwrap();
        let w0: Vec<u8> = m
            .indices
            .iter()
            .map(|&t| match t {
                0 => 0,
                1 => W_FREE,
                _ => 1,
            })
            .collect();
        let levels = check(&w0, (m.width, m.height), stem);
        assert!(levels >= 6, "{stem}: only {levels} levels");
    }
    assert!(stems.len() >= 4, "only {} type masks in {DEM}", stems.len());
}
