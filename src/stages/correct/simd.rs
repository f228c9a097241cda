//! The fast correction, byte-identical to [`super::scalar`] (tested on
//! real and random states of every size from 2×2).
//!
//! What makes it faster, without changing a single result:
//! - **Index arithmetic.** Every texel the pixel reads lies within one texel
//!   of a coordinate that is interior to its exemplar (two-texel margin), so
//!   after one column-table lookup per neighbour, `A(S(n) − v)` and the
//!   diagonals of a candidate are that index plus `±1 ± stride` — no
//!   per-texel exemplar lookup. Neighbours outside the level (two texels
//!   deep around it) are reflected and extrapolated by the scalar path's
//!   rule once, when the chunk reads them; the extrapolated texel stays
//!   one texel inside its exemplar's interior, so the arithmetic holds.
//! - **Each neighbour read once.** A pixel reads 17 neighbours (3×3 plus
//!   the eight at (±2, ±1), (±1, ±2)); consecutive pixels of a subpass share
//!   half of them, so a chunk of a row reads its neighbours once into a
//!   small grid and the pixels take them from there. Likewise the two N_S
//!   texels of a diagonal that lie in the grid column between two pixels
//!   are summed once for both (8 texel reads per pixel instead of 12).
//!   The grid is a structure of arrays, and the AVX2 copy fills its row
//!   runs four neighbours at a time with one column lookup
//!   (`grid`'s `avx2`).
//! - **C₁ without the clamp.** C₁ = u clamped into u's exemplar's interior
//!   is u itself unless a neighbour's texel lies on the interior's edge;
//!   the fill flags those (1.3 % of the pixels at 1024²), so the rest
//!   list and prefetch C₁ without a column lookup, and only the winner's
//!   coordinate is ever formed — for the rest, S(n) − Δ from the state,
//!   since C₁ is u = t(n) − Δ and takes n's fraction (the grid keeps no
//!   coordinates).
//! - **C₂ without chasing it.** C₂ entries point anywhere in the atlas,
//!   which at level 0 outgrows the L2 cache: reading `similar[u]`, then
//!   the texels it names, were two cache misses in a row per candidate.
//!   The span reads C₂'s four diagonal texels from `AtlasLevel::c2[u]`
//!   instead (gathered once per database, [`crate::database::c2`]),
//!   near `S(p)` like C₁, and looks up `similar[u]` only for a winner
//!   (C₂ won under 0.5 % of the pixels of a 1024² synthesis; at 1024² the
//!   correction ran ~8 % fewer instructions).
//! - **Prefetched candidates.** Candidates are listed a few pixels ahead
//!   of scoring and their texels prefetched (a software pipeline).
//! - **Vector scoring.** The four diagonal texels of a candidate are two
//!   `i16x8` loads; residuals are formed in `i32x8`, clamped to ±[`super::CLAMP`]
//!   (which fits in i16) and squared-and-summed by `i16x8::dot`, the
//!   multiply-add that sums pairs of squares (≤ 2·11584², no overflow).
//! - **A chunk's sources at once.** The AVX2 copy forms every pixel's
//!   nine u and its mask of distinct ones for a whole chunk before the
//!   pixel loop, eight pixels per vector (`gather`'s `avx2`), instead
//!   of per pixel inside it.
//! - **AVX2 where the CPU has it.** The span is compiled twice, for the
//!   SSE2 baseline and for AVX2 with BMI1/BMI2/LZCNT/POPCNT, and picked at
//!   run time (integer arithmetic: the same bytes either way). The AVX2
//!   copy scores with `score::avx2` instead: a candidate's four diagonal
//!   texels in one 256-bit vector, two candidates' horizontal sums shared
//!   (~60 instructions per candidate instead of ~90; at 1024² level 0's
//!   correction took ~4 % less time: much of the rest waits on the
//!   gathered candidates' cache misses).

mod gather;
mod grid;
mod score;

use super::nudge::{nudge, own_detail};
use super::{Guide, ParentRow, Prior, W_FREE, scalar, weigh};
use crate::database::c2::Quad;
use crate::isa::Isa;
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, FRAC_BITS, round};
use crate::level::state::State;
use crate::stages::common::{ALL_TYPES, DELTAS, texel_height};
use gather::{Pending, Table, gather, per_pixel, source_at};
use grid::{CHUNK, Grid};
use score::{Neighbourhood, best_of, column, neighbourhood, score_with};

