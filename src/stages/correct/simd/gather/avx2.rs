//! [`super::gather`]'s sources and duplicate search for a whole chunk,
//! eight pixels per AVX2 vector, before its pixel loop.
//!
//! Why: per pixel, forming the nine u (SSE2 shuffles into DELTAS order)
//! and finding the distinct ones (eight broadcast compares and a mask
//! narrowing) took ~95 instructions, an eighth of the kernel. Across
//! pixels the same work is regular: Δ's u of eight consecutive pixels is
//! one vector (their grid columns are two apart: the even or odd columns
//! of two loads), u_j = u_k is one compare for eight pixels, and each
//! pixel's mask of first occurrences is built in its own lane — ~26
//! instructions per pixel, off the pixel loop's dependency chains.

use super::super::grid::{GRID_COLS, Grid};
use super::Table;
use crate::stages::common::DELTAS;
use core::arch::x86_64::*;

/// Elements `b, b + 2, …, b + 14` of a grid row.
#[inline]
#[target_feature(enable = "avx2")]
fn evens(row: &[i32; GRID_COLS], b: usize) -> __m256i {
    let p: &[i32; 16] = row[b..b + 16].try_into().expect("sixteen columns");
    // SAFETY: two 32-byte reads of the sixteen elements of `p`.
    let (lo, hi) = unsafe {
        (
            _mm256_loadu_si256(p.as_ptr().cast()),
            _mm256_loadu_si256(p.as_ptr().add(8).cast()),
        )
    };
    // [lo0 lo2 hi0 hi2 | lo4 lo6 hi4 hi6], then the 64-bit pairs in order.
    let x = _mm256_shuffle_ps::<0b10_00_10_00>(_mm256_castsi256_ps(lo), _mm256_castsi256_ps(hi));
    _mm256_permute4x64_epi64::<0b11_01_10_00>(_mm256_castps_si256(x))
}

/// Fills `t` for the first `n` pixels of the chunk in `grid` (pixel i in
/// grid column 2i + 2; the lanes past `n` of the last eight are formed
/// from whatever the grid holds there, and never read).
#[inline]
#[target_feature(enable = "avx2")]
pub(in super::super) fn tabulate(grid: &Grid, n: usize, t: &mut Table) {
    let store = |out: &mut [i32], i0: usize, x: __m256i| {
        let out: &mut [i32; 8] = (&mut out[i0..i0 + 8]).try_into().expect("eight pixels");
        // SAFETY: `out` is eight i32, the width of the store.
        unsafe { _mm256_storeu_si256(out.as_mut_ptr().cast(), x) };
    };
    for i0 in (0..n).step_by(8) {
        let mut u = [_mm256_setzero_si256(); 9];
        for (k, &(dx, dy)) in DELTAS.iter().enumerate() {
            let (r, b) = ((2 + dy) as usize, (2 * i0 as i32 + 2 + dx) as usize);
            let (idx, stride) = (evens(&grid.idx[r], b), evens(&grid.stride[r], b));
            // u = t(n) − Δx − Δy·stride(n).
            let at = _mm256_sub_epi32(idx, _mm256_set1_epi32(dx));
            u[k] = match dy {
                -1 => _mm256_add_epi32(at, stride),
                0 => at,
                _ => _mm256_sub_epi32(at, stride),
            };
            store(&mut t.u[k], i0, u[k]);
            store(&mut t.s[k], i0, stride);
        }
        // Per lane, bit k set where some earlier u_j equals u_k.
        let mut dup = _mm256_setzero_si256();
        for k in 1..9 {
            let mut eq = _mm256_cmpeq_epi32(u[0], u[k]);
            for uj in &u[1..k] {
                eq = _mm256_or_si256(eq, _mm256_cmpeq_epi32(*uj, u[k]));
            }
            dup = _mm256_or_si256(dup, _mm256_and_si256(eq, _mm256_set1_epi32(1 << k)));
        }
        let first = _mm256_andnot_si256(dup, _mm256_set1_epi32(0x1FF));
        store(bytemuck::cast_slice_mut(&mut t.first), i0, first);
    }
}
