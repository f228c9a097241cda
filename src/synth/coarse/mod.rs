//! The coarse start: the state synthesis begins from, above or at the
//! coarsest corrected level L — the database's coarsest level, at most
//! [`MAX_START_LEVEL`].
//!
//! **Without jitter** (the reproduction property): level M holds the start
//! exemplar's centre, spread so that each level halves the spacing — at
//! level ≤ L an exact copy of the centre, tiled toroidally when the output
//! is larger than the exemplar.
//!
//! **With jitter**, level L starts as a mosaic of **pieces** of the
//! exemplars, one per cell of a grid of
//! [`Params::piece_size`](crate::synth::Params) output pixels (32 by
//! default), cut along wavy edges ([`pieces`](fn@pieces)): each piece copies the exemplar around a
//! texel drawn from the [`Pool`] of every interior texel ranked by the
//! altitude of its surroundings, at the rank an altitude guide — a smooth
//! random field of its own (`guide.rs`) — sets for the piece's place
//! ([`pieces`](fn@pieces)), plus the paper's jitter; from L down, jitter and
//! correction join and refine them. Where the user painted terrain types,
//! a pixel's piece comes from the pool of those types' texels
//! ([`Pool::of_types`]): correction sees types only at levels ≥ 2 and
//! replaces an unfitting piece pixel by pixel, so a painted region started
//! from the wrong landforms kept much of their relief (issue 40: a painted
//! disc had its type's local relief on 0–61 % of its area; 73–84 % now,
//! with the guide's rank pulled halfway to the median there, see
//! `pieces.rs`).
//!
//! Why pieces smaller than the novelty measure's window (64 px, `eval
//! novelty`): what a person recognises as a landform is its shape at that
//! scale, and a piece is a verbatim copy. The start laid blocks as large as
//! the exemplars allowed, so an output was the exemplar's own massifs
//! rearranged — on the 8 shared DEMs 39–69 % of its 64-px windows matched
//! the exemplar at NCC ≥ 0.95 (their own halves: 0–21 %), and a world 3×
//! the exemplar's side showed the same summits again and again. With
//! 32-px pieces no window is one piece; the landforms at that scale are
//! joins of pieces from unrelated places, and the layout of highs and lows
//! is the guide's, new for every seed and every place of a world.
//!
//! The start level is corrected with more passes than the others where
//! the exemplars are smooth at the pixel scale, so the pieces' seams heal
//! there before the finer levels add detail to them (`seams.rs`).
//!
//! Computed on the host for every backend and uploaded: it is small
//! (level L, ⌈W/2^L⌉ × ⌈H/2^L⌉ pixels), so it has no kernel mirror. Every
//! choice is a hash of the seed and the piece's absolute position
//! (DESIGN §6), so any window of a terrain starts from the same pieces.

mod guide;
mod pieces;
mod pool;
pub(super) mod seams;

pub use pieces::pieces;
pub use pool::Pool;

use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, FRAC_BITS};
use crate::level::state::{State, level_size};
use crate::synth::cone::Rect;

/// What the pieces draw from: the database level L of `atlas` and its
/// [`Pool`] (of one exemplar or all).
#[derive(Clone, Copy)]
pub struct Source<'a> {
    pub atlas: &'a AtlasLevel<'a>,
    pub pool: &'a Pool,
}

/// The coarsest level synthesis starts from (and corrects), whatever
/// coarser levels the database holds.
///
/// Why not the database's coarsest level L: synthesis coordinates stay
/// [`MARGIN`](crate::database::layout::MARGIN) texels inside every exemplar
/// at every level, and a level-L texel is 2^L pixels across — at L = 5
/// (the shared DEMs) the outer 64 pixels of every exemplar side, 20–29 %
/// of its area, were never drawn, and that is where those DEMs keep many of
/// their lowest valleys and highest ridges (the output kept 76–85 % of
/// their relief).
///
/// Why level 2 (8 px of each exemplar side out of reach) and not 3: the
/// start is pieces of 32 px (8 texels at level 2, 4 at level 3), and
/// correction joins pieces by levelling the heights across each join. A
/// 4-texel piece is three quarters join, so correcting level 3 levelled
/// the whole start: on the 8 shared DEMs (seeds 11–13) the outputs kept
/// 73–85 % of their relief where the start held 93–97 % (relief ≥ 85 %
/// on 1 of the 8, realism ratio ≤ 1.2 on 5); starting at level 2 they
/// keep 88–95 % (8 of 8) and the ratio is ≤ 1.2 on 7. The blocks the
/// start laid before were 512 px, and level 3 joined them.
pub const MAX_START_LEVEL: usize = 2;

/// How a synthesis starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Start {
    /// The start exemplar's centre at level M (no jitter).
    Centre,
    /// Pieces of `side` level-L texels, made at level L.
    Pieces { side: i32 },
}

impl Start {
    /// The start of an output whose coarsest level is `m`, for a synthesis
    /// whose coarsest corrected level is `l`: pieces of `piece_size` output
    /// pixels (at least a texel) when there is jitter and level L exists
    /// (outputs under 2^(L+1) pixels have no level L), else the centre.
    pub fn choose(jittered: bool, m: usize, l: usize, piece_size: usize) -> Start {
        if jittered && m >= l {
            Start::Pieces {
                side: ((piece_size + (1 << l >> 1)) >> l).max(1) as i32,
            }
        } else {
            Start::Centre
        }
    }

    /// The coarsest synthesized level.
    pub fn top(self, m: usize, l: usize) -> usize {
        match self {
            Start::Centre => m,
            Start::Pieces { .. } => l,
        }
    }
}

/// Level `top` of a `width × height` output without jitter, over `region`
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
