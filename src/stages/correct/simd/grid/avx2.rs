//! [`super::fill`]'s row runs in AVX2, four neighbours at a time.
//!
//! Why: a pixel's grid takes five neighbours (rows y and y + 1 whole, row
//! y + 2 at odd columns; rows y − 2 and y − 1 come from the class row
//! above), and one by one each was ~30 instructions — unpack, round,
//! column lookup, index, six stores — a sixth of the kernel. Four
//! consecutive pixels of a patch almost always point into one exemplar,
//! so one column lookup serves them, and the rest is a handful of vector
//! operations. Where the four straddle two exemplars they are read one
//! by one, as before.

use super::{Grid, put_pixel};
use crate::database::layout::MARGIN;
use crate::level::atlas::Column;
use crate::level::fixed::{FRAC_BITS, ONE};
use core::arch::x86_64::*;
use std::sync::atomic::{AtomicI32, AtomicU64};

/// Fills row `r` of `grid` from column `j0` on with the pixels whose S
/// and V are `s` and `v` (a run of one level row).
///
/// # Safety
/// No thread may write the run's pixels while this reads them: they are
/// read with plain vector loads. The correction calls it for level rows
/// y − 1, y and y + 1 of class row y, whose pixels are of other classes
/// (which the subpass does not write) or of row y itself (which only the
/// calling task writes, after this).
#[inline]
#[target_feature(enable = "avx2,bmi2")]
pub(super) unsafe fn fill_run(
    grid: &mut Grid,
    r: usize,
    j0: usize,
    columns: &[Column],
    s: &[AtomicU64],
    v: &[AtomicI32],
) {
    let n = s.len().min(v.len());
    let j_end = j0 + n;
    // Bounds of the grid row, checked once: every store below is at
    // j0 + k + 0..4 ≤ j_end.
    assert!(j_end <= grid.idx[r].len());
    let mut k = 0;
    while k + 4 <= n {
        let j = j0 + k;
        // SAFETY: k + 4 ≤ n, so the four S (8 bytes each, the layout of
        // AtomicU64) and V lie in the slices; the caller guarantees no
        // concurrent writer.
        let (sv, vv) = unsafe {
            (
                _mm256_loadu_si256(s.as_ptr().add(k).cast()),
                _mm_loadu_si128(v.as_ptr().add(k).cast()),
            )
        };
        // Round x and y of each coordinate (fixed point, i32 halves), then
        // gather the x into the low half and the y into the high half.
        let t = _mm256_srai_epi32::<{ FRAC_BITS as i32 }>(_mm256_add_epi32(
            sv,
            _mm256_set1_epi32(ONE >> 1),
        ));
        let t = _mm256_permutevar8x32_epi32(t, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
        let (sx, sy) = (_mm256_castsi256_si128(t), _mm256_extracti128_si256::<1>(t));
        let col = &columns[_mm_cvtsi128_si32(sx) as usize];
        // One exemplar: every x within the first one's rectangle (its
        // interior widened by the margin), whose columns share its entry.
        let gt = |a: __m128i, b: i32| _mm_cmpgt_epi32(a, _mm_set1_epi32(b));
        let lt = |a: __m128i, b: i32| _mm_cmpgt_epi32(_mm_set1_epi32(b), a);
        let margin = MARGIN as i32;
        let same = _mm_and_si128(
            gt(sx, col.min_x - margin - 1),
            lt(sx, col.max_x + margin + 1),
        );
        if _mm_movemask_epi8(same) != 0xFFFF {
            for i in k..k + 4 {
                put_pixel(grid, r, j0 + i, columns, &s[i], &v[i]);
            }
            k += 4;
            continue;
        }
        let stride = _mm_set1_epi32(col.stride as i32);
        let idx = _mm_add_epi32(
            _mm_add_epi32(_mm_set1_epi32(col.base), _mm_mullo_epi32(sy, stride)),
            sx,
        );
        // `Grid::edge` is "not strictly inside the interior".
        let inside = _mm_and_si128(
            _mm_and_si128(gt(sx, col.min_x), lt(sx, col.max_x)),
            _mm_and_si128(gt(sy, margin), lt(sy, col.max_y)),
        );
        let inside_bits = _mm_movemask_ps(_mm_castsi128_ps(inside)) as u32;
        let edge = _pdep_u32(!inside_bits & 0xF, 0x0101_0101).to_le_bytes();
        let store = |row: &mut [i32], x: __m128i| {
            let out: &mut [i32; 4] = (&mut row[j..j + 4]).try_into().expect("four columns");
            // SAFETY: `out` is four i32, the width of the store.
            unsafe { _mm_storeu_si128(out.as_mut_ptr().cast(), x) };
        };
        store(&mut grid.idx[r], idx);
        store(&mut grid.stride[r], stride);
        store(&mut grid.v[r], vv);
        grid.edge[r][j..j + 4].copy_from_slice(&edge);
        k += 4;
    }
    for i in k..n {
        put_pixel(grid, r, j0 + i, columns, &s[i], &v[i]);
    }
}
