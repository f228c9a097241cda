//! The fast correction for pixels at least two texels inside the level,
//! byte-identical to [`super::scalar`] (tested on real and random states).
//!
//! What makes it faster, without changing a single result:
//! - **Index arithmetic.** Every texel the pixel reads lies within one texel
//!   of a coordinate that is interior to its exemplar (two-texel margin), so
//!   after one column-table lookup per neighbour, `A(S(n) − v)` and the
//!   diagonals of a candidate are that index plus `±1 ± stride` — no
//!   per-texel exemplar lookup, no border reflection (interior pixels never
//!   reflect).
//! - **Each neighbour read once.** A pixel reads 17 neighbours (3×3 plus
//!   the eight at (±2, ±1), (±1, ±2)); consecutive pixels of a subpass share
//!   half of them, so a chunk of a row reads its neighbours once into a
//!   small grid and the pixels take them from there.
//! - **Prefetched candidates.** C₂ entries point anywhere in the atlas; at
//!   level 0 the atlas outgrows the L2 cache and scoring them one by one
//!   would serialise cache misses. Candidates are listed a few pixels ahead
//!   of scoring and their texels prefetched (a software pipeline), and the
//!   similarity entries a few pixels ahead of listing.
//! - **Vector scoring.** The four diagonal texels of a candidate are two
//!   `i16x8` loads; residuals are formed in `i32x8`, clamped to ±[`CLAMP`]
//!   (which fits in i16) and squared-and-summed by `i16x8::dot`, the
//!   multiply-add that sums pairs of squares (≤ 2·11584², no overflow).
//! - **AVX2 where the CPU has it.** The span is compiled twice, for the
//!   SSE2 baseline and for AVX2, and picked at run time (integer
//!   arithmetic: the same bytes either way).

use super::nudge::nudge;
use super::{ALL_TYPES, CLAMP, DELTAS, DIAGONALS, FLAT, Guide, Prior, W_FREE, scalar, weigh};
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, FRAC_BITS, round};
use crate::level::state::State;
use wide::{i16x8, i32x8};

/// A neighbour as the kernel needs it.
#[derive(Clone, Copy, Default)]
struct Tap {
    /// Texel index of the rounded coordinate.
    idx: i32,
    /// Row stride of its exemplar.
    stride: i32,
    /// Rounded coordinate.
    sx: i32,
    sy: i32,
    /// Height offset V.
    v: i32,
}

#[inline(always)]
fn tap(atlas: &AtlasLevel<'_>, st: &State, i: usize) -> Tap {
    let s = st.s(i);
    let (sx, sy) = (round(s.x), round(s.y));
    let col = &atlas.columns[sx as usize];
    Tap {
        idx: col.base + sy * col.stride as i32 + sx,
        stride: col.stride as i32,
        sx,
        sy,
        v: st.v(i),
    }
}

/// Two packed appearance texels as eight i16 lanes.
#[inline(always)]
fn pair(app: &[u64], a: i32, b: i32) -> i16x8 {
    wide::bytemuck::cast([app[a as usize], app[b as usize]])
}

/// The synthesis neighbourhood N_S (×3), two diagonals per vector, mode 1
/// including the offsets V.
#[derive(Clone, Copy)]
struct Neighbourhood {
    ns01: i32x8,
    ns23: i32x8,
}

/// Score (×κ) and optimal offset of the candidate whose texel index is
/// `q` in an exemplar of row stride `s` (same arithmetic as the scalar
/// `score`; the prior's weight P is a constant, so its closed form divides
/// by a constant).
#[inline(always)]
fn score<const P: u32>(
    app: &[u64],
    ns: &Neighbourhood,
    q: i32,
    s: i32,
    kappa: u32,
    vp: i32,
) -> (u32, i32) {
    score_with::<P>(app, ns, q, s, kappa, None, vp)
}