/// Scoring runs this many pixels behind candidate gathering, so that the
/// cache misses of the (prefetched) candidate texels overlap useful work.
/// Three is enough to hide them. Measured at 1024² (level 0's correction,
/// medians of 8 interleaved runs, shared N_S columns in place): 3 ~125 ms,
/// 4 and 6 ~128, 10 ~137 (prefetched lines wait longer to be used, and
/// the ring of gathered pixels grows).
const LOOKAHEAD: usize = 3;
/// Gathered pixels awaiting scoring: more than [`LOOKAHEAD`], and a power
/// of two so that the ring index is a mask.
const RING: usize = 4;
const _: () = assert!(RING > LOOKAHEAD && RING.is_power_of_two());

/// Corrects the pixels `x0, x0 + 2, … < x1` of the class rows `ys`
/// (consecutive: y, y + 2, …), writing each result as it is found.
///
/// The rows are walked one column chunk at a time, top to bottom, so that
/// each chunk's next row reuses three of the grid rows of the one before
/// (level rows y, y + 1 and y + 2 are rows 2–4 of row y's grid and rows
/// 0–2 of row y + 2's; see `grid::fill` for why they are unchanged):
/// a fill reads two rows of taps instead of 4, each level row once per
/// subpass.
///
/// On x86-64 CPUs with AVX2 the same code runs compiled for AVX2 where
/// `isa` asks for it (the baseline build targets SSE2): the `wide` vectors
/// and the integer arithmetic give the same results on either, only faster.
pub fn correct_span<const P: u32>(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    (ys, x0, x1): (&[usize], usize, usize),
    similar: bool,
    g: &Guide<'_>,
    isa: Isa,
) {
    let span = Span {
        atlas,
        st,
        parent,
        ys,
        x0,
        x1,
        g,
    };
    // A copy of the span per setting: with both scorers in one, the
    // compiler stopped inlining the pair scorer (a call per pair cost
    // level 1 ~8 %).
    #[cfg(target_arch = "x86_64")]
    if isa.avx2() {
        // SAFETY: the CPU supports AVX2, BMI1, BMI2, LZCNT and POPCNT
        // (`Isa::avx2` checks them), the features the function enables.
        unsafe {
            match similar {
                true => span_avx2::<P, true>(&span),
                false => span_avx2::<P, false>(&span),
            }
        };
        return;
    }
    match similar {
        true => run_span::<P, false, true>(&span),
        false => run_span::<P, false, false>(&span),
    }
}

/// The arguments of [`correct_span`].
#[derive(Clone, Copy)]
struct Span<'s> {
    atlas: &'s AtlasLevel<'s>,
    st: &'s State,
    parent: Option<&'s State>,
    ys: &'s [usize],
    x0: usize,
    x1: usize,
    g: &'s Guide<'s>,
}

/// [`run_span`] compiled for AVX2 and the scalar extensions every AVX2 CPU
/// has: BMI's flag-free shifts and `tzcnt` shorten the scalar half of the
/// kernel (candidate listing, the closed-form offset, the prior).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,bmi2,lzcnt,popcnt")]
fn span_avx2<const P: u32, const C2: bool>(span: &Span<'_>) {
    run_span::<P, true, C2>(span);
}

/// [`correct_span`] for any instruction set; `AVX2`: compiled into
/// [`span_avx2`], where the candidates are scored by [`score::avx2`]
/// ([`best_of`]); `C2`: `CorrectParams::similar`.
#[inline(always)]
fn run_span<const P: u32, const AVX2: bool, const C2: bool>(span: &Span<'_>) {
    let (ys, x0, x1) = (span.ys, span.x0, span.x1);
    let mut grid = Grid::new();
    let mut table = Table::new();
    let mut a = x0;
    while a < x1 {
        let b = x1.min(a + 2 * CHUNK);
        for (j, &y) in ys.iter().enumerate() {
            debug_assert!(j == 0 || y == ys[j - 1] + 2);
            let rows = (j > 0, j + 1 < ys.len());
            correct_chunk::<P, AVX2, C2>(span, (y, a, b), rows, (&mut grid, &mut table));
        }
        a = b;
    }
}

