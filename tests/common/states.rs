//! Level states for the stage tests: copies, states from a synthesis' kept
//! levels, and random states that keep the synthesis' guarantees.

use terrasynth::database::layout::MARGIN;
use terrasynth::level::atlas::AtlasLevel;
use terrasynth::level::fixed::{Coord, FRAC_BITS};
use terrasynth::level::state::State;
use terrasynth::synth::{LevelMaps, Params, Synthesizer};

/// A `w × h` state holding `coords` and `offsets`.
pub fn state_from(w: usize, h: usize, coords: &[Coord], offsets: &[i32]) -> State {
    let st = State::new(w, h);
    for i in 0..w * h {
        st.set(i, coords[i], offsets[i]);
    }
    st
}

/// A copy of `st` (stages work in place).
pub fn copy(st: &State) -> State {
    state_from(st.width, st.height, &st.coords(), &st.offsets())
}

/// A kept level's state.
pub fn from_maps(m: &LevelMaps) -> State {
    state_from(m.width, m.height, &m.coords, &m.offsets)
}

/// A state's pixels as `(S, V)` pairs, row-major: one value per pixel, so
/// that a difference names its pixel.
pub fn pixels(coords: &[Coord], offsets: &[i32]) -> Vec<(Coord, i32)> {
    coords
        .iter()
        .copied()
        .zip(offsets.iter().copied())
        .collect()
}

/// One level of a real synthesis: its state and the level above it (the
/// height prior's anchor; `None` at the top).
pub struct RealLevel {
    pub level: usize,
    pub state: State,
    pub parent: Option<State>,
}

/// Every level a `w × h` synthesis of `db` (seed `seed`, default
/// parameters) keeps, finest first.
pub fn real_levels(
    db: &terrasynth::database::Database,
    (w, h): (usize, usize),
    seed: u32,
) -> Vec<RealLevel> {
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let out = Synthesizer::new(db, params)
        .unwrap()
        .run(w, h, seed)
        .unwrap();
    let kept = |l: usize| out.levels.get(l).filter(|m| !m.coords.is_empty());
    out.levels
        .iter()
        .filter(|m| !m.coords.is_empty())
        .map(|m| RealLevel {
            level: m.level,
            state: from_maps(m),
            parent: kept(m.level + 1).map(from_maps),
        })
        .collect()
}

/// What the synthesis guarantees of a level's state: every coordinate
/// rounds into an exemplar's interior, its fraction in [−½, ½) texel.
/// Drawn from `bits` (cycled), mixed with each pixel's index and `salt`.
pub fn random_state(atlas: &AtlasLevel<'_>, w: usize, h: usize, bits: &[u32], salt: u32) -> State {
    let rects = &atlas.level.layout.rects;
    let st = State::new(w, h);
    for i in 0..w * h {
        let b =
            |k: usize| bits[(4 * i + k) % bits.len()] ^ (i as u32 ^ salt).wrapping_mul(0x9E37_79B9);
        let r = rects[b(0) as usize % rects.len()];
        let tx = r.x0 + MARGIN + b(1) % (r.width - 2 * MARGIN);
        let ty = MARGIN + b(2) % (r.height - 2 * MARGIN);
        let fx = (b(3) & 0xFF) as i32 - 128;
        let fy = ((b(3) >> 8) & 0xFF) as i32 - 128;
        let v = ((b(3) >> 16) % 801) as i32 - 400;
        st.set(
            i,
            Coord {
                x: ((tx as i32) << FRAC_BITS) + fx,
                y: ((ty as i32) << FRAC_BITS) + fy,
            },
            v,
        );
    }
    st
}

/// A xorshift64 stream from `seed`: the tests' reproducible randomness.
pub fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut x = seed | 1;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

/// A random but valid state: patches of coherent coordinates (so candidate
/// de-duplication is exercised) with random fractions, jumps between
/// exemplars, and random offsets.
pub fn patchy_state(atlas: &AtlasLevel<'_>, w: usize, h: usize, seed: u64) -> State {
    let mut next = xorshift(seed);
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

/// The level above a `w × h` [`patchy_state`], whose offsets (the height
/// prior's anchor) range as widely as the state's.
pub fn patchy_parent(atlas: &AtlasLevel<'_>, w: usize, h: usize, seed: u64) -> State {
    patchy_state(atlas, w.div_ceil(2), h.div_ceil(2), seed ^ 0x5EED)
}