/// [`score`] with the offset fixed to `fixed` when given (a coherent
/// previous result keeps its own offset).
#[inline(always)]
fn score_with<const P: u32>(
    app: &[u64],
    ns: &Neighbourhood,
    q: i32,
    s: i32,
    kappa: u32,
    fixed: Option<i32>,
    vp: i32,
) -> (u32, i32) {
    // DIAGONALS order: (−1,−1), (1,−1), (−1,1), (1,1).
    let m01 = i32x8::from_i16x8(pair(app, q - s - 1, q - s + 1));
    let m23 = i32x8::from_i16x8(pair(app, q + s - 1, q + s + 1));
    let d01 = ns.ns01 - (m01 + m01 + m01);
    let d23 = ns.ns23 - (m23 + m23 + m23);
    let (a, b) = (d01.to_array(), d23.to_array());
    let (ma, mb) = (m01.to_array(), m23.to_array());
    let sum1 = a[0] + a[4] + b[0] + b[4];
    // Both priors have constant weights, so each closed form divides by a
    // constant (the branch picks one, never a run-time divisor).
    let flat = Prior { weight: P, v: vp }.for_candidate([ma[0], ma[4], mb[0], mb[4]]) == FLAT;
    let prior = if flat {
        FLAT
    } else {
        Prior { weight: P, v: vp }
    };
    let h = fixed.unwrap_or_else(|| {
        if flat {
            FLAT.optimal(sum1)
        } else {
            Prior { weight: P, v: vp }.optimal(sum1)
        }
    });
    let h3 = 3 * h;
    let off = i32x8::new([h3, 0, 0, 0, h3, 0, 0, 0]);
    // Clamping after the saturating narrowing equals clamping before it
    // (saturation is monotone and ±CLAMP lies inside i16), and i16 min/max
    // are single instructions where i32 ones are not (SSE2).
    let lo = i16x8::splat(-CLAMP as i16);
    let hi = i16x8::splat(CLAMP as i16);
    let r01 = i16x8::from_i32x8_saturate(d01 - off).max(lo).min(hi);
    let r23 = i16x8::from_i32x8_saturate(d23 - off).max(lo).min(hi);
    let sums = (r01.dot(r01) + r23.dot(r23)).to_array();
    let s = (sums[0] as u32)
        .wrapping_add(sums[1] as u32)
        .wrapping_add(sums[2] as u32)
        .wrapping_add(sums[3] as u32)
        .wrapping_add(prior.cost(h));
    (s * kappa, h)
}

/// Class pixels per chunk: a chunk's neighbours are read once into a small
/// grid (5 rows × 2·CHUNK + 4 columns, ~16 KiB, in L1) that consecutive
/// pixels share — a 3×3 block and its ring overlap the next pixel's by half.
const CHUNK: usize = 64;
const GRID_COLS: usize = 2 * CHUNK + 4;

/// Scoring runs this many pixels behind candidate gathering, so that the
/// cache misses of the (prefetched) candidate texels overlap useful work.
const LOOKAHEAD: usize = 6;
const RING: usize = LOOKAHEAD + 1;

/// A pixel whose candidates are gathered, awaiting scoring.
#[derive(Clone, Copy, Default)]
struct Pending {
    cands: [Candidate; 18],
    count: usize,
}

/// Corrects the pixels `x0, x0 + 2, … < x1` of row `y`, all at least two
/// texels inside the level, writing each result as it is found.
///
/// On x86-64 CPUs with AVX2 the same code runs compiled for AVX2 (picked at
/// run time; the baseline build targets SSE2): the `wide` vectors and the
/// integer arithmetic give the same results on either, only faster.
pub fn correct_span<const P: u32>(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    y: usize,
    x0: usize,
    x1: usize,
    g: &Guide<'_>,
) {
    let span = Span {
        atlas,
        st,
        parent,
        y,
        x0,
        x1,
        g,
    };
    #[cfg(target_arch = "x86_64")]
    if std::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU supports AVX2, the one feature the function
        // enables (checked just above).
        unsafe { span_avx2::<P>(&span) };
        return;
    }
    run_span::<P>(&span);
}

/// The arguments of [`correct_span`].
#[derive(Clone, Copy)]
struct Span<'s> {
    atlas: &'s AtlasLevel<'s>,
    st: &'s State,
    parent: Option<&'s State>,
    y: usize,
    x0: usize,
    x1: usize,
    g: &'s Guide<'s>,
}

/// [`run_span`] compiled for AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn span_avx2<const P: u32>(span: &Span<'_>) {
    run_span::<P>(span);
}

/// [`correct_span`] for any instruction set.
#[inline(always)]
fn run_span<const P: u32>(span: &Span<'_>) {
    let Span {
        atlas,
        st,
        parent,
        y,
        x0,
        x1,
        g,
    } = *span;
    let mut grid = [[Tap::default(); GRID_COLS]; 5];
    let mut a = x0;
    while a < x1 {
        let b = x1.min(a + 2 * CHUNK);
        correct_chunk::<P>(atlas, st, parent, y, a, b, &mut grid, g);
        a = b;
    }
}