/// One chunk `[x0, x1)` of a span. Reading the neighbours up front is safe:
/// a subpass reads only pixels of other parity classes (which it never
/// writes), and each pixel's own coordinate before the pixel is written.
/// `rows`: whether `grid` holds this chunk of class row y − 2, and whether
/// class row y + 2 follows (see [`grid::fill`]).
#[inline(always)]
fn correct_chunk<const P: u32, const AVX2: bool, const C2: bool>(
    span: &Span<'_>,
    (y, x0, x1): (usize, usize, usize),
    rows: (bool, bool),
    (grid, table): (&mut Grid, &mut Table),
) {
    let Span {
        atlas,
        st,
        parent,
        g,
        ..
    } = *span;
    // A local copy: the pixel stores (atomics) then cannot change it, so
    // its tests leave the pixel loop.
    let g = *g;
    let g = &g;
    let w = st.width;
    let n = (x1 - x0).div_ceil(2);
    // True by construction; stated so that the compiler knows every grid
    // column a pixel reads (≤ 2n + 2) is inside the grid.
    assert!(n <= CHUNK);
    grid::fill::<AVX2>(grid, atlas, st, y, x0, n, rows);
    let grid = &*grid;
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: `AVX2` is set only in the span's AVX2 copy, which runs
        // only where the CPU has AVX2.
        unsafe { gather::avx2::tabulate(grid, n, table) };
    }
    let table = &*table;
    let mut ring = [Pending::default(); RING];
    // The parent's offset at each pixel of the chunk, read before the
    // pixel loop (one pass over the two parent rows).
    let mut anchors = [0i32; CHUNK];
    if let Some(pa) = parent {
        // SAFETY: the parent level is not written during its child's
        // correction.
        unsafe { ParentRow::new(pa, y).fill(x0, &mut anchors[..n]) };
    }
    let app = atlas.level.appearance;
    // The shared N_S texels of the grid column left of the next pixel.
    let mut left = column(app, grid, 1);
    for i in 0..n + LOOKAHEAD {
        if i < n {
            let at = ((x0 + 2 * i) as i32, y as i32);
            let (c, out) = (2 * i + 2, &mut ring[i % RING]);
            if AVX2 {
                let source = |k: usize| (table.u[k][i], table.s[k][i]);
                gather(
                    (atlas, st),
                    (grid, c),
                    at,
                    (table.first[i], source),
                    C2,
                    out,
                );
            } else {
                let (u, s, first) = per_pixel(grid, c);
                gather(
                    (atlas, st),
                    (grid, c),
                    at,
                    (first, |k| (u[k], s[k])),
                    C2,
                    out,
                );
            }
        }
        if i >= LOOKAHEAD {
            let k = i - LOOKAHEAD;
            let i = y * w + x0 + 2 * k;
            let right = column(app, grid, 2 * k + 3);
            let ns = neighbourhood(app, grid, 2 * k + 2, &left, &right);
            left = right;
            let prior = Prior {
                weight: P,
                v: anchors[k],
                held: g.targets.is_some_and(|t| t[i].tol >= 0),
            };
            // Type-constrained pixels take the scalar path (rejection and
            // seeding live there; they are few and at coarse levels).
            let (s, v) = match g.allowed {
                Some(a) if a[i] != ALL_TYPES => {
                    let (x, y) = ((x0 + 2 * k) as i32, y as i32);
                    scalar::correct_pixel_guided(atlas, st, (x, y), C2, g, prior)
                }
                _ => {
                    let at = (x0 + 2 * k, y);
                    let p = &ring[k % RING];
                    decide::<P, AVX2>(atlas, st, &ns, at, p, C2, g, prior)
                }
            };
            st.set(i, s, v);
        }
    }
}

