//! Stage `correct`: the scalar oracle (`correct::scalar`, the code the WGSL
//! kernel mirrors line by line), the CPU's fast path (SIMD, the level's
//! border included) and, with `--features gpu` and an adapter,
//! `kernels/correct.wgsl` give the same bytes — without control inputs on
//! random states (proptest) and on the real levels of syntheses from the
//! default database and from a database of ../shared/dem crops; under
//! control (paper §5: point/curve targets with tolerances, painted types,
//! frozen pixels, coherence weights, windows) on random guides over the
//! default database and over a typed database of two real DEM crops, and on
//! the guides a real controlled synthesis produces. And the controls do
//! what they are for.

use proptest::prelude::*;
use std::path::Path;
use terrasynth::database::c2;
use terrasynth::database::layout;
use terrasynth::io::maps::type_mask::TypeMask;
use terrasynth::isa::Isa;
use terrasynth::level::atlas::AtlasLevel;
use terrasynth::level::fixed::round;
use terrasynth::level::state::{State, level_size};
use terrasynth::stages::common::{ALL_TYPES, texel_height};
use terrasynth::stages::correct::nudge::{KEEP_DETAIL, MAX_TOL, Target};
use terrasynth::stages::correct::{
    self, Coherence, CorrectParams, DEFAULT_PRIOR, Guide, PRIORS, SUBPASSES,
};
use terrasynth::stages::reduce_types::reduce_types;
use terrasynth::stages::reduce_weights::reduce_weights;
use terrasynth::synth::control::UNCONSTRAINED;
use terrasynth::synth::{Guides, LevelGuide, Params, Synthesizer};

use crate::common::db::{RIVIERA_PYRENEES, default_db, real_syntheses, two_dems};
use crate::common::dem::DEM;
use crate::common::states::{
    copy, from_maps, patchy_parent, patchy_state, random_state, real_levels, xorshift,
};
use crate::common::variants::{assert_agree, rig};

proptest! {
    #![proptest_config(crate::common::proptest_cases(24))]

    /// States drawn anywhere in the exemplars' interiors, one subpass at
    /// one prior, with and without a parent.
    #[test]
    fn correct_agrees_on_random_states(
        w in 2usize..48, h in 2usize..48, level_pick in 0usize..8, sub in 0usize..4,
        prior in prop::sample::select(PRIORS.to_vec()), with_parent in any::<bool>(),
        similar in any::<bool>(), bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let rig = rig(default_db());
        let level = level_pick % rig.atlas.len();
        let st = random_state(&rig.atlas[level], w, h, &bits, 0);
        let rev: Vec<u32> = bits.iter().rev().copied().collect();
        let parent = random_state(&rig.atlas[level], w.div_ceil(2), h.div_ceil(2), &rev, 0);
        let (px, py) = SUBPASSES[sub];
        let p = CorrectParams { px, py, prior, similar };
        let runs = rig.correct(level, (&st, with_parent.then_some(&parent)), &p, None);
        assert_agree(&runs, &format!("random {w}x{h} level {level} prior {prior} C₂ {similar}"));
    }

    /// Coherent patches of coordinates (so candidate de-duplication is
    /// exercised), every subpass at every prior, through the guided entry
    /// points with no guide.
    #[test]
    fn correct_agrees_on_patchy_states_at_every_prior(
        level in 0usize..3,
        w in 2usize..70,
        h in 2usize..40,
        seed in any::<u64>(),
    ) {
        let rig = rig(default_db());
        let st = patchy_state(&rig.atlas[level], w, h, seed);
        let parent = patchy_parent(&rig.atlas[level], w, h, seed);
        let parent = (seed % 3 != 0).then_some(&parent);
        let what = format!("random {w}x{h} at level {level}");
        rig.correct_at_every_prior(level, (&st, parent), Some(&Guide::NONE), &what);
    }
}