/// One chunk `[x0, x1)` of a span. Reading the neighbours up front is safe:
/// a subpass reads only pixels of other parity classes (which it never
/// writes), and each pixel's own coordinate before the pixel is written.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn correct_chunk<const P: u32>(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    y: usize,
    x0: usize,
    x1: usize,
    grid: &mut [[Tap; GRID_COLS]; 5],
    g: &Guide<'_>,
) {
    let w = st.width;
    let n = (x1 - x0).div_ceil(2);
    // True by construction; stated so that the compiler knows every grid
    // column a pixel reads (≤ 2n + 2) is inside the grid.
    assert!(n <= CHUNK);
    // Grid column j is level column x0 − 2 + j; grid row r is level row
    // y − 2 + r. Rows y ± 2 are read only at odd offsets from the class.
    let cols = 2 * n + 3;
    for (r, row) in grid.iter_mut().enumerate() {
        let base = (y + r - 2) * w + x0 - 2;
        if r == 0 || r == 4 {
            for j in 0..cols / 2 {
                row[2 * j + 1] = tap(atlas, st, base + 2 * j + 1);
            }
        } else {
            for (j, t) in row[..cols].iter_mut().enumerate() {
                *t = tap(atlas, st, base + j);
            }
        }
    }
    let grid = &*grid;
    let mut ring = [Pending::default(); RING];
    for i in 0..n + LOOKAHEAD {
        if i + LOOKAHEAD < n {
            prefetch_similar(atlas, grid, 2 * (i + LOOKAHEAD) + 2);
        }
        if i < n {
            gather(atlas, grid, 2 * i + 2, &mut ring[i % RING]);
        }
        if i >= LOOKAHEAD {
            let k = i - LOOKAHEAD;
            let i = y * w + x0 + 2 * k;
            let prior = Prior::at(P, parent, x0 + 2 * k, y);
            // Type-constrained pixels take the scalar path (rejection and
            // seeding live there; they are few and at coarse levels).
            let (s, v) = match g.allowed {
                Some(a) if a[i] != ALL_TYPES => {
                    let (x, y) = ((x0 + 2 * k) as i32, y as i32);
                    scalar::correct_pixel_guided(atlas, st, x, y, g, prior)
                }
                _ => decide::<P>(atlas, st, grid, 2 * k + 2, i, &ring[k % RING], g, prior.v),
            };
            st.set(i, s, v);
        }
    }
}

/// The 5×5 neighbours of one pixel: rows y − 2 … y + 2, columns x − 2 …
/// x + 2 (not all are read). Taken once per use, so that the reads at
/// constant offsets need no bounds checks of their own.
type Window<'g> = [&'g [Tap; 5]; 5];

/// The [`Window`] of the pixel in grid column `c`.
#[inline(always)]
fn window(grid: &[[Tap; GRID_COLS]; 5], c: usize) -> Window<'_> {
    grid.each_ref().map(|row| {
        row[c - 2..c + 3]
            .try_into()
            .expect("a pixel's window is 5 columns wide")
    })
}

/// The neighbour at offset (dx, dy) of the window's pixel.
#[inline(always)]
fn at<'g>(win: &Window<'g>, dx: i32, dy: i32) -> &'g Tap {
    &win[(2 + dy) as usize][(2 + dx) as usize]
}

/// Prefetches the similarity entries the gathering of the pixel in grid
/// column `c` will read, those of `u = S(p + Δ) − Δ` for the three Δ of
/// its column (in a coherent patch all nine u coincide with these). The
/// first read of an atlas row near u is this one: gathering's own
/// prefetches cover only the texels that scoring reads later, and the
/// profile showed the `similar` load as the costliest instruction.
#[inline(always)]
fn prefetch_similar(atlas: &AtlasLevel<'_>, grid: &[[Tap; GRID_COLS]; 5], c: usize) {
    let similar = atlas.level.similar;
    let win = window(grid, c);
    for dy in -1..=1 {
        let n = at(&win, 0, dy);
        prefetch(similar, n.idx - dy * n.stride);
    }
}

/// Lists the candidates of the pixel in grid column `c` (C₁ and C₂ of every
/// distinct `u = S(p+Δ) − Δ`, in DELTAS order) and prefetches the texels
/// scoring will read: C₂ entries point anywhere in the atlas, and at level 0
/// the atlas is larger than the L2 cache.
#[inline(always)]
fn gather(atlas: &AtlasLevel<'_>, grid: &[[Tap; GRID_COLS]; 5], c: usize, out: &mut Pending) {
    let win = window(grid, c);
    let mut seen = Seen {
        idx: [0; 9],
        distinct: 0,
    };
    out.count = 0;
    // One call per Δ, so that each is compiled with its Δ as a constant.
    gather_delta::<0>(atlas, &win, &mut seen, out);
    gather_delta::<1>(atlas, &win, &mut seen, out);
    gather_delta::<2>(atlas, &win, &mut seen, out);
    gather_delta::<3>(atlas, &win, &mut seen, out);
    gather_delta::<4>(atlas, &win, &mut seen, out);
    gather_delta::<5>(atlas, &win, &mut seen, out);
    gather_delta::<6>(atlas, &win, &mut seen, out);
    gather_delta::<7>(atlas, &win, &mut seen, out);
    gather_delta::<8>(atlas, &win, &mut seen, out);
}

