//! [`super::best_of`] in 256-bit AVX2 vectors, for the span's AVX2 copy.
//!
//! Why a second scorer: in `wide`'s 128-bit form a candidate took four
//! 64-bit loads with a bounds check each, sign extensions by unpack and
//! shift, and two narrowings — about 90 instructions per candidate, the
//! largest share of the kernel. Here one candidate is one vector of its
//! four diagonal texels (16 i16 lanes): C₁'s built from two unaligned
//! loads, C₂'s one aligned load of its [`Quad`] (already in this order):
//! - `_mm256_madd_epi16` against (3, 0) and (0, 3) word pairs widens and
//!   triples modes 0/2 and 1/3 of every texel in one instruction each (the
//!   products are exact: |3·m| < 2¹⁷), so N_S is kept in the same
//!   even/odd-mode order ([`Ns256`]);
//! - the texel reads need no bounds checks (see [`candidate_texels`]);
//! - the flat test is one word compare against the broadcast first height.
//!
//! The arithmetic is the scalar `score`'s, step for step: the same i32
//! residuals, the same sum Σ d₁, the same closed form and prior, clamping
//! after the saturating narrowing (as in [`super::score_with`]), and the
//! squares summed by `madd` (16 terms ≤ 9459² each: no i32 overflow).

use super::super::super::{CLAMP, Prior};
use super::super::gather::Pair;
use super::Neighbourhood;
use crate::database::c2::Quad;
use core::arch::x86_64::*;

/// N_S (×3, V on mode 1) in the lane order of a candidate's
/// [`candidate_texels`] after `madd`: `even` holds modes 0 and 2, `odd`
/// modes 1 and 3, of the diagonals (−1,−1), (−1,1) in the low half and
/// (1,−1), (1,1) in the high half.
#[derive(Clone, Copy)]
pub(super) struct Ns256 {
    even: __m256i,
    odd: __m256i,
}

/// [`Ns256`] of a pixel's [`Neighbourhood`] (once per pixel).
#[inline]
#[target_feature(enable = "avx2")]
pub(super) fn ns256(ns: &Neighbourhood) -> Ns256 {
    // ns01: diagonals (−1,−1), (1,−1); ns23: (−1,1), (1,1); four modes each.
    let a: __m256i = wide::bytemuck::cast(ns.ns01);
    let b: __m256i = wide::bytemuck::cast(ns.ns23);
    // Modes 0, 2, 1, 3 within each diagonal, then pair the diagonals.
    let a = _mm256_shuffle_epi32::<0b11_01_10_00>(a);
    let b = _mm256_shuffle_epi32::<0b11_01_10_00>(b);
    Ns256 {
        even: _mm256_unpacklo_epi64(a, b),
        odd: _mm256_unpackhi_epi64(a, b),
    }
}

/// The four diagonal texels of the candidate whose up-left and down-left
/// diagonals are texels `up` and `down` ([`Pair`]), as 16 i16 lanes:
/// (−1,−1), (−1,1) in the low half, (1,−1), (1,1) in the high half.
///
/// # Safety
/// `up … up + 3` and `down … down + 3` must be indices of `app`. Every
/// candidate is an interior coordinate of its exemplar, [`MARGIN`] = 2
/// texels from each edge: C₁ by `AtlasLevel::clamp_interior`, C₂ because
/// the database checks every similarity entry when it is opened
/// (`check_level`). So the rows above and below and the columns up to two
/// to the right lie in the same exemplar, whose texels are all in `app`.
///
/// [`MARGIN`]: crate::database::layout::MARGIN
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn candidate_texels(app: &[u64], up: i32, down: i32) -> __m256i {
    debug_assert!(up >= 0 && ((down + 3) as usize) < app.len());
    let p = app.as_ptr();
    // SAFETY: the caller guarantees both 32-byte reads (texels up … up + 3
    // and down … down + 3) lie in `app`; unaligned loads.
    let (up, down) = unsafe {
        (
            _mm256_loadu_si256(p.offset(up as isize).cast()),
            _mm256_loadu_si256(p.offset(down as isize).cast()),
        )
    };
    // Texels 0 and 2 of each row: the candidate's columns − 1 and + 1.
    _mm256_unpacklo_epi64(up, down)
}

