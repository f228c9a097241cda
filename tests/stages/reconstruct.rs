//! Stages `reconstruct` and `repair_extrema`: the CPU stages (fused, row
//! block by row block) give the heights of the documented rule computed
//! pixel by pixel from coordinates ([`oracle`]), and, with `--features gpu`
//! and an adapter, `kernels/reconstruct.wgsl` + `kernels/repair_extrema.wgsl`
//! give the same fixed-point heights — on random level-0 states (proptest:
//! every pixel a join, so extrema of every support are repaired) and on the
//! level 0 of syntheses from the default database and from a database of
//! ../shared/dem crops. Without a GPU the cross-checks say so and pass. The
//! CPU stage over a rectangle (an edit's re-synthesis) is checked against
//! the whole level's.

use proptest::prelude::*;
use terrasynth::database::appearance::{MODE1_BIAS, unpack_texel};
use terrasynth::level::atlas::AtlasLevel;
use terrasynth::level::fixed::round;
use terrasynth::level::state::State;
use terrasynth::stages::reconstruct::{reconstruct, reconstruct_rect};
use terrasynth::stages::repair_extrema::{DIMPLE_SUPPORT, SUPPORT};

use crate::common::db::{default_db, real_syntheses};
use crate::common::states::{random_state, real_levels};
use crate::common::variants::{assert_agree, gpu_or_skip, rig};

/// The rule of `stages::reconstruct` and `stages::repair_extrema`, pixel by
/// pixel from coordinates, in i64: the blend b (the mean of the neighbours'
/// smooth predictions plus the pixel's own texel detail), then each
/// interior pixel strictly below (above) its eight neighbours' blends
/// judged by its texel's support in the exemplar: on a hollow's floor (a
/// rise's top) it stays, no deeper than half the texel's least rise.
fn oracle(atlas: &AtlasLevel<'_>, heights: &[u16], st: &State) -> Vec<i32> {
    let (w, h) = (st.width as i64, st.height as i64);
    let at = |x: i64, y: i64| (y * w + x) as usize;
    let texel = |x: i64, y: i64| {
        let s = st.s(at(x, y));
        (round(s.x), round(s.y))
    };
    let e = |(x, y): (i32, i32)| heights[atlas.index(x, y)] as i64;
    let mu =
        |(x, y): (i32, i32)| unpack_texel(atlas.appearance(x, y))[0] as i64 - MODE1_BIAS as i64;
    let v = |x: i64, y: i64| st.v(at(x, y)) as i64;
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && x < w && y < h;
    let deltas = || (-1..=1i64).flat_map(|dy| (-1..=1i64).map(move |dx| (dx, dy)));
    let mut b = vec![0i64; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let (mut sum, mut count) = (0, 0);
            for (dx, dy) in deltas().filter(|&(dx, dy)| inside(x + dx, y + dy)) {
                let (tx, ty) = texel(x + dx, y + dy);
                sum += mu((tx - dx as i32, ty - dy as i32)) + v(x + dx, y + dy);
                count += 1;
            }
            let t = texel(x, y);
            b[at(x, y)] = (sum * 256).div_euclid(count) + (e(t) - mu(t)) * 256;
        }
    }
    let mut out = b.clone();
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let c = b[at(x, y)];
            let ring: Vec<i64> = deltas()
                .filter(|&d| d != (0, 0))
                .map(|(dx, dy)| b[at(x + dx, y + dy)])
                .collect();
            let (lo, hi) = (*ring.iter().min().unwrap(), *ring.iter().max().unwrap());
            if c >= lo && c <= hi {
                continue;
            }
            let pit = c < lo;
            let t = texel(x, y);
            // The texel's rises to its supporting neighbours (higher ones
            // for a pit, lower ones for a peak), in metres of the exemplar.
            let rises: Vec<i64> = deltas()
                .filter(|&d| d != (0, 0))
                .map(|(dx, dy)| e((t.0 + dx as i32, t.1 + dy as i32)) - e(t))
                .filter(|&r| if pit { r > 0 } else { r < 0 })
                .map(i64::abs)
                .collect();
            let support = rises.len() as u32;
            // Half the least rise, ×2^8.
            let bound = rises.iter().min().map_or(0, |&r| r * 128);
            out[at(x, y)] = if support == 8 {
                c
            } else if support >= DIMPLE_SUPPORT {
                if pit {
                    c.max(lo - bound)
                } else {
                    c.min(hi + bound)
                }
            } else if support >= SUPPORT {
                let sum: i64 = deltas()
                    .map(|(dx, dy)| {
                        let (tx, ty) = texel(x + dx, y + dy);
                        e((tx - dx as i32, ty - dy as i32)) + v(x + dx, y + dy)
                    })
                    .sum();
                (sum * 256).div_euclid(9)
            } else if pit {
                lo
            } else {
                hi
            };
        }
    }
    out.into_iter().map(|o| o as i32).collect()
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(24))]

    #[test]
    fn reconstruct_follows_the_rule_on_random_states(
        w in 1usize..48, h in 1usize..48,
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let rig = rig(default_db());
        let st = random_state(&rig.atlas[0], w.max(2), h.max(2), &bits, 0);
        let got = reconstruct(&rig.atlas[0], rig.heights, &st);
        prop_assert_eq!(got, oracle(&rig.atlas[0], rig.heights, &st));
    }

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

/// On the level 0 of real syntheses (coherent patches and their joins):
/// the documented rule.
#[test]
fn reconstruct_follows_the_rule_on_real_states() {
    for (db, size, seed) in real_syntheses("real-DEM reconstruct rule") {
        let levels = real_levels(db, size, seed);
        let level0 = levels.iter().find(|r| r.level == 0).expect("level 0 kept");
        let rig = rig(db);
        let st = &level0.state;
        let got = reconstruct(&rig.atlas[0], rig.heights, st);
        assert_eq!(
            got,
            oracle(&rig.atlas[0], rig.heights, st),
            "{size:?} seed {seed}"
        );
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
