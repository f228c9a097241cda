//! The vector part of a candidate's score: its residuals against N_S and
//! their clamped squares, in 128-bit `wide` vectors on any CPU
//! ([`Portable`]) or in 256-bit AVX2 vectors ([`Avx2`], the AVX2 copy of
//! the span only). Why two: `wide` picks its implementation when the crate
//! is compiled, for the SSE2 baseline, so in the AVX2 copy each of its
//! 8-lane operations stayed two 128-bit instructions (a sign extension
//! four); with 256-bit vectors a candidate's score takes about a sixth
//! fewer instructions. Both compute the same integers.

use super::super::CLAMP;
use wide::{i16x8, i32x8};

/// A candidate's residuals d = N_S − 3·N_E (×3 units), two diagonals per
/// 8-lane half, modes in lanes 0–3 and 4–7.
pub(super) trait Lanes: Copy {
    /// The residuals of the candidate whose four diagonal texels (packed
    /// modes, DIAGONALS order) are `t` against N_S = (`ns01`, `ns23`).
    fn residuals(ns01: i32x8, ns23: i32x8, t: [u64; 4]) -> Self;
    /// Σ over the diagonals of the mode-1 residual.
    fn sum1(&self) -> i32;
    /// Σ of the squared residuals, mode 1 less `h3` = 3h, each clamped to
    /// ±[`CLAMP`] (wrapping in 32 bits, as the scalar sum does).
    fn squares(&self, h3: i32) -> u32;
}

/// [`Lanes`] in `wide` vectors: the SSE2 baseline (and other CPUs).
#[derive(Clone, Copy)]
pub(super) struct Portable {
    d01: i32x8,
    d23: i32x8,
}

impl Lanes for Portable {
    #[inline(always)]
    fn residuals(ns01: i32x8, ns23: i32x8, t: [u64; 4]) -> Self {
        let pair = |a: u64, b: u64| i32x8::from_i16x8(wide::bytemuck::cast([a, b]));
        let (m01, m23) = (pair(t[0], t[1]), pair(t[2], t[3]));
        Portable {
            d01: ns01 - (m01 + m01 + m01),
            d23: ns23 - (m23 + m23 + m23),
        }
    }

    #[inline(always)]
    fn sum1(&self) -> i32 {
        let (a, b) = (self.d01.to_array(), self.d23.to_array());
        a[0] + a[4] + b[0] + b[4]
    }

    #[inline(always)]
    fn squares(&self, h3: i32) -> u32 {
        let off = i32x8::new([h3, 0, 0, 0, h3, 0, 0, 0]);
        // Clamping after the saturating narrowing equals clamping before it
        // (saturation is monotone and ±CLAMP lies inside i16), and i16
        // min/max are single instructions where i32 ones are not (SSE2).
        let lo = i16x8::splat(-CLAMP as i16);
        let hi = i16x8::splat(CLAMP as i16);
        let r01 = i16x8::from_i32x8_saturate(self.d01 - off).max(lo).min(hi);
        let r23 = i16x8::from_i32x8_saturate(self.d23 - off).max(lo).min(hi);
        let sums = (r01.dot(r01) + r23.dot(r23)).to_array();
        (sums[0] as u32)
            .wrapping_add(sums[1] as u32)
            .wrapping_add(sums[2] as u32)
            .wrapping_add(sums[3] as u32)
    }
}

#[cfg(target_arch = "x86_64")]
pub(super) use avx2::Avx2;

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{CLAMP, Lanes, i32x8};
    use core::arch::x86_64::*;

    /// [`Lanes`] in 256-bit AVX2 vectors. Used only by the AVX2 copy of
    /// the span, which runs only where the CPU has AVX2.
    #[derive(Clone, Copy)]
    pub(in super::super) struct Avx2 {
        d01: __m256i,
        d23: __m256i,
    }

    impl Lanes for Avx2 {
        #[inline(always)]
        fn residuals(ns01: i32x8, ns23: i32x8, t: [u64; 4]) -> Self {
            // SAFETY: `Avx2` is used only in the span compiled for AVX2,
            // which runs only after `isa::avx2` found it.
            unsafe { residuals(ns01, ns23, t) }
        }

        #[inline(always)]
        fn sum1(&self) -> i32 {
            // SAFETY: as in `residuals`.
            unsafe { sum1(self) }
        }

        #[inline(always)]
        fn squares(&self, h3: i32) -> u32 {
            // SAFETY: as in `residuals`.
            unsafe { squares(self, h3) }
        }
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn residuals(ns01: i32x8, ns23: i32x8, t: [u64; 4]) -> Avx2 {
        let v = |x: i32x8| -> __m256i { wide::bytemuck::cast(x) };
        let m = |a: u64, b: u64| _mm256_cvtepi16_epi32(_mm_set_epi64x(b as i64, a as i64));
        let (m01, m23) = (m(t[0], t[1]), m(t[2], t[3]));
        let three = |m: __m256i| _mm256_add_epi32(m, _mm256_add_epi32(m, m));
        Avx2 {
            d01: _mm256_sub_epi32(v(ns01), three(m01)),
            d23: _mm256_sub_epi32(v(ns23), three(m23)),
        }
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn sum1(d: &Avx2) -> i32 {
        let s = _mm256_add_epi32(d.d01, d.d23);
        let s = _mm_add_epi32(_mm256_castsi256_si128(s), _mm256_extracti128_si256::<1>(s));
        _mm_cvtsi128_si32(s)
    }

    #[target_feature(enable = "avx2")]
    #[inline]
    fn squares(d: &Avx2, h3: i32) -> u32 {
        let off = _mm256_setr_epi32(h3, 0, 0, 0, h3, 0, 0, 0);
        // The pack interleaves the two halves per 128-bit lane; the sum
        // of squares does not depend on the order.
        let r = _mm256_packs_epi32(_mm256_sub_epi32(d.d01, off), _mm256_sub_epi32(d.d23, off));
        let r = _mm256_min_epi16(_mm256_max_epi16(r, _mm256_set1_epi16(-CLAMP as i16)), {
            _mm256_set1_epi16(CLAMP as i16)
        });
        let sq = _mm256_madd_epi16(r, r);
        let s = _mm_add_epi32(
            _mm256_castsi256_si128(sq),
            _mm256_extracti128_si256::<1>(sq),
        );
        let s = _mm_add_epi32(s, _mm_shuffle_epi32::<0b01_00_11_10>(s));
        let s = _mm_add_epi32(s, _mm_shuffle_epi32::<0b10_11_00_01>(s));
        _mm_cvtsi128_si32(s) as u32
    }
}
