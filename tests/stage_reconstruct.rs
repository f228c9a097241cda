//! Stage `reconstruct`: the CPU stage and, with `--features gpu` and an
//! adapter, `kernels/reconstruct.wgsl` give the same fixed-point heights —
//! on random level-0 states (proptest) and on the level 0 of syntheses from
//! the default database and from a database of ../shared/dem crops.
//! Without a GPU there is nothing to compare against: every test says so
//! and passes. The CPU stage over a rectangle (an edit's re-synthesis) is
//! checked against the whole level's on the CPU alone.

use proptest::prelude::*;
use terrasynth::stages::reconstruct::{reconstruct, reconstruct_rect};

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

    #[test]
    fn reconstruct_rect_is_the_whole_level_inside_and_keeps_the_rest(
        w in 2usize..64, h in 2usize..64, r in prop::array::uniform4(0usize..70),
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let rig = rig(default_db());
        let st = random_state(&rig.atlas[0], w, h, &bits, 0);
        let whole = reconstruct(&rig.atlas[0], rig.heights, &st);
        let rect = [r[0].min(r[1]), r[2].min(r[3]), r[0].max(r[1]), r[2].max(r[3])];
        let mut out = vec![i32::MIN; w * h];
        reconstruct_rect(&rig.atlas[0], rig.heights, &st, &mut out, rect);
        for (k, (o, e)) in out.iter().zip(&whole).enumerate() {
            let (x, y) = (k % w, k / w);
            let inside = (rect[0]..rect[2]).contains(&x) && (rect[1]..rect[3]).contains(&y);
            prop_assert_eq!(*o, if inside { *e } else { i32::MIN }, "pixel ({}, {})", x, y);
        }
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