/// Texel indices of the distinct u of a pixel so far: u lies in the
/// exemplar of S(n), one texel from its interior, so its index identifies
/// it.
struct Seen {
    idx: [i32; 9],
    distinct: usize,
}

/// [`gather`]'s step for Δ = `DELTAS[K]`: C₁ and C₂ of its u unless an
/// earlier Δ had the same u.
#[inline(always)]
fn gather_delta<const K: usize>(
    atlas: &AtlasLevel<'_>,
    win: &Window<'_>,
    seen: &mut Seen,
    out: &mut Pending,
) {
    let app = atlas.level.appearance;
    let (dx, dy) = DELTAS[K];
    let n = at(win, dx, dy);
    let u_idx = n.idx - dx - dy * n.stride;
    if seen.idx[..seen.distinct].contains(&u_idx) {
        return;
    }
    seen.idx[seen.distinct] = u_idx;
    seen.distinct += 1;
    let count = out.count;
    // C₁: u clamped into its exemplar's interior (same exemplar as S(n)).
    let u = (n.sx - dx, n.sy - dy);
    let (cx, cy) = atlas.clamp_interior(u.0, u.1);
    out.cands[count] = Candidate {
        idx: u_idx + (cx - u.0) + (cy - u.1) * n.stride,
        stride: n.stride,
        x: cx,
        y: cy,
        from: K as u8,
        kappa: 1,
    };
    // C₂: the stored best other match, anywhere in the atlas.
    let c2 = atlas.level.similar[u_idx as usize];
    let (qx, qy) = ((c2 & 0xFFFF) as i32, (c2 >> 16) as i32);
    let col = &atlas.columns[qx as usize];
    out.cands[count + 1] = Candidate {
        idx: col.base + qy * col.stride as i32 + qx,
        stride: col.stride as i32,
        x: qx,
        y: qy,
        from: K as u8,
        kappa: 2,
    };
    // Scoring reads q − s ± 1 and q + s ± 1: two texels apart, on two
    // lines of one row when they straddle a cache line (a quarter of the
    // time). C₂ lands anywhere, so both of its lines are asked for; C₁ is
    // near S(p), whose lines N_S reads anyway.
    for q in &out.cands[count..count + 2] {
        prefetch(app, q.idx - q.stride - 1);
        prefetch(app, q.idx + q.stride - 1);
    }
    let q = &out.cands[count + 1];
    prefetch(app, q.idx - q.stride + 1);
    prefetch(app, q.idx + q.stride + 1);
    out.count = count + 2;
}

/// Scores a gathered pixel's candidates against its synthesis
/// neighbourhood; returns the winner's coordinate (with the fraction of
/// the neighbour it came from) and optimal offset.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn decide<const P: u32>(
    atlas: &AtlasLevel<'_>,
    st: &State,
    grid: &[[Tap; GRID_COLS]; 5],
    c: usize,
    pixel: usize,
    p: &Pending,
    g: &Guide<'_>,
    vp: i32,
) -> (Coord, i32) {
    let app = atlas.level.appearance;
    let ns = &neighbourhood(app, grid, c);
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
        let (sc, h_prev) = score_with::<P>(app, ns, idx, col.stride as i32, 1, fixed, vp);
        let (cost, i, hh) = best_of::<P>(app, ns, p, weigh(sc, w), vp);
        if i == usize::MAX {
            return match free {
                true => (prev, nudged(atlas, idx, h_prev, pixel, g)),
                false => (prev, v),
            };
        }
        return finish(atlas, st, pixel, p, (cost, i, hh), g);
    }
    let winner = best_of::<P>(app, ns, p, u32::MAX, vp);
    finish(atlas, st, pixel, p, winner, g)
}

