//! The fast correction (`correct`, SIMD inside + scalar frame) must give the
//! same bytes as the scalar reference (`correct::scalar`, the oracle the GPU
//! kernel mirrors) on real synthesis states and on random ones.

use proptest::prelude::*;
use std::sync::OnceLock;
use terrasynth::database::{Database, default, layout::MARGIN};
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::control::Target;
use terrasynth::synth::fixed::Coord;
use terrasynth::synth::stages::correct::{
    self, ALL_TYPES, Coherence, CorrectParams, DEFAULT_PRIOR, Guide, PRIORS, SUBPASSES, scalar,
};
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

/// Runs one subpass both ways on copies of a state, for every height prior
/// weight; asserts equal bytes.
fn assert_paths_agree(atlas: &AtlasLevel<'_>, st: &State, parent: Option<&State>, what: &str) {
    assert_guided_paths_agree(atlas, st, parent, &Guide::NONE, what)
}

/// [`assert_paths_agree`] under control inputs.
fn assert_guided_paths_agree(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    g: &Guide<'_>,
    what: &str,
) {
    for (&(px, py), &prior) in SUBPASSES
        .iter()
        .flat_map(|s| PRIORS.iter().map(move |p| (s, p)))
    {
        let p = CorrectParams { px, py, prior };
        let fast = state_from(st.width, st.height, &st.coords(), &st.offsets());
        let slow = state_from(st.width, st.height, &st.coords(), &st.offsets());
        correct::correct_guided(atlas, &fast, parent, &p, g);
        scalar::correct_guided(atlas, &slow, parent, &p, g);
        let (fc, sc) = (fast.coords(), slow.coords());
        let (fo, so) = (fast.offsets(), slow.offsets());
        if let Some(i) = (0..fc.len()).find(|&i| fc[i] != sc[i] || fo[i] != so[i]) {
            panic!(
                "{what}, subpass ({px},{py}), prior {prior}: pixel ({}, {}) fast {:?}/{} vs scalar {:?}/{}",
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
    for (i, maps) in out
        .levels
        .iter()
        .enumerate()
        .filter(|(_, m)| m.level <= coarsest)
    {
        let atlas = AtlasLevel::new(db(), maps.level);
        let st = state_from(maps.width, maps.height, &maps.coords, &maps.offsets);
        let parent = out
            .levels
            .get(i + 1)
            .map(|p| state_from(p.width, p.height, &p.coords, &p.offsets));
        assert_paths_agree(
            &atlas,
            &st,
            parent.as_ref(),
            &format!("level {}", maps.level),
        );
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

/// The level above a `w × h` random state, whose offsets (the height
/// prior's anchor) range as widely as the state's.
fn random_parent(atlas: &AtlasLevel<'_>, w: usize, h: usize, seed: u64) -> State {
    random_state(atlas, w.div_ceil(2), h.div_ceil(2), seed ^ 0x5EED)
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
        let parent = random_parent(&atlas, w, h, seed);
        let parent = (seed % 3 != 0).then_some(&parent);
        assert_paths_agree(&atlas, &st, parent, &format!("random {w}x{h} at level {level}"));
    }
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
    let mut rng = seed | 1;
    let mut next = move || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        rng
    };
    let n = w * h;
    let targets = (0..n)
        .map(|_| {
            if next() % 2 == 0 {
                Target::NONE
            } else {
                Target {
                    height: (next() % 70_000) as i32 - 2_000,
                    tol: (next() % 5_000) as i32,
                }
            }
        })
        .collect();
    let prev = random_state(atlas, w, h, seed ^ 0x9E37_79B9);
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Geometric targets, coherence, type sets and windows: the fast path
    /// still gives the scalar oracle's bytes.
    #[test]
    fn fast_and_scalar_correction_agree_under_control(
        level in 0usize..3,
        w in 2usize..70,
        h in 2usize..40,
        seed in any::<u64>(),
        which in 0u8..16,
    ) {
        let atlas = AtlasLevel::new(db(), level);
        let st = random_state(&atlas, w, h, seed);
        let (targets, prev, weights, allowed, window) = random_guide_inputs(&atlas, w, h, seed);
        let (coords, offsets) = (prev.coords(), prev.offsets());
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
            origin: [(seed as u32 % 4096) * 2, (seed >> 32) as u32 % 4096 * 2],
        };
        let parent = random_parent(&atlas, w, h, seed);
        let what = format!("guided {which:04b} {w}x{h} at level {level}");
        assert_guided_paths_agree(&atlas, &st, Some(&parent), &g, &what);
    }
}

/// The controls actually act: a target pulls heights, a window leaves the
/// outside alone, a frozen coherence candidate is kept as is.
#[test]
fn controls_change_the_result_as_intended() {
    let atlas = AtlasLevel::new(db(), 1);
    let (w, h) = (40, 30);
    let st = random_state(&atlas, w, h, 5);
    let p = CorrectParams {
        px: 0,
        py: 0,
        prior: DEFAULT_PRIOR,
    };
    let plain = state_from(w, h, &st.coords(), &st.offsets());
    correct::correct(&atlas, &plain, None, &p);
    // A far-away target with zero tolerance moves every corrected offset.
    let targets = vec![
        Target {
            height: 200_000,
            tol: 0
        };
        w * h
    ];
    let pulled = state_from(w, h, &st.coords(), &st.offsets());
    let g = Guide {
        targets: Some(&targets),
        ..Guide::NONE
    };
    correct::correct_guided(&atlas, &pulled, None, &p, &g);
    for i in (0..w * h).filter(|i| (i % w) % 2 == 0 && (i / w) % 2 == 0) {
        assert!(
            pulled.offsets()[i] > plain.offsets()[i] + 10_000,
            "pixel {i}"
        );
    }
    // A window corrects only inside.
    let windowed = state_from(w, h, &st.coords(), &st.offsets());
    let g = Guide {
        window: Some([10, 4, 20, 12]),
        ..Guide::NONE
    };
    correct::correct_guided(&atlas, &windowed, None, &p, &g);
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
    let prev = random_state(&atlas, w, h, 99);
    let (coords, offsets) = (prev.coords(), prev.offsets());
    let weights = vec![0u8; w * h];
    let frozen = state_from(w, h, &st.coords(), &st.offsets());
    let g = Guide {
        coherence: Some(Coherence {
            coords: &coords,
            offsets: &offsets,
            weights: &weights,
        }),
        ..Guide::NONE
    };
    correct::correct_guided(&atlas, &frozen, None, &p, &g);
    for i in (0..w * h).filter(|i| (i % w) % 2 == 0 && (i / w) % 2 == 0) {
        assert_eq!(
            (frozen.coords()[i], frozen.offsets()[i]),
            (coords[i], offsets[i])
        );
    }
}