/// A candidate's residuals before its offset is known: `d_even`, `d_odd`
/// as [`Ns256`]'s lanes (N_S − 3·A), and its flat test.
struct Residuals {
    even: __m256i,
    odd: __m256i,
    flat: bool,
}

/// [`Residuals`] of a pair's C₁.
///
/// # Safety
/// As [`candidate_texels`].
#[inline]
#[target_feature(enable = "avx2")]
unsafe fn residuals<const P: u32>(app: &[u64], ns: &Ns256, pair: &Pair) -> Residuals {
    // SAFETY: forwarded from the caller.
    let t = unsafe { candidate_texels(app, pair.up, pair.down) };
    residuals_of::<P>(ns, t)
}

/// [`Residuals`] of the candidate whose diagonal texels are `t`.
#[inline]
#[target_feature(enable = "avx2")]
fn residuals_of<const P: u32>(ns: &Ns256, t: __m256i) -> Residuals {
    // Flat: the four mode-0 words (0, 4, 8, 12) equal word 0.
    let flat = P > 0 && {
        let first = _mm256_broadcastw_epi16(_mm256_castsi256_si128(t));
        let eq = _mm256_movemask_epi8(_mm256_cmpeq_epi16(t, first)) as u32;
        eq & 0x0101_0101 == 0x0101_0101
    };
    Residuals {
        even: _mm256_sub_epi32(ns.even, _mm256_madd_epi16(t, _mm256_set1_epi32(3))),
        odd: _mm256_sub_epi32(ns.odd, _mm256_madd_epi16(t, _mm256_set1_epi32(3 << 16))),
        flat,
    }
}

/// The optimal offset of a candidate with residuals `r` and Σ d₁ = `sum1`,
/// its prior's cost, and its clamped residuals squared and summed in
/// pairs (eight i32 lanes; their sum is the score before the prior).
#[inline]
#[target_feature(enable = "avx2")]
fn fit<const P: u32>(r: &Residuals, sum1: i32, prior: Prior) -> (i32, u32, __m256i) {
    let (prior, h) = Prior { weight: P, ..prior }.fit(r.flat, None, sum1);
    // 3h in the mode-0 lanes (the low half of each 64-bit lane), 0 in the
    // others: one broadcast, no blend.
    let off = _mm256_set1_epi64x(i64::from((3 * h) as u32));
    let d = _mm256_packs_epi32(_mm256_sub_epi32(r.even, off), r.odd);
    let d = _mm256_min_epi16(
        _mm256_max_epi16(d, _mm256_set1_epi16(-CLAMP as i16)),
        _mm256_set1_epi16(CLAMP as i16),
    );
    (h, cost(prior, h), _mm256_madd_epi16(d, d))
}

/// [`Prior::cost`] with one compare: its clamp then square is the square
/// capped at CLAMP², once the square is exact (i64; the product 3(h − V)
/// itself wraps in i32 as in the scalar `score` and the WGSL kernel).
#[inline(always)]
fn cost(prior: Prior, h: i32) -> u32 {
    let r = i64::from(3 * (h - prior.v));
    prior.weight * (r * r).min(i64::from(CLAMP * CLAMP)) as u32
}

/// Score and optimal offset of a pair's C₁ alone (κ = 1), where C₂ does
/// not compete; as [`score_pair`]'s first.
///
/// # Safety
/// As [`candidate_texels`].
#[inline]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn score_c1<const P: u32>(
    app: &[u64],
    ns: &Ns256,
    pair: &Pair,
    prior: Prior,
) -> (u32, i32) {
    // SAFETY: forwarded from the caller.
    let a = unsafe { residuals::<P>(app, ns, pair) };
    // Σ d₁: the mode-0 lanes 0, 2, 4, 6 of `even`.
    let (h, cost, squares) = fit::<P>(&a, lane_sum(a.even), prior);
    // The squares sum to at most 16·9459² < 2³¹; with the prior < 2³².
    (hsum(squares).wrapping_add(cost), h)
}

