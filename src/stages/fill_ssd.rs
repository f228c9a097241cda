//! Stage `fill_ssd`: round one of the patch engine's hole filling (seed 004
//! §6.2, DESIGN §7) — the DC-corrected SSD of every fill candidate of a
//! source against one user window, under every transform, on the 8×
//! reduced grid. Integer throughout so that `kernels/fill_ssd.wgsl` gives
//! the same table: [`fill_ssd_scalar`] is the oracle, [`fill_ssd`] its
//! explicit-SIMD twin, [`fill_ssd_table`] the data-parallel loop over
//! candidates. Where it runs (CPU or GPU) is `patch::fill::fill_ssd::FillCost`.

use bytemuck::{Pod, Zeroable};

/// Largest magnitude of a centred cell in the round-one fill kernels
/// ([`fill_ssd`]), in decimetres (819.1 m). Cells are centred on their
/// window's mean first, which leaves the DC-corrected SSD unchanged (it is
/// invariant, exactly in integers, under adding one constant to every
/// difference); clamping then bounds a difference by 2·8191 < 2^14.5, its
/// square by 2^28, and four squares summed per lane by 2^30, so an `i32`
/// lane never overflows (the bound the WGSL mirror will need too). A cell
/// 819 m from the mean of its 8×-reduced window only occurs in a window
/// that holds about the whole relief of a relief-normalised source; there
/// the cost saturates, which only matters to a candidate ranked out anyway.
pub const FILL_CLAMP: i32 = 8191;

/// Centres `v` (in place) on the floor mean of the cells where `valid` is
/// set (all cells when `None`) and clamps to ±[`FILL_CLAMP`]; cells not
/// valid become 0. Returns the number of valid cells.
pub fn centre_cells(v: &mut [i32], valid: Option<&[bool]>) -> i64 {
    let ok = |i: usize| valid.is_none_or(|m| m[i]);
    let (mut s, mut k) = (0i64, 0i64);
    for (i, &x) in v.iter().enumerate() {
        if ok(i) {
            s += x as i64;
            k += 1;
        }
    }
    let mean = if k > 0 { s.div_euclid(k) } else { 0 };
    for (i, x) in v.iter_mut().enumerate() {
        *x = if ok(i) {
            (*x as i64 - mean).clamp(-(FILL_CLAMP as i64), FILL_CLAMP as i64) as i32
        } else {
            0
        };
    }
    k
}

/// Round one of hole filling, scalar reference: the DC-corrected SSD
/// `(k·Σd² − (Σd)²) / k²` (floor) of `d = user − cand` over the `k` cells
/// whose `mask` is `-1` (all bits; `0` = not valid); 0 when `k = 0`. Both
/// inputs are centred and clamped ([`centre_cells`]). This is the oracle
/// for [`fill_ssd`] and the definition the WGSL mirror must reproduce.
pub fn fill_ssd_scalar(user: &[i32], mask: &[i32], cand: &[i32], k: i64) -> u64 {
    let (mut s, mut s2) = (0i64, 0i64);
    for ((&u, &m), &c) in user.iter().zip(mask).zip(cand) {
        let d = ((u - c) & m) as i64;
        s += d;
        s2 += d * d;
    }
    dc_ssd(s, s2, k)
}

/// The DC-corrected SSD `(k·s2 − s²) / k²` (floor; 0 when `k = 0`) from
/// the sums `s = Σd`, `s2 = Σd²` over `k` cells: the last step of
/// [`fill_ssd`], shared by the GPU path, whose kernel returns the sums.
#[inline]
pub fn dc_ssd(s: i64, s2: i64, k: i64) -> u64 {
    if k > 0 {
        ((k * s2 - s * s) / (k * k)) as u64
    } else {
        0
    }
}

/// [`fill_ssd_scalar`] with explicit SIMD (`wide::i32x8`, eight cells per
/// step; byte-identical by construction and by test): differences and
/// squares stay in `i32` lanes under the [`FILL_CLAMP`] bound and are
/// widened to `i64` every four steps, before a lane could overflow.
pub fn fill_ssd(user: &[i32], mask: &[i32], cand: &[i32], k: i64) -> u64 {
    use wide::i32x8;
    let len = user.len().min(mask.len()).min(cand.len());
    let lanes = |v: &[i32], i: usize| i32x8::new(v[i..i + 8].try_into().expect("8 lanes"));
    let (mut s, mut s2) = (0i64, 0i64);
    let mut i = 0;
    while i + 8 <= len {
        let (mut vs, mut vs2) = (i32x8::ZERO, i32x8::ZERO);
        let mut steps = 0;
        while steps < 4 && i + 8 <= len {
            let d = (lanes(user, i) - lanes(cand, i)) & lanes(mask, i);
            vs += d;
            vs2 += d * d;
            i += 8;
            steps += 1;
        }
        s += vs.to_array().iter().map(|&v| v as i64).sum::<i64>();
        s2 += vs2.to_array().iter().map(|&v| v as i64).sum::<i64>();
    }
    for j in i..len {
        let d = ((user[j] - cand[j]) & mask[j]) as i64;
        s += d;
        s2 += d * d;
    }
    dc_ssd(s, s2, k)
}

/// Round one of hole filling for one source: [`fill_ssd`] of every
/// candidate (`cells.len() / user.len() * transforms` of them, each
/// `user[v].len()` cells, contiguous in `cells`) under every transform `v`
/// (`user[v]`, `mask[v]`), candidate-major: entry `k · transforms + v`.
/// Data-parallel over candidates; `backend::gpu::fill_ssd` computes the
/// same table on the GPU.
pub fn fill_ssd_table(user: &[Vec<i32>], mask: &[Vec<i32>], cells: &[i32], k: i64) -> Vec<u64> {
    use rayon::prelude::*;
    let per = user.first().map_or(0, Vec::len);
    if per == 0 {
        return Vec::new();
    }
    cells
        .par_chunks(per)
        .flat_map_iter(|c| {
            user.iter()
                .zip(mask)
                .map(move |(u, m)| fill_ssd(u, m, c, k))
        })
        .collect()
}

/// `FillSsdParams` of `kernels/fill_ssd.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct FillSsdUniform {
    pub cells: u32,
    pub candidates: u32,
    pub transforms: u32,
    pub pad0: u32,
}
