//! Stage `correct` without control inputs: the scalar oracle
//! (`correct::scalar`, the code the WGSL kernel mirrors line by line), the
//! CPU's fast path (SIMD inside, scalar frame) and, with `--features gpu`
//! and an adapter, `kernels/correct.wgsl` give the same bytes — on random
//! states (proptest) and on the real levels of syntheses from the default
//! database and from a database of ../shared/dem crops. Under control
//! inputs: `stage_correct_guided.rs`.

use proptest::prelude::*;
use terrasynth::database::Database;
use terrasynth::stages::correct::{CorrectParams, DEFAULT_PRIOR, Guide, PRIORS, SUBPASSES};

mod common;
use common::db::{PYRENEES_JURA, default_db, two_dems};
use common::states::{patchy_parent, patchy_state, random_state, real_levels};
use common::variants::{assert_agree, rig};

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// States drawn anywhere in the exemplars' interiors, one subpass at
    /// one prior, with and without a parent.
    #[test]
    fn correct_agrees_on_random_states(
        w in 2usize..48, h in 2usize..48, level_pick in 0usize..8, sub in 0usize..4,
        prior in prop::sample::select(PRIORS.to_vec()), with_parent in any::<bool>(),
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let rig = rig(default_db());
        let level = level_pick % rig.atlas.len();
        let st = random_state(&rig.atlas[level], w, h, &bits, 0);
        let rev: Vec<u32> = bits.iter().rev().copied().collect();
        let parent = random_state(&rig.atlas[level], w.div_ceil(2), h.div_ceil(2), &rev, 0);
        let (px, py) = SUBPASSES[sub];
        let p = CorrectParams { px, py, prior };
        let runs = rig.correct(level, (&st, with_parent.then_some(&parent)), &p, None);
        assert_agree(&runs, &format!("random {w}x{h} level {level} prior {prior}"));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

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

/// Every subpass at the default prior on every corrected level of one
/// synthesis, each from the same state.
fn check_real_states(db: &'static Database, size: (usize, usize), seed: u32) {
    let rig = rig(db);
    let l = db.level_count() - 1;
    for r in real_levels(db, size, seed).iter().filter(|r| r.level <= l) {
        for (k, &(px, py)) in SUBPASSES.iter().enumerate() {
            let p = CorrectParams {
                px,
                py,
                prior: DEFAULT_PRIOR,
            };
            let runs = rig.correct(r.level, (&r.state, r.parent.as_ref()), &p, None);
            let what = format!("real state, level {}, subpass {k}", r.level);
            assert_agree(&runs, &what);
        }
    }
}

#[test]
fn correct_agrees_on_real_states_of_the_default_database() {
    check_real_states(default_db(), (256, 192), 3);
}

#[test]
fn correct_agrees_on_real_states_of_shared_dems() {
    if let Some(db) = two_dems(PYRENEES_JURA, "real-DEM correct cross-checks") {
        check_real_states(db, (200, 256), 11);
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