/// The sum of the eight i32 lanes of `x` (wrapping).
#[inline]
#[target_feature(enable = "avx2")]
fn hsum(x: __m256i) -> u32 {
    let x = _mm_add_epi32(_mm256_castsi256_si128(x), _mm256_extracti128_si256::<1>(x));
    let x = _mm_add_epi32(x, _mm_unpackhi_epi64(x, x));
    _mm_cvtsi128_si32(_mm_add_epi32(x, _mm_shuffle_epi32::<0b01>(x))) as u32
}

/// The sum of lanes 0, 2, 4 and 6 of `x` (i32, wrapping).
#[inline]
#[target_feature(enable = "avx2")]
fn lane_sum(x: __m256i) -> i32 {
    let x = _mm_add_epi32(_mm256_castsi256_si128(x), _mm256_extracti128_si256::<1>(x));
    _mm_cvtsi128_si32(_mm_add_epi32(x, _mm_unpackhi_epi64(x, x)))
}

/// Scores and optimal offsets of a pair's C₁ (κ = 1) and C₂ (κ = 2), as
/// the scalar `score`. Two at a time so that their horizontal sums share
/// shuffles. C₂'s texels are one aligned load from `c2` (its entry is
/// bounds-checked).
///
/// # Safety
/// As [`candidate_texels`], for C₁.
#[inline]
#[target_feature(enable = "avx2")]
pub(super) unsafe fn score_pair<const P: u32>(
    app: &[u64],
    c2: &[Quad],
    ns: &Ns256,
    pair: &Pair,
    prior: Prior,
) -> [(u32, i32); 2] {
    // SAFETY: forwarded from the caller.
    let a = unsafe { residuals::<P>(app, ns, pair) };
    let quad: *const Quad = &c2[pair.u as usize];
    // SAFETY: a `Quad` is 32 bytes, 32-byte aligned.
    let b = residuals_of::<P>(ns, unsafe { _mm256_load_si256(quad.cast()) });
    // Σ d₁ of both: the mode-0 lanes 0, 2, 4, 6 of each `even`,
    // interleaved (a's in even lanes, b's in odd) and summed.
    let x = _mm256_blend_epi32::<0b1010_1010>(a.even, _mm256_slli_epi64::<32>(b.even));
    let x = _mm_add_epi32(_mm256_castsi256_si128(x), _mm256_extracti128_si256::<1>(x));
    let sums = _mm_cvtsi128_si64(_mm_add_epi32(x, _mm_unpackhi_epi64(x, x)));
    let (ha, ca, sa) = fit::<P>(&a, sums as i32, prior);
    let (hb, cb, sb) = fit::<P>(&b, (sums >> 32) as i32, prior);
    // [a, a, b, b | a, a, b, b] → [a, a, b, b] → [a, b, a, b].
    let x = _mm256_hadd_epi32(sa, sb);
    let x = _mm_add_epi32(_mm256_castsi256_si128(x), _mm256_extracti128_si256::<1>(x));
    let sums = _mm_cvtsi128_si64(_mm_hadd_epi32(x, x));
    // The squares sum to at most 16·9459² < 2³¹; with the prior < 2³², and
    // doubled (κ = 2) still (see `CLAMP`).
    let s1 = (sums as u32).wrapping_add(ca);
    let s2 = ((sums >> 32) as u32).wrapping_add(cb) << 1;
    [(s1, ha), (s2, hb)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stages::correct::PRIORS;

    #[test]
    fn the_capped_square_is_the_priors_cost() {
        // Offsets inside the clamp, at it, past it, and far past it (the
        // square of 3(h − V) beyond i32), for every weight.
        let mut x = 0x2545_F491u32;
        let mut next = || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        let edge = CLAMP as u32 / 3;
        for _ in 0..20_000 {
            let scale = [4, edge + 2, 1 << 16, 1 << 28][(next() % 4) as usize];
            let mut within = || (next() % (2 * scale)) as i32 - scale as i32;
            let (h, v) = (within(), within());
            for weight in PRIORS {
                let prior = Prior {
                    weight,
                    v,
                    held: false,
                };
                assert_eq!(cost(prior, h), prior.cost(h), "P {weight}, h {h}, V {v}");
            }
        }
    }
}
