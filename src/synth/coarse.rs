//! The coarse start: the state synthesis begins from, above or at the
//! database's coarsest level L.
//!
//! **Without jitter** (the reproduction property): level M holds the start
//! exemplar's centre, spread so that each level halves the spacing — at
//! level ≤ L an exact copy of the centre, tiled toroidally when the output
//! is larger than the exemplar.
//!
//! **With jitter**, level L starts as a mosaic of *blocks* of 2^b × 2^b
//! texels, each copied verbatim from a hash-chosen origin in any exemplar,
//! drawn uniformly over every interior texel (so every exemplar, every
//! terrain type and every part of an exemplar is drawn by its area), plus
//! the paper's jitter; from L down, jitter and correction rearrange them.
//!
//! Why blocks, and why as large as the exemplars allow (b = ⌊log₂⌋ of the
//! smallest exemplar interior side at L): pixel-based correction can join
//! patches but cannot create large-scale structure. A mosaic of many small
//! blocks (the fully jittered coarse level of Lefebvre & Hoppe 2005, which
//! this crate used with b = 2) has no structure above the block size, and
//! its joins — blocks from different altitudes side by side — are what the
//! correction then levels: measured on the shared DEMs, level L kept 55–65 %
//! of the exemplar's height spread and the output 55–70 % of its relief.
//! Large blocks keep the exemplars' massifs and valley networks; the output
//! still differs from any exemplar below the block scale (coherent patches
//! at level 0 average ~100 pixels), and outputs larger than the exemplars
//! get more blocks rather than a tiled copy. Halving the blocks (b − 1)
//! was measured too: relief ≥ 85 % on 2 of the 8 DEMs instead of 4, and
//! "hills" took 69 % of a typed output where they are 48 % of the
//! exemplars — every join is levelled towards the middle.
//!
//! Computed on the host for every backend and uploaded: it is small
//! (level L, ⌈W/2^L⌉ × ⌈H/2^L⌉ pixels), so it has no kernel mirror. Every
//! choice is a hash of the seed and the block's absolute position
//! (DESIGN §6), so any window of a terrain starts from the same blocks.

use crate::database::layout::MARGIN;
use crate::hash::{below, hash4};
use crate::synth::atlas::AtlasLevel;
use crate::synth::cone::Rect;
use crate::synth::fixed::{Coord, FRAC_BITS};
use crate::synth::stages::upsample_jitter;
use crate::synth::state::{State, level_size};

/// Hash salt of the block positions (kept apart from the jitter's
/// `hash4(seed, level, x, y)`, whose level is always < 2^16).
const COARSE_SALT: u32 = 0xC0A5_0000;

/// How a synthesis starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Start {
    /// The start exemplar's centre at level M (no jitter, or no room for a
    /// block above L).
    Centre,
    /// Verbatim blocks of 2^bits × 2^bits level-L texels, made at level L.
    Blocks { bits: usize },
}

impl Start {
    /// The start of an output whose coarsest level is `m`, for a database
    /// whose coarsest level `l` is `atlas_l`: blocks (from exemplar `from`,
    /// or every exemplar) when there is jitter and room above L, else the
    /// centre.
    pub fn choose(
        jittered: bool,
        m: usize,
        l: usize,
        atlas_l: &AtlasLevel<'_>,
        from: Option<usize>,
    ) -> Start {
        let bits = block_bits(atlas_l, from).min(m.saturating_sub(l));
        if jittered && bits > 0 {
            Start::Blocks { bits }
        } else {
            Start::Centre
        }
    }

    /// The coarsest synthesized level.
    pub fn top(self, m: usize, l: usize) -> usize {
        match self {
            Start::Centre => m,
            Start::Blocks { .. } => l,
        }
    }
}

/// Inclusive interior bounds `[x0, x1] × [y0, y1]` of exemplar `from`, or
/// of every exemplar, of a level, in atlas texels.
fn interiors<'a>(
    a: &'a AtlasLevel<'_>,
    from: Option<usize>,
) -> impl Iterator<Item = (i32, i32, i32, i32)> + 'a {
    let rects = &a.level.layout.rects;
    let rects = match from {
        Some(e) => &rects[e..=e],
        None => &rects[..],
    };
    rects.iter().map(|r| {
        let c = a.columns[r.x0 as usize];
        (c.min_x, c.max_x, MARGIN as i32, c.max_y)
    })
}

/// The largest b such that a 2^b block fits the interior of exemplar
/// `from` (or of every exemplar) at level L.
pub fn block_bits(a: &AtlasLevel<'_>, from: Option<usize>) -> usize {
    let side = interiors(a, from)
        .map(|(x0, x1, y0, y1)| (x1 - x0 + 1).min(y1 - y0 + 1))
        .min()
        .unwrap_or(1)
        .max(1);
    side.ilog2() as usize
}

