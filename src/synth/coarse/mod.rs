//! The coarse start: the state synthesis begins from, above or at the
//! coarsest corrected level L — the database's coarsest level, at most
//! [`MAX_START_LEVEL`].
//!
//! **Without jitter** (the reproduction property): level M holds the start
//! exemplar's centre, spread so that each level halves the spacing — at
//! level ≤ L an exact copy of the centre, tiled toroidally when the output
//! is larger than the exemplar.
//!
//! **With jitter**, level L starts as a mosaic of *blocks* of 2^b × 2^b
//! texels, each copied verbatim around a hash-chosen texel of any exemplar
//! ([`blocks`]), drawn uniformly over every interior texel (so every
//! exemplar, every terrain type and every part of an exemplar is drawn by
//! its area), plus the paper's jitter; from L down, jitter and correction
//! rearrange them. Each 2 × 2 group of blocks keeps, of eight such draws,
//! the one whose heights, slopes and terrain types are distributed most
//! like its exemplars' (`fit.rs`).
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
//! (DESIGN §6), or a comparison of such draws over the block's group and
//! the world's size, so any window of a terrain starts from the same
//! blocks.

mod blocks;
mod fit;

pub use blocks::blocks;
pub use fit::Profile;

use crate::database::layout::MARGIN;
use crate::synth::atlas::AtlasLevel;
use crate::synth::cone::Rect;
use crate::synth::fixed::{Coord, FRAC_BITS};
use crate::synth::state::{State, level_size};

/// What the blocks draw from: the database level L of `atlas`, exemplar
/// `from` (or every exemplar), and the [`Profile`] of the same.
#[derive(Clone, Copy)]
pub struct Source<'a> {
    pub atlas: &'a AtlasLevel<'a>,
    pub from: Option<usize>,
    pub profile: &'a Profile,
}

/// The coarsest level synthesis starts from (and corrects), whatever
/// coarser levels the database holds.
///
/// Why not the database's coarsest level L: synthesis coordinates stay
/// [`MARGIN`] texels inside every exemplar at every level, and a level-L
/// texel is 2^L pixels across — at L = 5 (the shared DEMs) the outer 64
/// pixels of every exemplar side, 20–29 % of its area, were never drawn
/// (measured from `--coords`: 0.0–0.5 % of the output from the outer 64
/// columns of franconian_jura, 8 % of its area), and that is where those
/// DEMs keep their lowest valleys and highest ridges: the output kept
/// 76–85 % of their relief. Starting at level 3 loses 16 pixels a side;
/// the blocks keep their size in pixels (b grows as the level falls).
/// Level 2 left too few levels to join the blocks: straight seams showed
/// along block edges (looked at on thuringia).
pub const MAX_START_LEVEL: usize = 3;

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