/// N_S (eq. 5–6) of the pixel in grid column `c`: per diagonal δ,
/// g(p+δ, v) = A(S(p+δ+v) − v) + V(p+δ+v)·a for v ∈ {0, (δx, 0), (0, δy)}.
/// Two diagonals per vector, three texels each; V joins mode 1.
#[inline(always)]
fn neighbourhood(app: &[u64], grid: &[[Tap; GRID_COLS]; 5], c: usize) -> Neighbourhood {
    let win = window(grid, c);
    Neighbourhood {
        ns01: diagonals(app, &win, 0),
        ns23: diagonals(app, &win, 2),
    }
}

/// Diagonals k and k + 1 of N_S, summed, as one vector.
#[inline(always)]
fn diagonals(app: &[u64], win: &Window<'_>, k: usize) -> i32x8 {
    let ((t0, v0), (t1, v1)) = (diagonal(app, win, k), diagonal(app, win, k + 1));
    let mut sum = i32x8::new([v0, 0, 0, 0, v1, 0, 0, 0]);
    for j in 0..3 {
        sum += i32x8::from_i16x8(wide::bytemuck::cast([t0[j], t1[j]]));
    }
    sum
}

/// Diagonal k of N_S: its three appearance texels and their ΣV.
#[inline(always)]
fn diagonal(app: &[u64], win: &Window<'_>, k: usize) -> ([u64; 3], i32) {
    let (dx, dy) = DIAGONALS[k];
    let a = at(win, dx, dy);
    let b = at(win, 2 * dx, dy);
    let cc = at(win, dx, 2 * dy);
    let texels = [
        app[a.idx as usize],
        app[(b.idx - dx) as usize],
        app[(cc.idx - dy * cc.stride) as usize],
    ];
    (texels, a.v + b.v + cc.v)
}

/// The winner's offset `v`, nudged towards the pixel's geometric target
/// if any (`idx`: the winner's texel).
#[inline(always)]
fn nudged(atlas: &AtlasLevel<'_>, idx: i32, v: i32, pixel: usize, g: &Guide<'_>) -> i32 {
    match g.targets {
        Some(t) => {
            let h_c = scalar::texel_height(atlas.level.appearance[idx as usize]) + v;
            nudge(v, h_c, t[pixel])
        }
        None => v,
    }
}

/// The best gathered candidate whose cost is below `bar`:
/// (cost, index, optimal offset), index `usize::MAX` if none is.
#[inline(always)]
fn best_of<const P: u32>(
    app: &[u64],
    ns: &Neighbourhood,
    p: &Pending,
    bar: u32,
    vp: i32,
) -> (u32, usize, i32) {
    let mut best = (bar, usize::MAX, 0i32);
    for (i, c) in p.cands[..p.count].iter().enumerate() {
        let (sc, hh) = score::<P>(app, ns, c.idx, c.stride, c.kappa, vp);
        if sc < best.0 {
            best = (sc, i, hh);
        }
    }
    best
}

/// The winner's coordinate (with the fraction of the neighbour it came
/// from) and its offset, nudged towards a geometric target if any.
#[inline(always)]
fn finish(
    atlas: &AtlasLevel<'_>,
    st: &State,
    pixel: usize,
    p: &Pending,
    best: (u32, usize, i32),
    g: &Guide<'_>,
) -> (Coord, i32) {
    debug_assert!(best.1 < p.count);
    let q = p.cands[best.1];
    let (dx, dy) = DELTAS[q.from as usize];
    let n = st.s((pixel as isize + dy as isize * st.width as isize + dx as isize) as usize);
    let frac = |v: i32| v - (round(v) << FRAC_BITS);
    let s = Coord {
        x: (q.x << FRAC_BITS) + frac(n.x),
        y: (q.y << FRAC_BITS) + frac(n.y),
    };
    (s, nudged(atlas, q.idx, best.2, pixel, g))
}

/// One candidate of the pixel being corrected.
#[derive(Clone, Copy, Default)]
struct Candidate {
    /// Texel index and row stride.
    idx: i32,
    stride: i32,
    /// Atlas texel.
    x: i32,
    y: i32,
    /// Index into DELTAS of the neighbour it came from.
    from: u8,
    kappa: u32,
}

/// [`prefetch_line`] for element `i` of `table`. The address is only
/// formed, never read, so it needs no bounds check (prefetching is a hint
/// that cannot fault).
#[inline(always)]
fn prefetch<T>(table: &[T], i: i32) {
    prefetch_line(table.as_ptr().wrapping_offset(i as isize).cast());
}

/// Asks the cache for the line holding `t` (a hint: no effect on results).
#[inline(always)]
fn prefetch_line(t: *const i8) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: `prefetch` only hints the cache; it cannot fault or change
    // memory, and SSE is part of the x86_64 baseline.
    unsafe {
        use core::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(t);
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = t;
}