/// Every subpass at the default prior on every corrected level of each
/// real synthesis, each from the same state.
/// The fast path reads C₂'s diagonal texels from `AtlasLevel::c2` (the
/// oracle from `similar` and the appearance): every texel's entry holds
/// those of its similarity entry, found here through the database's own
/// addressing, in the AVX2 scorer's order (−1,−1), (−1,1), (1,−1), (1,1).
#[test]
fn c2_table_holds_the_diagonals_of_every_similarity_entry() {
    let db = default_db();
    let mut bytes = 0;
    for i in 0..db.level_count() {
        let atlas = AtlasLevel::new(db, i);
        let level = &atlas.level;
        assert_eq!(atlas.c2.len(), level.appearance.len(), "level {i}");
        bytes += std::mem::size_of_val(atlas.c2);
        for (u, (&c, quad)) in level.similar.iter().zip(atlas.c2).enumerate() {
            let (x, y) = layout::unpack(c);
            let texel = |dx: i32, dy: i32| {
                let q = layout::pack(x.wrapping_add_signed(dx), y.wrapping_add_signed(dy));
                level.appearance[level.index_of(q).unwrap()]
            };
            let want = [texel(-1, -1), texel(-1, 1), texel(1, -1), texel(1, 1)];
            assert_eq!(quad.0, want, "level {i}, texel {u}");
        }
    }
    // What `db info` reports.
    assert_eq!(c2::table_bytes(db), bytes);
    // Built once per database: every synthesizer shares the same table.
    let (a, b) = (AtlasLevel::new(db, 0), AtlasLevel::new(db, 0));
    assert!(std::ptr::eq(a.c2, b.c2), "the table was built twice");
}

#[test]
fn correct_agrees_on_real_states() {
    for (db, size, seed) in real_syntheses("real-DEM correct cross-checks") {
        let rig = rig(db);
        let l = db.level_count() - 1;
        for r in real_levels(db, size, seed).iter().filter(|r| r.level <= l) {
            for (k, &(px, py)) in SUBPASSES.iter().enumerate() {
                for similar in [true, false] {
                    let p = CorrectParams {
                        px,
                        py,
                        prior: DEFAULT_PRIOR,
                        similar,
                    };
                    let runs = rig.correct(r.level, (&r.state, r.parent.as_ref()), &p, None);
                    let what = format!("real state, level {}, subpass {k}, C₂ {similar}", r.level);
                    assert_agree(&runs, &what);
                }
            }
        }
    }
}

/// A 203×150 synthesis' corrected levels, every subpass at every prior.
#[test]
fn correct_agrees_on_real_states_at_every_prior() {
    let rig = rig(default_db());
    let coarsest = default_db().level_count() - 1;
    let levels = real_levels(default_db(), (203, 150), 77);
    let mut checked = 0;
    for r in levels.iter().filter(|r| r.level <= coarsest) {
        let what = format!("level {}", r.level);
        let st = (&r.state, r.parent.as_ref());
        rig.correct_at_every_prior(r.level, st, Some(&Guide::NONE), &what);
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} levels checked");
}

/// Random control inputs for a w×h level: targets on about half the
/// pixels, coherence from another random state with weights 0, 1 or 4,
/// type sets on a few pixels, and a window.
#[allow(clippy::type_complexity)]
fn random_guide_inputs(
    atlas: &AtlasLevel<'_>,
    w: usize,
    h: usize,
    seed: u64,
) -> (Vec<Target>, State, Vec<u8>, Vec<u32>, [usize; 4]) {
    let mut next = xorshift(seed);
    let n = w * h;
    let targets = (0..n)
        .map(|_| {
            if next() % 2 == 0 {
                Target::NONE
            } else {
                Target {
                    height: (next() % 70_000) as i32 - 2_000,
                    tol: (next() % 5_000) as i32 | [0, KEEP_DETAIL][(next() % 2) as usize],
                }
            }
        })
        .collect();
    let prev = patchy_state(atlas, w, h, seed ^ 0x9E37_79B9);
    let weights = (0..n).map(|_| [0u8, 1, 4][(next() % 3) as usize]).collect();
    let types = atlas.seed_counts.len() as u32;
    let allowed = (0..n)
        .map(|_| {
            if next() % 5 == 0 {
                (1u32 << (next() % types as u64)) | (next() as u32 & 1) << (next() % types as u64)
            } else {
                ALL_TYPES
            }
        })
        .collect();
    let x0 = (next() % w as u64) as usize;
    let y0 = (next() % h as u64) as usize;
    let window = [
        x0,
        y0,
        x0 + 1 + (next() % w as u64) as usize,
        y0 + 1 + (next() % h as u64) as usize,
    ];
    (targets, prev, weights, allowed, window)
}

/// Cases of the two guided proptests below, each of which runs all 16
/// combinations of the guides on every case (drawn once per case, as they
/// were, 24 cases left each combination a (15/16)^24 ≈ 21 % chance never
/// to run).
const COMBINATION_CASES: u32 = 6;

