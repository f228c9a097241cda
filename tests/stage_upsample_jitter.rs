//! Stage `upsample_jitter`: the CPU stage and, with `--features gpu` and an
//! adapter, `kernels/upsample_jitter.wgsl` give the same bytes — on random
//! parents (proptest: pyramid, virtual and wrapping steps) and on the real
//! levels of syntheses from the default database and from a database of
//! ../shared/dem crops. Without a GPU there is nothing to compare against:
//! every test says so and passes. The CPU stage over a rectangle (an
//! edit's re-synthesis) is checked against the whole level's on the CPU
//! alone.

use proptest::prelude::*;
use terrasynth::database::layout::MARGIN;
use terrasynth::level::state::State;
use terrasynth::level::state::level_size;
use terrasynth::stages::upsample_jitter::{
    Step, UpsampleParams, upsample_jitter, upsample_jitter_rect,
};

mod common;
use common::db::{default_db, real_syntheses};
use common::states::{random_state, real_levels};
use common::variants::{assert_agree, gpu_or_skip, rig};

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn upsample_jitter_agrees_on_random_states(
        w in 2usize..40, h in 2usize..40, level_pick in 0usize..8, seed in any::<u32>(),
        jitter in 0i32..=1024, shift in 1u32..4, kind in 0u32..3,
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        if !gpu_or_skip("upsample_jitter") {
            return Ok(());
        }
        let rig = rig(default_db());
        let l = rig.atlas.len() - 1;
        let (cw, ch) = (2 * w - (bits[0] & 1) as usize, 2 * h - (bits[1] & 1) as usize);
        let (level, step, parent_level) = match kind {
            0 => {
                let level = level_pick % l;
                (level, Step::Pyramid, level + 1)
            }
            1 => (l + shift as usize, Step::Virtual { shift }, l),
            _ => {
                let r = rig.atlas[l].level.layout.rects[0];
                let step = Step::Wrap {
                    min_x: (r.x0 + MARGIN) as i32,
                    max_x: (r.x0 + r.width - 1 - MARGIN) as i32,
                    min_y: MARGIN as i32,
                    max_y: (r.height - 1 - MARGIN) as i32,
                };
                (l, step, l)
            }
        };
        let parent = random_state(&rig.atlas[parent_level], w, h, &bits, 0);
        // Windowed synthesis: the jitter hashes absolute (even-cornered)
        // coordinates.
        let origin = [bits[1] % 65536 * 2, bits[2] % 65536 * 2];
        let p = UpsampleParams { seed, level: level as u32, jitter, step, origin };
        let runs = rig.upsample_jitter(&parent, (cw.max(2), ch.max(2)), level, &p);
        assert_agree(&runs, &format!("upsample_jitter to level {level} ({step:?})"));
    }

    #[test]
    fn upsample_jitter_rect_is_the_whole_level_inside_and_keeps_the_rest(
        w in 2usize..40, h in 2usize..40, r in prop::array::uniform4(0usize..84),
        seed in any::<u32>(), bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let rig = rig(default_db());
        let level = 0;
        let parent = random_state(&rig.atlas[level + 1], w, h, &bits, 0);
        let p = UpsampleParams { seed, level: 0, jitter: 102, step: Step::Pyramid, origin: [0, 0] };
        let (cw, ch) = (2 * w, 2 * h);
        let (whole, part) = (State::new(cw, ch), State::new(cw, ch));
        upsample_jitter(&parent, &whole, Some(&rig.atlas[level]), &p);
        let rect = [r[0].min(r[1]), r[2].min(r[3]), r[0].max(r[1]), r[2].max(r[3])];
        upsample_jitter_rect(&parent, &part, Some(&rig.atlas[level]), &p, rect);
        let untouched = State::new(1, 1);
        for k in 0..cw * ch {
            let (x, y) = (k % cw, k / cw);
            let inside = (rect[0]..rect[2]).contains(&x) && (rect[1]..rect[3]).contains(&y);
            let want = if inside { (whole.s(k), whole.v(k)) } else { (untouched.s(0), untouched.v(0)) };
            prop_assert_eq!((part.s(k), part.v(k)), want, "pixel ({}, {})", x, y);
        }
    }
}

/// Every kept level of each real synthesis at or below the database's
/// coarsest (and above level 0) upsampled into the level below it.
#[test]
fn upsample_jitter_agrees_on_real_states() {
    if !gpu_or_skip("upsample_jitter") {
        return;
    }
    for (db, (w, h), seed) in real_syntheses("real-DEM upsample_jitter cross-checks") {
        let rig = rig(db);
        let l = db.level_count() - 1;
        for r in real_levels(db, (w, h), seed) {
            if r.level >= 1 && r.level <= l {
                let level = r.level - 1;
                let p = UpsampleParams {
                    seed,
                    level: level as u32,
                    jitter: 102,
                    step: Step::Pyramid,
                    origin: [0, 0],
                };
                let runs = rig.upsample_jitter(&r.state, level_size(w, h, level), level, &p);
                assert_agree(&runs, &format!("upsample_jitter to level {level} (real)"));
            }
        }
    }
}
