//! The fast correction (`correct`, SIMD inside + scalar frame) must give the
//! same bytes as the scalar reference (`correct::scalar`, the oracle the GPU
//! kernel mirrors) on real synthesis states and on random ones.

use proptest::prelude::*;
use std::sync::OnceLock;
use terrasynth::database::{Database, default, layout::MARGIN};
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::fixed::Coord;
use terrasynth::synth::stages::correct::{self, CorrectParams, SUBPASSES, scalar};
use terrasynth::synth::state::State;
use terrasynth::synth::{Params, Synthesizer};

fn db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

fn state_from(w: usize, h: usize, coords: &[Coord], offsets: &[i32]) -> State {
    let st = State::new(w, h);
    for i in 0..w * h {
        st.set(i, coords[i], offsets[i]);
    }
    st
}

/// Runs one subpass both ways on copies of a state; asserts equal bytes.
fn assert_paths_agree(atlas: &AtlasLevel<'_>, st: &State, what: &str) {
    for &(px, py) in &SUBPASSES {
        let p = CorrectParams { px, py };
        let fast = state_from(st.width, st.height, &st.coords(), &st.offsets());
        let slow = state_from(st.width, st.height, &st.coords(), &st.offsets());
        correct::correct(atlas, &fast, &p);
        scalar::correct(atlas, &slow, &p);
        let (fc, sc) = (fast.coords(), slow.coords());
        let (fo, so) = (fast.offsets(), slow.offsets());
        if let Some(i) = (0..fc.len()).find(|&i| fc[i] != sc[i] || fo[i] != so[i]) {
            panic!(
                "{what}, subpass ({px},{py}): pixel ({}, {}) fast {:?}/{} vs scalar {:?}/{}",
                i % st.width,
                i / st.width,
                fc[i],
                fo[i],
                sc[i],
                so[i]
            );
        }
    }
}

#[test]
fn fast_and_scalar_correction_agree_on_real_states() {
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let out = Synthesizer::new(db(), params)
        .unwrap()
        .run(203, 150, 77)
        .unwrap();
    let coarsest = db().level_count() - 1;
    let mut checked = 0;
    for maps in out.levels.iter().filter(|m| m.level <= coarsest) {
        let atlas = AtlasLevel::new(db(), maps.level);
        let st = state_from(maps.width, maps.height, &maps.coords, &maps.offsets);
        assert_paths_agree(&atlas, &st, &format!("level {}", maps.level));
        checked += 1;
    }
    assert!(checked >= 3, "only {checked} levels checked");
}

/// A random but valid state: patches of coherent coordinates (so candidate
/// de-duplication is exercised) with random fractions, jumps between
/// exemplars, and random offsets.
fn random_state(atlas: &AtlasLevel<'_>, w: usize, h: usize, seed: u64) -> State {
    let mut rng = seed | 1;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    let rects = &atlas.level.layout.rects;
    let st = State::new(w, h);
    let mut origin = (0i32, 0i32, 0usize);
    for y in 0..h {
        for x in 0..w {
            if x % 5 == 0 || next() % 7 == 0 {
                origin = (x as i32, y as i32, (next() % rects.len() as u64) as usize);
            }
            let r = rects[origin.2];
            let span = |n: u32| (n - 2 * MARGIN) as i32;
            let tx = (r.x0 + MARGIN) as i32
                + (x as i32 - origin.0 + (next() % 3) as i32).rem_euclid(span(r.width));
            let ty = MARGIN as i32 + (y as i32 - origin.1).rem_euclid(span(r.height));
            let frac = |v: u64| (v % 256) as i32 - 128;
            let c = Coord {
                x: (tx << 8) + frac(next()),
                y: (ty << 8) + frac(next()),
            };
            let v = (next() % 4001) as i32 - 2000;
            st.set(y * w + x, c, v);
        }
    }
    st
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn fast_and_scalar_correction_agree_on_random_states(
        level in 0usize..3,
        w in 2usize..70,
        h in 2usize..40,
        seed in any::<u64>(),
    ) {
        let atlas = AtlasLevel::new(db(), level);
        let st = random_state(&atlas, w, h, seed);
        assert_paths_agree(&atlas, &st, &format!("random {w}x{h} at level {level}"));
    }
}