proptest! {
    #![proptest_config(crate::common::proptest_cases(COMBINATION_CASES))]

    /// Geometric targets, coherence, type sets and windows over the
    /// default database — each of the 16 combinations of them on each
    /// case — every subpass at every prior.
    #[test]
    fn guided_correct_agrees_at_every_prior(
        level in 0usize..3,
        w in 2usize..70,
        h in 2usize..40,
        seed in any::<u64>(),
    ) {
        let rig = rig(default_db());
        let atlas = &rig.atlas[level];
        let st = patchy_state(atlas, w, h, seed);
        let (targets, prev, weights, allowed, window) = random_guide_inputs(atlas, w, h, seed);
        let (coords, offsets) = (prev.coords(), prev.offsets());
        let parent = patchy_parent(atlas, w, h, seed);
        for which in 0u8..16 {
            let g = Guide {
                level: level as u32,
                targets: (which & 1 != 0).then_some(&targets[..]),
                coherence: (which & 2 != 0).then_some(Coherence {
                    coords: &coords,
                    offsets: &offsets,
                    weights: &weights,
                }),
                allowed: (which & 4 != 0).then_some(&allowed[..]),
                window: (which & 8 != 0).then_some(window),
                // Windowed synthesis: type seeding hashes absolute coordinates.
                origin: [(seed as u32 % 4096) * 2, (seed >> 32) as u32 % 4096 * 2],
            };
            let what = format!("guided {which:04b} {w}x{h} at level {level}");
            rig.correct_at_every_prior(level, (&st, Some(&parent)), Some(&g), &what);
        }
    }

    /// Random states, targets (some unconstrained, tolerances 0..MAX_TOL,
    /// far-off heights), type sets (none, one or several types, empty
    /// sets forcing seeding), previous results with weights 0..=5, and
    /// windows over the typed database: every control path of the kernel.
    #[test]
    fn guided_correct_agrees_on_random_guides_of_shared_dems(
        w in 2usize..40, h in 2usize..40, level_pick in 0usize..8, sub in 0usize..4,
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let Some(db) = two_dems(RIVIERA_PYRENEES, "random-guide correct cross-checks") else {
            return Ok(());
        };
        let rig = rig(db);
        let level = level_pick % rig.atlas.len();
        let a = &rig.atlas[level];
        let st = random_state(a, w, h, &bits, 0);
        let prev = random_state(a, w, h, &bits, 0x51);
        let types = db.type_names().len() as u32;
        let b = |i: usize, k: u32| bits[(i * 3 + k as usize) % bits.len()] ^ (i as u32).wrapping_mul(0x2545_F491) ^ k;
        let targets: Vec<Target> = (0..w * h).map(|i| {
            let r = b(i, 1);
            if r % 4 == 0 { Target::NONE } else {
                let keep = [0, KEEP_DETAIL][(b(i, 5) % 2) as usize];
                Target { height: (r >> 8) as i32 % 90_000 - 10_000, tol: (b(i, 2) % (MAX_TOL as u32 + 1)) as i32 | keep }
            }
        }).collect();
        let allowed: Vec<u32> = (0..w * h).map(|i| match b(i, 3) % 5 {
            0 => ALL_TYPES,
            1 => 1 << (b(i, 4) % types.max(1)),
            2 => b(i, 4) & ((1 << types) - 1),
            3 => 0,
            _ => b(i, 4),
        }).collect();
        let weights: Vec<u8> = (0..w * h).map(|i| (b(i, 5) % 6) as u8).collect();
        let (coords, offsets) = (prev.coords(), prev.offsets());
        let (px, py) = SUBPASSES[sub];
        let parent = random_state(a, w.div_ceil(2), h.div_ceil(2), &bits, 0x5EED);
        let prior = PRIORS[bits[5] as usize % PRIORS.len()];
        let similar = bits[5] >> 16 & 1 == 1;
        let p = CorrectParams { px, py, prior, similar };
        // Targets, types, coherence (flags' bits 0–2) and a window (bit 3):
        // all 16 combinations on each case.
        for flags in 0u32..16 {
            let window = (flags & 8 != 0).then(|| {
                let (x0, y0) = (b(0, 6) as usize % w, b(0, 7) as usize % h);
                [x0, y0, x0 + 1 + b(0, 8) as usize % w, y0 + 1 + b(0, 9) as usize % h]
            });
            let g = Guide {
                level: level as u32,
                targets: (flags & 1 != 0).then_some(&targets[..]),
                allowed: (flags & 2 != 0).then_some(&allowed[..]),
                coherence: (flags & 4 != 0).then_some(Coherence { coords: &coords, offsets: &offsets, weights: &weights }),
                window,
                // Windowed synthesis: type seeding hashes absolute coordinates.
                origin: [b(0, 10) % 65536 * 2, b(0, 11) % 65536 * 2],
            };
            let runs = rig.correct(level, (&st, Some(&parent)), &p, Some(&g));
            let what = format!("random {w}×{h} level {level} flags {flags:04b} prior {prior} C₂ {similar}");
            assert_agree(&runs, &what);
        }
    }
}