/// Scores a gathered pixel's candidates against its synthesis
/// neighbourhood `ns`; returns the winner's coordinate (with the fraction of
/// the neighbour it came from) and optimal offset. `at`: the pixel's level
/// position.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn decide<const P: u32, const AVX2: bool>(
    atlas: &AtlasLevel<'_>,
    st: &State,
    ns: &Neighbourhood,
    at: (usize, usize),
    p: &Pending,
    similar: bool,
    g: &Guide<'_>,
    prior: Prior,
) -> (Coord, i32) {
    let pixel = at.1 * st.width + at.0;
    let app = atlas.level.appearance;
    // The coherence candidate first (a tie keeps the previous result), then
    // the rest in DELTAS order, C₁ before C₂ (ties keep the earlier).
    if let Some(c) = &g.coherence {
        let (prev, v) = (c.coords[pixel], c.offsets[pixel]);
        let w = c.weights[pixel];
        if w == 0 {
            // Frozen: cost 0 cannot be beaten (ties keep the first).
            return (prev, v);
        }
        let col = &atlas.columns[round(prev.x) as usize];
        let idx = col.base + round(prev.y) * col.stride as i32 + round(prev.x);
        // Unweighted: the coordinate, re-fitted and nudged like any other;
        // coherent: the previous result as is.
        let free = w >= W_FREE;
        let fixed = (!free).then_some(v);
        let t = Quad::around(app, idx, col.stride as i32);
        let (sc, h_prev) = score_with::<P>(ns, &t, 1, fixed, prior);
        let bar = weigh(sc, w);
        let (cost, i, hh) = best_of::<P, AVX2>(app, atlas.c2, ns, (p, similar), bar, prior);
        if i == usize::MAX {
            return match free {
                true => (prev, nudged(atlas, (idx, col.stride as i32), h_prev, pixel, g)),
                false => (prev, v),
            };
        }
        return finish(atlas, st, at, p, (cost, i, hh), g);
    }
    let winner = best_of::<P, AVX2>(app, atlas.c2, ns, (p, similar), u32::MAX, prior);
    finish(atlas, st, at, p, winner, g)
}

/// The winner's offset `v`, nudged towards the pixel's geometric target
/// if any (`idx`: the winner's texel).
#[inline(always)]
fn nudged(
    atlas: &AtlasLevel<'_>,
    (idx, stride): (i32, i32),
    v: i32,
    pixel: usize,
    g: &Guide<'_>,
) -> i32 {
    match g.targets {
        Some(t) => {
            let app = atlas.level.appearance;
            let h = texel_height(app[idx as usize]);
            let d = own_detail(g.level, t[pixel], h, |dx, dy| {
                texel_height(app[(idx + dx + dy * stride) as usize])
            });
            nudge(v, h + v - d, t[pixel])
        }
        None => v,
    }
}

/// The winner's coordinate (with the fraction of the neighbour it came
/// from) and its offset, nudged towards a geometric target if any.
#[inline(always)]
fn finish(
    atlas: &AtlasLevel<'_>,
    st: &State,
    (x, y): (usize, usize),
    p: &Pending,
    best: (u32, usize, i32),
    g: &Guide<'_>,
) -> (Coord, i32) {
    debug_assert!(best.1 < p.count);
    let pair = &p.pairs[best.1 / 2];
    let (dx, dy) = DELTAS[pair.from as usize];
    let pixel = y * st.width + x;
    let (s, idx) = match (best.1 % 2, p.edge) {
        // C₁ = u = t(n) − Δ with n's fraction: S(n) − Δ, n inside the
        // level (no edge neighbour: the whole 3×3 is).
        (0, false) => {
            let i = pixel as isize + dy as isize * st.width as isize + dx as isize;
            let n = st.s(i as usize);
            let s = Coord {
                x: n.x - (dx << FRAC_BITS),
                y: n.y - (dy << FRAC_BITS),
            };
            (s, (pair.c1(), (pair.down - pair.up) >> 1))
        }
        (c, _) => {
            let (n, u) = source_at(atlas, st, (x as i32, y as i32), pair.from as usize);
            let q = match c {
                0 => atlas.clamp_interior(u.0, u.1),
                _ => {
                    let c = atlas.level.similar[pair.u as usize];
                    ((c & 0xFFFF) as i32, (c >> 16) as i32)
                }
            };
            let s = Coord {
                x: (q.0 << FRAC_BITS) + n.frac.0,
                y: (q.1 << FRAC_BITS) + n.frac.1,
            };
            let idx = match c {
                0 => pair.c1(),
                _ => atlas.index(q.0, q.1) as i32,
            };
            (s, (idx, atlas.columns[q.0 as usize].stride as i32))
        }
    };
    (s, nudged(atlas, idx, best.2, pixel, g))
}
