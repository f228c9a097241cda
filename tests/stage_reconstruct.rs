//! Stage `reconstruct`: the CPU stage and, with `--features gpu` and an
//! adapter, `kernels/reconstruct.wgsl` give the same fixed-point heights —
//! on random level-0 states (proptest) and on the level 0 of syntheses from
//! the default database and from a database of ../shared/dem crops.
//! Without a GPU there is nothing to compare against: every test says so
//! and passes.

use proptest::prelude::*;

mod common;
use common::db::{default_db, real_syntheses};
use common::states::{random_state, real_levels};
use common::variants::{assert_agree, gpu_or_skip, rig};

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn reconstruct_agrees_on_random_states(
        w in 2usize..64, h in 2usize..64,
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        if !gpu_or_skip("reconstruct") {
            return Ok(());
        }
        let rig = rig(default_db());
        let st = random_state(&rig.atlas[0], w, h, &bits, 0);
        assert_agree(&rig.reconstruct(&st), "reconstruct");
    }
}

/// Level 0 of each real synthesis.
#[test]
fn reconstruct_agrees_on_real_states() {
    if !gpu_or_skip("reconstruct") {
        return;
    }
    for (db, size, seed) in real_syntheses("real-DEM reconstruct cross-checks") {
        let levels = real_levels(db, size, seed);
        let level0 = levels.iter().find(|r| r.level == 0).expect("level 0 kept");
        assert_agree(&rig(db).reconstruct(&level0.state), "reconstruct (real)");
    }
}