/// Real guides: a two-frame controlled synthesis of the typed DEM database
/// (R⁰ from a real type mask, targets from real heights, W⁰ from the mask's
/// regions); every kept level of frame 2 is corrected (each subpass) under
/// its level's guide, with frame 1's results and without.
#[test]
fn guided_correct_agrees_on_real_guides() {
    let Some(db) = two_dems(RIVIERA_PYRENEES, "real-guide correct cross-checks") else {
        return;
    };
    let rig = rig(db);
    let (w, h) = (160, 128);
    let m = TypeMask::read(&Path::new(DEM).join("riviera_coast_types.png")).unwrap();
    let hf = terrasynth::io::read(
        &Path::new(DEM).join("riviera_coast.png"),
        &Default::default(),
    )
    .unwrap();
    let (ox, oy) = (200, 260);
    let full = ((1u64 << db.type_names().len()) - 1) as u32;
    // The coarsest level synthesis corrects.
    let l = (db.level_count() - 1).min(terrasynth::synth::coarse::MAX_START_LEVEL);
    let mut levels = Vec::new();
    let (lw, lh) = level_size(w, h, 0);
    let mut allowed: Vec<u32> = (0..lw * lh)
        .map(|k| {
            let (x, y) = (k % lw, k / lw);
            let t = m.indices[(oy + y.min(h - 1)) * m.width + ox + x.min(w - 1)];
            if t == UNCONSTRAINED || t as usize >= db.type_names().len() {
                ALL_TYPES
            } else {
                1 << t
            }
        })
        .collect();
    let mut weights: Vec<u8> = (0..lw * lh)
        .map(|k| (allowed[k].trailing_zeros() % 3) as u8 * 2)
        .collect();
    for i in 0..=l {
        let (cw, ch) = level_size(w, h, i);
        if i > 0 {
            let (pw, ph) = level_size(w, h, i - 1);
            allowed = reduce_types(&allowed, pw, ph, cw, ch, full);
            weights = reduce_weights(&weights, pw, ph, cw, ch);
        }
        let targets: Vec<Target> = (0..cw * ch)
            .map(|k| {
                let (x, y) = ((k % cw) << i, (k / cw) << i);
                let v = hf.data()[(oy + y.min(h - 1)) * hf.width() + ox + x.min(w - 1)];
                if x < w / 2 {
                    Target::NONE
                } else {
                    Target {
                        height: (v * 20.0) as i32,
                        // Curves' targets keep the winner's detail; points'
                        // do not (both kinds, the kernel's two branches).
                        tol: (y as i32 * 50).min(MAX_TOL) | [0, KEEP_DETAIL][x % 2],
                    }
                }
            })
            .collect();
        levels.push(LevelGuide {
            targets: Some(targets),
            allowed: Some(allowed.clone()),
            weights: Some(weights.clone()),
            dirty: None,
        });
    }
    let guides = Guides {
        levels,
        restrict: false,
    };
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let synth = Synthesizer::new(db, params).unwrap();
    let (_, f1) = synth.run_with(w, h, 9, &guides, None, true).unwrap();
    let f1 = f1.unwrap();
    let (out, _) = synth
        .run_with(w, h, 9, &guides, Some(f1.clone()), false)
        .unwrap();
    let mut checked = 0;
    for maps in out
        .levels
        .iter()
        .filter(|m| m.level <= l && !m.coords.is_empty())
    {
        let i = maps.level;
        let st = from_maps(maps);
        let parent = out
            .levels
            .get(i + 1)
            .filter(|m| !m.coords.is_empty())
            .map(from_maps);
        let lg = &guides.levels[i];
        let r = &f1.levels()[i][0];
        let g = Guide {
            level: i as u32,
            targets: lg.targets.as_deref(),
            allowed: lg.allowed.as_deref(),
            coherence: Some(Coherence {
                coords: &r.coords,
                offsets: &r.offsets,
                weights: lg.weights.as_deref().unwrap(),
            }),
            window: None,
            origin: [0, 0],
        };
        // With frame 1's results, and without (a first frame: every pixel
        // picks a k-coherence candidate or a seed, then is nudged).
        let first = Guide {
            coherence: None,
            ..g
        };
        for (s, &(px, py)) in SUBPASSES.iter().enumerate() {
            for (g, frame) in [(&g, 2), (&first, 1)] {
                // As the synthesizer sets it (random states try both).
                let p = CorrectParams {
                    px,
                    py,
                    prior: DEFAULT_PRIOR,
                    similar: i >= Params::default().similar_from,
                };
                let runs = rig.correct(i, (&st, parent.as_ref()), &p, Some(g));
                let what = format!("real guide, frame {frame}, level {i}, subpass {s}");
                assert_agree(&runs, &what);
            }
            checked += 1;
        }
    }
    assert!(checked >= 4 * (l + 1), "only {checked} subpasses checked");
}

