//! [`super::fill`]'s row runs in AVX2, eight neighbours at a time.
//!
//! Why: a pixel's grid takes four neighbours per subpass (rows y + 1 and
//! y + 2 whole; rows y − 2 … y come from the class row above), and one by
//! one each was ~30 instructions — unpack, round, column lookup, index,
//! stores — a sixth of the kernel. Consecutive pixels of a patch almost
//! always point into one exemplar, so one column lookup serves eight, and
//! the rest is a handful of 256-bit operations (with the row runs' ends
//! and the exemplar changes, ~17 instructions per neighbour four at a time,
//! ~11 eight at a time). Where the eight straddle two exemplars they go
//! one by one, as before.

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
/// y + 1 and y + 2 of class row y (and y − 2 … y for a block's first),
/// whose pixels are of other classes (which the subpass does not write)
/// or of class rows only the calling task writes, after this.
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
    // Bounds of the grid row, checked once: every store below is at
    // j0 + k + 0..8 ≤ j0 + n.
    assert!(j0 + n <= grid.idx[r].len());
    let mut k = 0;
    // The last eight start at n − 8, overlapping some already stored (with
    // the same values) instead of leaving up to seven one by one.
    while k < n && n >= 8 {
        let at = k.min(n - 8);
        // SAFETY: at + 8 ≤ n (the caller's guarantees forwarded).
        if !unsafe { put8(grid, r, (j0, at), columns, s, v) } {
            for i in at..at + 8 {
                put_pixel(grid, r, j0 + i, columns, &s[i], &v[i]);
            }
        }
        k = at + 8;
    }
    for i in k..n {
        put_pixel(grid, r, j0 + i, columns, &s[i], &v[i]);
    }
}

/// The rounded coordinates of four S (fixed point, packed x | y << 32):
/// the x in the low half, the y in the high half.
#[inline]
#[target_feature(enable = "avx2")]
fn round4(sv: __m256i) -> __m256i {
    let t = _mm256_srai_epi32::<{ FRAC_BITS as i32 }>(_mm256_add_epi32(
        sv,
        _mm256_set1_epi32(ONE >> 1),
    ));
    _mm256_permutevar8x32_epi32(t, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7))
}

/// Eight neighbours from `k` on, if they lie in one exemplar (else none is
/// stored: false).
///
/// # Safety
/// `k + 8 ≤ n`, and [`fill_run`]'s.
#[inline]
#[target_feature(enable = "avx2,bmi2")]
unsafe fn put8(
    grid: &mut Grid,
    r: usize,
    (j0, k): (usize, usize),
    columns: &[Column],
    s: &[AtomicU64],
    v: &[AtomicI32],
) -> bool {
    // SAFETY: the eight S (8 bytes each, the layout of AtomicU64) and V
    // lie in the slices; no concurrent writer (the caller's guarantee).
    let (s0, s1, vv) = unsafe {
        (
            _mm256_loadu_si256(s.as_ptr().add(k).cast()),
            _mm256_loadu_si256(s.as_ptr().add(k + 4).cast()),
            _mm256_loadu_si256(v.as_ptr().add(k).cast()),
        )
    };
    let (t0, t1) = (round4(s0), round4(s1));
    let sx = _mm256_permute2x128_si256::<0x20>(t0, t1);
    let sy = _mm256_permute2x128_si256::<0x31>(t0, t1);
    let col = &columns[_mm256_cvtsi256_si32(sx) as usize];
    let gt = |a: __m256i, b: i32| _mm256_cmpgt_epi32(a, _mm256_set1_epi32(b));
    let lt = |a: __m256i, b: i32| _mm256_cmpgt_epi32(_mm256_set1_epi32(b), a);
    let margin = MARGIN as i32;
    // One exemplar: every x within the first one's rectangle (its
    // interior widened by the margin), whose columns share its entry.
    let same = _mm256_and_si256(
        gt(sx, col.min_x - margin - 1),
        lt(sx, col.max_x + margin + 1),
    );
    if _mm256_movemask_epi8(same) != -1 {
        return false;
    }
    let stride = _mm256_set1_epi32(col.stride as i32);
    let idx = _mm256_add_epi32(
        _mm256_add_epi32(_mm256_set1_epi32(col.base), _mm256_mullo_epi32(sy, stride)),
        sx,
    );
    // `Grid::edge` is "not strictly inside the interior".
    let inside = _mm256_and_si256(
        _mm256_and_si256(gt(sx, col.min_x), lt(sx, col.max_x)),
        _mm256_and_si256(gt(sy, margin), lt(sy, col.max_y)),
    );
    let inside_bits = _mm256_movemask_ps(_mm256_castsi256_ps(inside)) as u64;
    let edge = _pdep_u64(!inside_bits & 0xFF, 0x0101_0101_0101_0101).to_le_bytes();
    let j = j0 + k;
    let store = |row: &mut [i32], x: __m256i| {
        let out: &mut [i32; 8] = (&mut row[j..j + 8]).try_into().expect("eight columns");
        // SAFETY: `out` is eight i32, the width of the store.
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), x) };
    };
    store(&mut grid.idx[r], idx);
    store(&mut grid.stride[r], stride);
    store(&mut grid.v[r], vv);
    grid.edge[r][j..j + 8].copy_from_slice(&edge);
    true
}
