//! Scoring (paper eq. 7): the synthesis neighbourhood N_S of a pixel and
//! the cost of each gathered candidate against it, two diagonals per
//! vector.

use super::super::{CLAMP, DIAGONALS, Prior};
use super::gather::Pending;
use super::grid::{Grid, at, window};
use crate::database::c2::Quad;
use wide::{i16x8, i32x4, i32x8};

#[cfg(target_arch = "x86_64")]
pub(super) mod avx2;

/// The synthesis neighbourhood N_S (×3), two diagonals per vector, mode 1
/// including the offsets V.
#[derive(Clone, Copy)]
pub(super) struct Neighbourhood {
    ns01: i32x8,
    ns23: i32x8,
}

/// Score (×κ) and optimal offset of the candidate whose diagonal texels
/// are `t` (same arithmetic as the scalar `score`; the prior's weight P is
/// a constant, so its closed form divides by a constant), with the offset
/// fixed to `fixed` when given (a coherent previous result keeps its own
/// offset).
#[inline(always)]
pub(super) fn score_with<const P: u32>(
    ns: &Neighbourhood,
    t: &Quad,
    kappa: u32,
    fixed: Option<i32>,
    prior: Prior,
) -> (u32, i32) {
    // DIAGONALS order: (−1,−1), (1,−1), (−1,1), (1,1).
    let [a, b, c, d] = t.0;
    let m01 = i32x8::from_i16x8(wide::bytemuck::cast([a, c]));
    let m23 = i32x8::from_i16x8(wide::bytemuck::cast([b, d]));
    let d01 = ns.ns01 - (m01 + m01 + m01);
    let d23 = ns.ns23 - (m23 + m23 + m23);
    let (a, b) = (d01.to_array(), d23.to_array());
    let (ma, mb) = (m01.to_array(), m23.to_array());
    let sum1 = a[0] + a[4] + b[0] + b[4];
    // P, FLAT's and FLAT_FIT's weights are constants, so each closed form
    // divides by a constant (`Prior::fit` picks one, never a run-time
    // divisor).
    let prior = Prior { weight: P, ..prior };
    let (prior, h) = prior.fit(prior.is_flat([ma[0], ma[4], mb[0], mb[4]]), fixed, sum1);
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

/// N_S (eq. 5–6) of the pixel in grid column `c`: per diagonal δ,
/// g(p+δ, v) = A(S(p+δ+v) − v) + V(p+δ+v)·a for v ∈ {0, (δx, 0), (0, δy)}.
/// Two diagonals per vector, three texels each; V joins mode 1. Two of a
/// diagonal's texels lie in the grid column c + δx, which the pixels on
/// either side of it share: they come summed in `left` and `right`
/// ([`column`](fn@column) of c − 1 and c + 1); only v = (δx, 0) is read here.
#[inline(always)]
pub(super) fn neighbourhood(
    app: &[u64],
    grid: &Grid,
    c: usize,
    left: &Column,
    right: &Column,
) -> Neighbourhood {
    let [up_l, down_l] = *left;
    let [up_r, down_r] = *right;
    Neighbourhood {
        ns01: wide::bytemuck::cast::<_, i32x8>([up_l, up_r]) + outer(app, grid, c, 0),
        ns23: wide::bytemuck::cast::<_, i32x8>([down_l, down_r]) + outer(app, grid, c, 2),
    }
}

/// The texels of N_S that grid column j (odd) gives the diagonals of both
/// pixels beside it, per δy (−1, then 1): A(S(p+δ)) and A(S(p+δ+(0, δy)) −
/// (0, δy)), summed, with their V on mode 1. Consecutive pixels of a
/// subpass are two columns apart, so each such sum serves two pixels and
/// is formed once.
pub(super) type Column = [i32x4; 2];

/// The [`Column`] of grid column `j`.
#[inline(always)]
pub(super) fn column(app: &[u64], grid: &Grid, j: usize) -> Column {
    // Rows 1 and 0 (δy = −1), rows 3 and 4 (δy = 1); the pixel's row is 2.
    let (idx, stride, v) = (&grid.idx, &grid.stride, &grid.v);
    let near = [app[idx[1][j] as usize], app[idx[3][j] as usize]];
    let far = [
        app[(idx[0][j] + stride[0][j]) as usize],
        app[(idx[4][j] - stride[4][j]) as usize],
    ];
    let v = i32x8::new([v[1][j] + v[0][j], 0, 0, 0, v[3][j] + v[4][j], 0, 0, 0]);
    let sum = i32x8::from_i16x8(wide::bytemuck::cast(near))
        + i32x8::from_i16x8(wide::bytemuck::cast(far))
        + v;
    wide::bytemuck::cast(sum)
}

/// The texels of N_S's diagonals k and k + 1 (δy alike) at v = (δx, 0),
/// with their V on mode 1, as one vector.
#[inline(always)]
fn outer(app: &[u64], grid: &Grid, c: usize, k: usize) -> i32x8 {
    let (idx, v) = (window(&grid.idx, c), window(&grid.v, c));
    let texel = |k: usize| {
        let (dx, dy) = DIAGONALS[k];
        (
            app[(at(&idx, 2 * dx, dy) - dx) as usize],
            at(&v, 2 * dx, dy),
        )
    };
    let ((t0, v0), (t1, v1)) = (texel(k), texel(k + 1));
    i32x8::from_i16x8(wide::bytemuck::cast([t0, t1])) + i32x8::new([v0, 0, 0, 0, v1, 0, 0, 0])
}

/// The best gathered candidate whose cost is below `bar`:
/// (cost, index, optimal offset), index `usize::MAX` if none is; C₂
/// candidates only if `similar`. `AVX2`: in the span's AVX2 copy, by
/// [`avx2`]'s scorer (the same candidates in the same order, the same
/// strict `<`: ties keep the earlier).
///
/// The dispatch is a constant, not a `#[target_feature]` function: those
/// cannot be `#[inline(always)]`, and left to itself the compiler called
/// the AVX2 loop once per pixel instead of inlining it.
#[inline(always)]
pub(super) fn best_of<const P: u32, const AVX2: bool>(
    app: &[u64],
    c2: &[Quad],
    ns: &Neighbourhood,
    (p, similar): (&Pending, bool),
    bar: u32,
    prior: Prior,
) -> (u32, usize, i32) {
    let mut best = (bar, usize::MAX, 0i32);
    let pairs = &p.pairs[..p.count / 2];
    #[cfg(target_arch = "x86_64")]
    if AVX2 {
        // SAFETY: `AVX2` is set only in the span's AVX2 copy, which runs
        // only where the CPU has AVX2.
        let ns = unsafe { avx2::ns256(ns) };
        if !similar {
            for (j, pair) in pairs.iter().enumerate() {
                // SAFETY: the CPU has AVX2 (as above) and C₁ is an
                // interior coordinate (see `avx2::score_pair`).
                let (sc, hh) = unsafe { avx2::score_c1::<P>(app, &ns, pair, prior) };
                if sc < best.0 {
                    best = (sc, 2 * j, hh);
                }
            }
            return best;
        }
        for (j, pair) in pairs.iter().enumerate() {
            // SAFETY: the CPU has AVX2 (as above), C₁ is an interior
            // coordinate (see `avx2::score_pair`) and u a texel.
            let scored = unsafe { avx2::score_pair::<P>(app, c2, &ns, pair, prior) };
            for (i, (sc, hh)) in scored.into_iter().enumerate() {
                if sc < best.0 {
                    best = (sc, 2 * j + i, hh);
                }
            }
        }
        return best;
    }
    for (j, pair) in pairs.iter().enumerate() {
        let c1 = Quad::beside(app, pair.up, pair.down);
        let (sc, hh) = score_with::<P>(ns, &c1, 1, None, prior);
        if sc < best.0 {
            best = (sc, 2 * j, hh);
        }
        if similar {
            let (sc, hh) = score_with::<P>(ns, &c2[pair.u as usize], 2, None, prior);
            if sc < best.0 {
                best = (sc, 2 * j + 1, hh);
            }
        }
    }
    best
}