/// The controls actually act: a target pulls heights, a window leaves the
/// outside alone, a frozen coherence candidate is kept as is.
#[test]
fn controls_change_the_result_as_intended() {
    let atlas = AtlasLevel::new(default_db(), 1);
    let (w, h) = (40, 30);
    let st = patchy_state(&atlas, w, h, 5);
    let p = CorrectParams {
        px: 0,
        py: 0,
        prior: DEFAULT_PRIOR,
        similar: true,
    };
    let plain = copy(&st);
    correct::correct(&atlas, &plain, None, &p, Isa::default());
    // `st` corrected with one target everywhere.
    let hold = |height: i32, tol: i32| {
        let targets = vec![Target { height, tol }; w * h];
        let held = copy(&st);
        let g = Guide {
            targets: Some(&targets),
            ..Guide::NONE
        };
        correct::correct_guided(&atlas, &held, None, &p, &g, Isa::default());
        held
    };
    // A far-away target with zero tolerance moves every corrected offset.
    let pulled = hold(200_000, 0);
    for i in (0..w * h).filter(|i| (i % w) % 2 == 0 && (i / w) % 2 == 0) {
        assert!(
            pulled.offsets()[i] > plain.offsets()[i] + 10_000,
            "pixel {i}"
        );
    }
    // With KEEP_DETAIL (a curve's target) the winner's smooth height, the
    // floor of the mean of the nine texels two apart around it, meets the
    // target and its own detail stays on top; without, its height does (a
    // point's).
    let height = |s: &State, i: usize| {
        let c = s.coords()[i];
        texel_height(atlas.appearance(round(c.x), round(c.y))) + s.offsets()[i]
    };
    let smooth = |s: &State, i: usize| {
        let c = s.coords()[i];
        let (x, y) = (round(c.x), round(c.y));
        let sum: i32 = [-2, 0, 2]
            .into_iter()
            .flat_map(|dy| [-2, 0, 2].map(|dx| (dx, dy)))
            .map(|(dx, dy)| texel_height(atlas.appearance(x + dx, y + dy)))
            .sum();
        sum.div_euclid(9) + s.offsets()[i]
    };
    let target = 20_000;
    let (exact, detailed) = (hold(target, 0), hold(target, KEEP_DETAIL));
    let corrected: Vec<usize> = (0..w * h)
        .filter(|i| (i % w) % 2 == 0 && (i / w) % 2 == 0)
        .collect();
    let mut kept = 0;
    for &i in &corrected {
        assert_eq!(height(&exact, i), target, "pixel {i}: exact");
        assert_eq!(smooth(&detailed, i), target, "pixel {i}: smooth height");
        kept += (height(&detailed, i) != target) as usize;
    }
    assert!(
        kept * 2 > corrected.len(),
        "detail kept at {kept} of {}",
        corrected.len()
    );
    // A window corrects only inside.
    let windowed = copy(&st);
    let g = Guide {
        window: Some([10, 4, 20, 12]),
        ..Guide::NONE
    };
    correct::correct_guided(&atlas, &windowed, None, &p, &g, Isa::default());
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let inside = (10..20).contains(&x) && (4..12).contains(&y);
            let want = if inside {
                plain.coords()[i]
            } else {
                st.coords()[i]
            };
            assert_eq!(windowed.coords()[i], want, "({x}, {y})");
        }
    }
    // Frozen (W = 0): the previous result comes back unchanged.
    let prev = patchy_state(&atlas, w, h, 99);
    let (coords, offsets) = (prev.coords(), prev.offsets());
    let weights = vec![0u8; w * h];
    let frozen = copy(&st);
    let g = Guide {
        coherence: Some(Coherence {
            coords: &coords,
            offsets: &offsets,
            weights: &weights,
        }),
        ..Guide::NONE
    };
    correct::correct_guided(&atlas, &frozen, None, &p, &g, Isa::default());
    for i in (0..w * h).filter(|i| (i % w) % 2 == 0 && (i / w) % 2 == 0) {
        assert_eq!(
            (frozen.coords()[i], frozen.offsets()[i]),
            (coords[i], offsets[i])
        );
    }
}