/// Level L of an output over `region` (absolute level-L pixels: the whole
/// level, or a window's cone): the level-`L + bits` pixel above
/// each 2^bits × 2^bits group of pixels picks one exemplar texel (`hash`
/// of the seed and the group's position) uniformly over every interior
/// texel of exemplar `from` (or of every exemplar); the group copies the
/// exemplar from that origin, wrapping toroidally inside the exemplar's
/// interior, and each pixel gets the level's jitter (`jitter`, fixed point,
/// the same hash as `upsample_jitter`).
///
/// Why wrap: blocks that must fit the interior start only at the first
/// `side − 2^bits + 1` texels of each axis, so a texel near an exemplar edge
/// is covered by one origin where a central one is covered by 2^bits —
/// measured on the shared DEMs (blocks of 32 in a 43-texel interior), the
/// output drew 12× more from the exemplar's centre than from its edges,
/// and real DEMs are not alike across their extent (thuringia: median slope
/// 6.2° in its centre, 5.0° over all). Wrapping covers every interior texel
/// equally; the wrap line is one more join, which correction repairs like
/// the joins between blocks.
pub fn blocks(
    a: &AtlasLevel<'_>,
    from: Option<usize>,
    region: Rect,
    (l, bits): (usize, usize),
    seed: u32,
    jitter: i32,
) -> State {
    let mask = (1usize << bits) - 1;
    // Interior origin and size (x0, y0, nx, ny) per exemplar.
    let ranges: Vec<(i32, i32, i32, i32)> = interiors(a, from)
        .map(|(x0, x1, y0, y1)| (x0, y0, x1 - x0 + 1, y1 - y0 + 1))
        .collect();
    let total: u32 = ranges.iter().map(|r| (r.2 * r.3) as u32).sum();
    let (w, h) = (region.width(), region.height());
    let st = State::new(w, h);
    for (i, y) in (region.y0..region.y1).enumerate() {
        for (j, x) in (region.x0..region.x1).enumerate() {
            let hash = hash4(seed, COARSE_SALT, (x >> bits) as u32, (y >> bits) as u32);
            let mut k = below(hash, total);
            for &(x0, y0, nx, ny) in &ranges {
                let n = (nx * ny) as u32;
                if k < n {
                    let (bx, by) = ((k % nx as u32) as i32, (k / nx as u32) as i32);
                    let lx = bx + (x & mask) as i32;
                    let ly = by + (y & mask) as i32;
                    let (jx, jy) =
                        upsample_jitter::jitter(seed, l as u32, x as u32, y as u32, jitter);
                    let s = Coord {
                        x: wrap_centred(((x0 + lx) << FRAC_BITS) + jx, x0, nx),
                        y: wrap_centred(((y0 + ly) << FRAC_BITS) + jy, y0, ny),
                    };
                    st.set(i * w + j, s, 0);
                    break;
                }
                k -= n;
            }
        }
    }
    st
}

/// Wraps fixed-point `v` into `[min − ½, min + n − ½)` texels, so that it
/// rounds (half up) to one of the `n` texels from `min`.
fn wrap_centred(v: i32, min: i32, n: i32) -> i32 {
    let half = 1 << (FRAC_BITS - 1);
    let base = (min << FRAC_BITS) - half;
    base + (v - base).rem_euclid(n << FRAC_BITS)
}

/// Level `top` of a `width × height` output without blocks, over `region`
/// (absolute level-`top` pixels): the centre of exemplar `e` at the level
/// `min(top, l)` of `a`, spread so that each level halves the spacing (in
/// level-L units above L).
pub fn centre(
    a: &AtlasLevel<'_>,
    e: usize,
    (width, height): (usize, usize),
    region: Rect,
    top: usize,
    l: usize,
) -> State {
    let r = a.level.layout.rects[e];
    let (w, h) = level_size(width, height, top);
    let st = State::new(region.width(), region.height());
    let (cx, cy) = ((r.x0 + r.width / 2) as i32, (r.height / 2) as i32);
    for (i, y) in (region.y0..region.y1).enumerate() {
        for (j, x) in (region.x0..region.x1).enumerate() {
            // Offset from the level's centre, in half texels of level top.
            let (hx, hy) = (2 * x as i32 + 1 - w as i32, 2 * y as i32 + 1 - h as i32);
            let to_fixed = |half: i32| -> i32 {
                if top > l {
                    // In level-L units: a level-top texel is 2^(top−L) of them.
                    (half << FRAC_BITS) << (top - l - 1)
                } else {
                    half << (FRAC_BITS - 1)
                }
            };
            let s = Coord {
                x: (cx << FRAC_BITS) + to_fixed(hx),
                y: (cy << FRAC_BITS) + to_fixed(hy),
            };
            st.set(i * region.width() + j, s, 0);
        }
    }
    st
}
