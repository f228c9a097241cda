//! Stage `upsample_jitter` against an oracle written here from the stage's
//! documented rule (eq. 1–2 and the module docs of
//! `src/stages/upsample_jitter.rs`; none of the stage's code): the CPU
//! stage over the whole level and over rectangles (an edit's
//! re-synthesis) and, with `--features gpu` and an adapter,
//! `kernels/upsample_jitter.wgsl` — on random parents (proptest: pyramid,
//! virtual and wrapping steps, windows' origins) and on the real levels of
//! syntheses from the default database and from a database of
//! ../shared/dem crops. Under `TERRASYNTH_PORTABLE_SIMD` the CPU runs its
//! baseline copy (no AVX2), which the oracle then checks.

use proptest::prelude::*;
use terrasynth::database::layout::MARGIN;
use terrasynth::hash::hash4;
use terrasynth::isa::Isa;
use terrasynth::level::atlas::AtlasLevel;
use terrasynth::level::fixed::{Coord, FRAC_BITS};
use terrasynth::level::state::State;
use terrasynth::level::state::level_size;
use terrasynth::stages::upsample_jitter::{
    Step, UpsampleParams, upsample_jitter, upsample_jitter_rect,
};

use crate::common::db::{default_db, real_syntheses};
use crate::common::states::{random_state, real_levels};
use crate::common::variants::{Run, assert_agree, rig};

/// Child pixel (x, y) of `parent` by the rule: with c = (x mod 2, y mod 2)
/// and the parent p = (⌊x/2⌋, ⌊y/2⌋), S = 2·S(p) + c + r·H and V = V(p),
/// H's two components the low and high 16 bits of hash4(seed, level, X, Y)
/// at the absolute position (X, Y) = origin + (x, y), centred on 0 and
/// scaled so that r·H ∈ [−r, r), rounded down. Below the coarsest level the
/// child is clamped into the interior (the 2-texel margin off) of the
/// exemplar that holds it before jitter; above it, coordinates stay in
/// level-L units and move by (c + r·H)·2^shift; entering L they wrap into
/// the start rectangle. Plain i64 arithmetic: no shifts, no overflow.
/// `atlas` is the child level's (pyramid steps clamp with it).
fn oracle(
    parent: &State,
    atlas: Option<&AtlasLevel<'_>>,
    p: &UpsampleParams,
    x: usize,
    y: usize,
) -> (Coord, i32) {
    let one = 1i64 << FRAC_BITS;
    let k = (y / 2) * parent.width + x / 2;
    let (s, v) = (parent.s(k), parent.v(k));
    let h = hash4(
        p.seed,
        p.level,
        p.origin[0] + x as u32,
        p.origin[1] + y as u32,
    );
    let rh = |half: u32| ((i64::from(half) - 32768) * i64::from(p.jitter)).div_euclid(32768);
    let (cx, cy) = ((x % 2) as i64 * one, (y % 2) as i64 * one);
    let (ox, oy) = (cx + rh(h & 0xFFFF), cy + rh(h >> 16));
    let (sx, sy) = (i64::from(s.x), i64::from(s.y));
    let (nx, ny) = match p.step {
        Step::Pyramid => {
            let home = (2 * sx + cx + one / 2).div_euclid(one);
            let r = atlas
                .expect("pyramid steps have an atlas")
                .level
                .layout
                .rects
                .iter()
                .find(|r| (i64::from(r.x0)..i64::from(r.x0 + r.width)).contains(&home))
                .expect("the child's home texel lies in an exemplar");
            let m = i64::from(MARGIN);
            let (x0, w, h) = (i64::from(r.x0), i64::from(r.width), i64::from(r.height));
            (
                (2 * sx + ox).clamp((x0 + m) * one, (x0 + w - 1 - m) * one),
                (2 * sy + oy).clamp(m * one, (h - 1 - m) * one),
            )
        }
        Step::Virtual { shift } => (sx + ox * (1 << shift), sy + oy * (1 << shift)),
        Step::Wrap {
            min_x,
            max_x,
            min_y,
            max_y,
        } => {
            let wrap = |v: i64, lo: i32, hi: i32| {
                let (lo, hi) = (i64::from(lo) * one, (i64::from(hi) + 1) * one);
                lo + (v - lo).rem_euclid(hi - lo)
            };
            (wrap(sx + ox, min_x, max_x), wrap(sy + oy, min_y, max_y))
        }
    };
    (
        Coord {
            x: nx as i32,
            y: ny as i32,
        },
        v,
    )
}

/// The oracle's `w × h` child level, as a run to put first in a variant list.
fn oracle_run(
    parent: &State,
    atlas: Option<&AtlasLevel<'_>>,
    (w, h): (usize, usize),
    p: &UpsampleParams,
) -> Run<(Coord, i32)> {
    let px = (0..w * h).map(|k| oracle(parent, atlas, p, k % w, k / w));
    ("oracle", px.collect())
}

