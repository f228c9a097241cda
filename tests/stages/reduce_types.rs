//! Stage `reduce_types` against an oracle written here from the stage's
//! documented rule (paper §5.2, the module docs of
//! `src/stages/reduce_types.rs`; none of the stage's code): the CPU stage
//! and, with `--features gpu` and an adapter, `kernels/reduce_types.wgsl`
//! give the oracle's type-set pyramids — on random rasters (proptest, odd
//! and even sizes, every value a u32 can hold), on every 2×2 block of
//! the sets that matter, and on the type masks of every ../shared/dem DEM,
//! reduced to the top of the pyramid as a session does; mis-sized rasters
//! are a typed error on every backend.

use proptest::prelude::*;
use std::path::Path;
use terrasynth::backend::{Backend, cpu::Cpu};
use terrasynth::io::maps::type_mask::TypeMask;
use terrasynth::level::state::level_size;
use terrasynth::stages::common::ALL_TYPES;
use terrasynth::synth::control::UNCONSTRAINED;

use crate::common::db::default_db;
use crate::common::dem::{DEM, typed_stems};
use crate::common::variants::{assert_agree, assert_mis_sized, rig};

/// One level up (`w × h`) by the rule, as sets: a pixel's set is the union
/// of the sets of its children (the 2×2 block at 2p, less those past the
/// child level's edge) that constrain anything — a child whose set holds
/// every type of the database (`full`, ALL_TYPES or more) does not — and
/// is ALL_TYPES (unconstrained) when that union is empty.
fn oracle_level(
    child: &[u32],
    (cw, ch): (usize, usize),
    (w, h): (usize, usize),
    full: u32,
) -> Vec<u32> {
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let block = [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| (2 * x + dx, 2 * y + dy));
            let constraining = block
                .iter()
                .filter(|&&(cx, cy)| cx < cw && cy < ch)
                .map(|&(cx, cy)| child[cy * cw + cx])
                .filter(|&set| set != ALL_TYPES && set & full != full);
            let union = constraining.fold(0, |u, set| u | set);
            out.push(if union == 0 { ALL_TYPES } else { union });
        }
    }
    out
}

/// Every level of the pyramid of `r0` must equal the oracle's, on every
/// variant; returns how many levels were compared.
fn check(r0: &[u32], size: (usize, usize), full: u32, what: &str) -> usize {
    let levels = rig(default_db()).reduce_types(r0, size, full);
    let (mut below, mut at) = (r0.to_vec(), size);
    for (k, runs) in levels.iter().enumerate() {
        let up = level_size(size.0, size.1, k + 1);
        below = oracle_level(&below, at, up, full);
        at = up;
        let mut runs = runs.clone();
        runs.insert(0, ("oracle", below.clone()));
        assert_agree(&runs, &format!("{what}: reduce_types to level {}", k + 1));
    }
    levels.len()
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(32))]

    /// Sets drawn so that every branch is hit: ALL_TYPES, `full` itself,
    /// supersets of `full`, single types, empty sets and arbitrary words.
    #[test]
    fn reduce_types_agrees_on_random_rasters(
        w in 1usize..70, h in 1usize..70, types in 1u32..=32,
        picks in prop::collection::vec((0u32..6, any::<u32>()), 1..128),
    ) {
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

/// Every 2×2 block of seven sets — unconstrained (ALL_TYPES), every type
/// (`full`), more than every type, empty, one type, another, two types —
/// side by side in one 2-row raster: each of the 2 401 blocks is one
/// pixel of level 1, so each case of the rule is met, deterministically.
#[test]
fn reduce_types_follows_the_rule_on_every_block_of_the_sets_that_matter() {
    let full = 0b111;
    let sets = [ALL_TYPES, full, full | 1 << 9, 0, 0b001, 0b100, 0b011];
    let n = sets.len().pow(4);
    let (w, h) = (2 * n, 2);
    let mut r0 = vec![0; w * h];
    for b in 0..n {
        for (c, (dx, dy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
            r0[dy * w + 2 * b + dx] = sets[b / sets.len().pow(c as u32) % sets.len()];
        }
    }
    check(&r0, (w, h), full, "every block");
}

/// A type-set raster whose length is not width × height is a typed error
/// on every backend, never an out-of-bounds read.
#[test]
fn mis_sized_type_rasters_are_rejected() {
    // The CPU backend reads no database for this: bind none.
    let cpu = Cpu::new(&[], &[]);
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