proptest! {
    #![proptest_config(crate::common::proptest_cases(24))]

    #[test]
    fn upsample_jitter_agrees_on_random_states(
        w in 2usize..40, h in 2usize..40, level_pick in 0usize..8, seed in any::<u32>(),
        jitter in 0i32..=1024, shift in 1u32..4, kind in 0u32..3,
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
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
        let size = (cw.max(2), ch.max(2));
        let mut runs = rig.upsample_jitter(&parent, size, level, &p);
        runs.insert(0, oracle_run(&parent, rig.atlas.get(level), size, &p));
        assert_agree(&runs, &format!("upsample_jitter to level {level} ({step:?})"));
    }

    #[test]
    fn upsample_jitter_rect_follows_the_rule_inside_and_keeps_the_rest(
        w in 2usize..40, h in 2usize..40, r in prop::array::uniform4(0usize..84),
        level_pick in 0usize..8, jitter in 0i32..=1024, seed in any::<u32>(),
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let rig = rig(default_db());
        let level = level_pick % (rig.atlas.len() - 1);
        let parent = random_state(&rig.atlas[level + 1], w, h, &bits, 0);
        let origin = [bits[1] % 65536 * 2, bits[2] % 65536 * 2];
        let p = UpsampleParams { seed, level: level as u32, jitter, step: Step::Pyramid, origin };
        let (cw, ch) = (2 * w, 2 * h);
        let rect = [r[0].min(r[1]), r[2].min(r[3]), r[0].max(r[1]), r[2].max(r[3])];
        let untouched = State::new(1, 1);
        for &isa in Isa::all() {
            let part = State::new(cw, ch);
            upsample_jitter_rect(&parent, &part, Some(&rig.atlas[level]), &p, rect, isa);
            for k in 0..cw * ch {
                let (x, y) = (k % cw, k / cw);
                let inside = (rect[0]..rect[2]).contains(&x) && (rect[1]..rect[3]).contains(&y);
                let want = if inside {
                    oracle(&parent, rig.atlas.get(level), &p, x, y)
                } else {
                    (untouched.s(0), untouched.v(0))
                };
                prop_assert_eq!((part.s(k), part.v(k)), want, "{:?}: pixel ({}, {})", isa, x, y);
            }
        }
    }
}

/// The whole-level entry the rect one wraps, called directly (the random
/// test reaches it through the CPU backend): a parent with every
/// exemplar's corner texels, where clamping acts most, at the largest
/// jitter `--jitter` allows.
#[test]
fn upsample_jitter_whole_level_follows_the_rule_at_exemplar_corners() {
    let rig = rig(default_db());
    let atlas = &rig.atlas[1];
    let one = 1 << FRAC_BITS;
    let mut coords = Vec::new();
    for r in &atlas.level.layout.rects {
        let (x0, x1) = ((r.x0 + MARGIN) as i32, (r.x0 + r.width - 1 - MARGIN) as i32);
        let (y0, y1) = (MARGIN as i32, (r.height - 1 - MARGIN) as i32);
        for (x, y) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
            for f in [-one / 2, 0, one / 2 - 1] {
                coords.push(Coord {
                    x: x * one + f,
                    y: y * one - f,
                });
            }
        }
    }
    let (w, h) = (coords.len(), 3);
    let parent = State::new(w, h);
    for (k, &c) in coords.iter().cycle().take(w * h).enumerate() {
        parent.set(k, c, k as i32 - 40);
    }
    let p = UpsampleParams {
        seed: 9,
        level: 0,
        jitter: 4 * one,
        step: Step::Pyramid,
        origin: [0, 0],
    };
    for &isa in Isa::all() {
        let child = State::new(2 * w, 2 * h);
        upsample_jitter(&parent, &child, Some(&rig.atlas[0]), &p, isa);
        for k in 0..4 * w * h {
            let (x, y) = (k % (2 * w), k / (2 * w));
            let want = oracle(&parent, rig.atlas.first(), &p, x, y);
            assert_eq!((child.s(k), child.v(k)), want, "{isa:?}: pixel ({x}, {y})");
        }
    }
}

/// Every kept level of each real synthesis at or below the database's
/// coarsest (and above level 0) upsampled into the level below it.
#[test]
fn upsample_jitter_agrees_on_real_states() {
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
                let size = level_size(w, h, level);
                let mut runs = rig.upsample_jitter(&r.state, size, level, &p);
                runs.insert(0, oracle_run(&r.state, rig.atlas.get(level), size, &p));
                assert_agree(&runs, &format!("upsample_jitter to level {level} (real)"));
            }
        }
    }
}

/// The rig runs the CPU path once per instruction-set level this CPU has,
/// named by it, then the GPU where there is one: a level that silently
/// stopped running (an AVX2 CPU whose `avx2` copy went unchecked) fails
/// here rather than passing every comparison unseen.
#[test]
fn the_rig_runs_every_isa_level_and_the_gpu() {
    let rig = rig(default_db());
    let p = UpsampleParams {
        seed: 1,
        level: 0,
        jitter: 102,
        step: Step::Virtual { shift: 0 },
        origin: [0, 0],
    };
    let runs = rig.upsample_jitter(&State::new(2, 2), (4, 4), 0, &p);
    let names: Vec<&str> = runs.iter().map(|r| r.0).collect();
    let mut want: Vec<&str> = Isa::all().iter().map(|i| i.name()).collect();
    if rig.has_gpu() {
        want.push("gpu");
    }
    assert_eq!(names, want);
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        assert_eq!(names[..2], ["portable", "avx2"]);
    }
}
