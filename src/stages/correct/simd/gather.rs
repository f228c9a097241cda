//! Candidate gathering (paper eq. 3): C₁ and C₂ of every distinct
//! `u = S(p+Δ) − Δ` of a pixel, listed ahead of scoring with their texels
//! prefetched.

use super::super::scalar::{Neighbour, neighbour};
use super::grid::{CHUNK, Grid, any_edge};
use crate::isa::prefetch;
use crate::level::atlas::AtlasLevel;
use crate::level::state::State;
use crate::stages::common::DELTAS;

#[cfg(target_arch = "x86_64")]
pub(super) mod avx2;

/// A pixel whose candidates are gathered, awaiting scoring: C₁ and C₂ of
/// each distinct u, candidate `i` being pair `i / 2`'s C₁ (`i` even) or
/// C₂ (`i` odd).
#[derive(Clone, Copy, Default)]
pub(super) struct Pending {
    pub pairs: [Pair; 9],
    /// Candidates (twice the pairs).
    pub count: usize,
    /// Whether a neighbour lies next to an edge, so that C₁ may differ
    /// from u (else the winner's coordinate is u's, unclamped, and the
    /// whole 3×3 lies inside the level).
    pub edge: bool,
}

/// The two candidates of one u.
///
/// C₁ is kept as the texel indices scoring reads (its diagonals' rows),
/// not as its own index and row stride: they are the addresses `list`
/// prefetches anyway, and every candidate is scored while only the winner
/// needs C₁'s own index ([`Pair::c1`]), so the address arithmetic is done
/// once per pair instead of again in the scorer's loop.
#[derive(Clone, Copy, Default)]
pub(super) struct Pair {
    /// The texel up-left of C₁ (`c1 − stride − 1`), where C₁ is u's texel
    /// unless u left its exemplar's interior and was clamped back (the
    /// winner's coordinate is formed by `finish`).
    pub up: i32,
    /// The texel down-left of C₁ (`c1 + stride − 1`).
    pub down: i32,
    /// u's texel index: C₂ is `similar[u]`, its diagonal texels `c2[u]`
    /// (`AtlasLevel`). Only the winner's coordinate is ever looked up.
    pub u: i32,
    /// Index into DELTAS of the neighbour both came from.
    pub from: u8,
}

impl Pair {
    /// C₁'s texel index: midway between `up` and `down`, one texel right.
    #[inline(always)]
    pub fn c1(&self) -> i32 {
        ((self.up + self.down) >> 1) + 1
    }
}

/// Lists the candidates of the pixel in grid column `c` (C₁ and C₂ of every
/// distinct `u = S(p+Δ) − Δ`, in DELTAS order) and prefetches the texels
/// scoring will read (at level 0 the atlas is larger than the L2 cache):
/// C₂'s only when they compete (`similar`).
///
/// The distinct u are found first, as a bit mask, with a fixed number of
/// compares; then only they are listed, in one loop. Deciding per Δ
/// whether its u is new was a branch that varied from pixel to pixel and
/// mispredicted often (listing every Δ instead, repeats included, was
/// slower still).
/// `pos`: the pixel's level position (read only where it has an edge
/// neighbour).
/// `first` and `source` are the pixel's [`firsts`] mask and, per Δ k, u's
/// texel index and stride (its [`sources`], or a [`Table`]'s row).
#[inline(always)]
pub(super) fn gather(
    (atlas, st): (&AtlasLevel<'_>, &State),
    (grid, c): (&Grid, usize),
    pos: (i32, i32),
    (mut first, source): (u32, impl Fn(usize) -> (i32, i32)),
    similar: bool,
    out: &mut Pending,
) {
    out.count = 2 * first.count_ones() as usize;
    // C₁ is u itself unless a neighbour lies next to an edge (rare).
    let edge = any_edge(grid, c);
    out.edge = edge;
    // One slot per distinct u, in order (a slot per iteration, not an
    // index: no bounds check, and the count is known up front).
    for slot in &mut out.pairs {
        if first == 0 {
            break;
        }
        let k = first.trailing_zeros() as usize;
        first &= first - 1;
        let (u, s) = source(k);
        let c1 = match edge {
            true => clamped(atlas, st, pos, k, (u, s)),
            false => u,
        };
        *slot = list(atlas, k, c1, (u, s), similar);
    }
}

/// A chunk's [`sources`] and [`firsts`], per Δ (DELTAS order) and pixel:
/// u's texel index, its exemplar's row stride, and the mask of first
/// occurrences — what the AVX2 span forms for a whole chunk at once
/// ([`avx2::tabulate`]) before its pixel loop.
pub(super) struct Table {
    pub u: [[i32; CHUNK]; 9],
    pub s: [[i32; CHUNK]; 9],
    pub first: [u32; CHUNK],
}

impl Table {
    pub fn new() -> Table {
        Table {
            u: [[0; CHUNK]; 9],
            s: [[0; CHUNK]; 9],
            first: [0; CHUNK],
        }
    }
}

/// The pixel in grid column `c`'s [`sources`] and [`firsts`] mask, formed
/// for it alone (the baseline span's way).
#[inline(always)]
pub(super) fn per_pixel(grid: &Grid, c: usize) -> ([i32; 9], [i32; 9], u32) {
    let (u, s) = sources(grid, c);
    (u, s, firsts(&u))
}

/// The texel index of every `u = t(n) − Δ` of the pixel in grid column
/// `c`, in DELTAS order, and the row stride of its exemplar (u lies in the
/// exemplar of S(n), one texel from its interior, so its texel index
/// identifies it: `idx(n) − Δx − Δy·stride(n)`).
///
/// On x86-64 a grid row's three neighbours are one vector (SSE2): three
/// rows of index and stride loads, an add or subtract per row, and
/// shuffles into DELTAS order, instead of eighteen loads and nine
/// multiply-adds one by one.
#[inline(always)]
fn sources(grid: &Grid, c: usize) -> ([i32; 9], [i32; 9]) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of the x86-64 baseline.
    unsafe {
        use core::arch::x86_64::*;
        // Columns c − 1 … c + 2 of a grid row (the fourth is not used).
        let row = |f: &super::grid::Field<i32>, r: usize| {
            let v: &[i32; 4] = f[r][c - 1..c + 3].try_into().expect("four columns");
            _mm_loadu_si128(v.as_ptr().cast())
        };
        // −Δx per column.
        let minus_dx = _mm_setr_epi32(1, 0, -1, -2);
        let (s1, s2, s3) = (
            row(&grid.stride, 1),
            row(&grid.stride, 2),
            row(&grid.stride, 3),
        );
        let u1 = _mm_add_epi32(_mm_add_epi32(row(&grid.idx, 1), s1), minus_dx);
        let u2 = _mm_add_epi32(row(&grid.idx, 2), minus_dx);
        let u3 = _mm_add_epi32(_mm_sub_epi32(row(&grid.idx, 3), s3), minus_dx);
        // DELTAS order: (0, 0), then row −1's three, (−1, 0), (1, 0), row
        // 1's three: lanes (r1[0], r1[1], r1[2], r2[0]) and (r2[2], r3[0],
        // r3[1], r3[2]).
        let order = |a: __m128i, b: __m128i, c: __m128i| {
            let (a, b, c) = (
                _mm_castsi128_ps(a),
                _mm_castsi128_ps(b),
                _mm_castsi128_ps(c),
            );
            let ab = _mm_shuffle_ps::<0b00_00_00_10>(a, b);
            let lo = _mm_shuffle_ps::<0b10_00_01_00>(a, ab);
            let bc = _mm_shuffle_ps::<0b00_00_00_10>(b, c);
            let hi = _mm_shuffle_ps::<0b10_01_10_00>(bc, c);
            (_mm_castps_si128(lo), _mm_castps_si128(hi))
        };
        let mut u = [0i32; 9];
        let mut s = [0i32; 9];
        for (out, (a, b, c)) in [(&mut u, (u1, u2, u3)), (&mut s, (s1, s2, s3))] {
            let (lo, hi) = order(a, b, c);
            out[0] = _mm_cvtsi128_si32(_mm_shuffle_epi32::<1>(b));
            _mm_storeu_si128(out[1..5].as_mut_ptr().cast(), lo);
            _mm_storeu_si128(out[5..9].as_mut_ptr().cast(), hi);
        }
        (u, s)
    }
    #[cfg(not(target_arch = "x86_64"))]
    sources_scalar(grid, c)
}

/// [`sources`] by its definition: the path off x86-64, and the reference
/// its vector form is tested against.
#[cfg(any(test, not(target_arch = "x86_64")))]
fn sources_scalar(grid: &Grid, c: usize) -> ([i32; 9], [i32; 9]) {
    use super::grid::{at, window};
    let (idx, stride) = (window(&grid.idx, c), window(&grid.stride, c));
    let s: [i32; 9] = std::array::from_fn(|k| at(&stride, DELTAS[k].0, DELTAS[k].1));
    let u: [i32; 9] = std::array::from_fn(|k| {
        let (dx, dy) = DELTAS[k];
        at(&idx, dx, dy) - dx - dy * s[k]
    });
    (u, s)
}

/// Bit k set: no earlier Δ has Δ k's u (bit 0 always).
///
/// On x86-64 the 36 pairwise compares are eight vector compares of one u
/// against u₁…u₈ (SSE2, the baseline); the scalar compares were a tenth
/// of the kernel's instructions. The baseline span calls this per pixel
/// ([`per_pixel`]); the AVX2 span finds the same masks for a whole chunk
/// at once ([`avx2::tabulate`], tested against this). A 256-bit compare of
/// one pixel's u inside the pixel loop ran fewer instructions but slower
/// (LLVM turned it into long shuffle chains; ×1.13 in interleaved runs).
#[inline(always)]
fn firsts(u: &[i32; 9]) -> u32 {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is part of the x86-64 baseline.
    unsafe {
        use core::arch::x86_64::*;
        let lo = _mm_setr_epi32(u[1], u[2], u[3], u[4]);
        let hi = _mm_setr_epi32(u[5], u[6], u[7], u[8]);
        // Two bits per k (k − 1 as an i16 lane): set where an earlier u_j
        // equals u_k.
        let mut dup = 0u32;
        for (j, &uj) in u[..8].iter().enumerate() {
            let b = _mm_set1_epi32(uj);
            let eq = _mm_packs_epi32(_mm_cmpeq_epi32(b, lo), _mm_cmpeq_epi32(b, hi));
            dup |= _mm_movemask_epi8(eq) as u32 & (0xFFFF << (2 * j));
        }
        // One bit per lane: bit k − 1.
        let mut d = dup & 0x5555;
        d = (d | d >> 1) & 0x3333;
        d = (d | d >> 2) & 0x0F0F;
        d = (d | d >> 4) & 0x00FF;
        1 | (!(d << 1) & 0x1FE)
    }
    #[cfg(not(target_arch = "x86_64"))]
    firsts_scalar(u)
}

/// [`firsts`] by its definition: the pairwise compares (the path off
/// x86-64, and the reference its vector compares are tested against).
#[cfg(any(test, not(target_arch = "x86_64")))]
fn firsts_scalar(u: &[i32; 9]) -> u32 {
    let mut first = 1u32;
    for k in 1..9 {
        let dup = u[..k].iter().fold(false, |dup, &v| dup | (v == u[k]));
        first |= (!dup as u32) << k;
    }
    first
}

/// [`gather`]'s listing of C₁ (texel index `c1`) and C₂ of Δ =
/// `DELTAS[k]`, whose u has texel index `u_idx` in an exemplar of row
/// stride `stride` (C₂ listed but not prefetched unless `similar`: the
/// scorer then skips it).
#[inline(always)]
fn list(
    atlas: &AtlasLevel<'_>,
    k: usize,
    c1: i32,
    (u_idx, stride): (i32, i32),
    similar: bool,
) -> Pair {
    // Scoring reads C₁'s texels q − s ± 1 and q + s ± 1 (the AVX2 scorer
    // the 32 bytes q ± s − 1 … q ± s + 2), near S(p), whose lines N_S
    // reads anyway; and C₂'s from `c2[u]`, one line.
    let app = atlas.level.appearance;
    let (up, down) = (c1 - stride - 1, c1 + stride - 1);
    prefetch(app, up);
    prefetch(app, down);
    if similar {
        prefetch(atlas.c2, u_idx);
    }
    Pair {
        up,
        down,
        u: u_idx,
        from: k as u8,
    }
}

/// The neighbour n at Δ = `DELTAS[k]` of the pixel at level position
/// (x, y), as the grid reads it (reflected at the level border, its texel
/// extrapolated), and its u = t(n) − Δ: for the pixels with an edge
/// neighbour, whose C₁ must be clamped, and for a winner's fraction.
#[inline(always)]
pub(super) fn source_at(
    atlas: &AtlasLevel<'_>,
    st: &State,
    (x, y): (i32, i32),
    k: usize,
) -> (Neighbour, (i32, i32)) {
    let (dx, dy) = DELTAS[k];
    let n = neighbour(atlas, st, x + dx, y + dy);
    let u = (n.tx - dx, n.ty - dy);
    (n, u)
}

/// C₁'s texel index, from u's (`u_idx`, in an exemplar of row stride
/// `stride`), where the pixel at level position `at` has a neighbour next
/// to an edge: u ([`source_at`]) clamped into its exemplar's interior.
#[inline(never)]
fn clamped(
    atlas: &AtlasLevel<'_>,
    st: &State,
    at: (i32, i32),
    k: usize,
    (u_idx, stride): (i32, i32),
) -> i32 {
    let (_, u) = source_at(atlas, st, at, k);
    let (cx, cy) = atlas.clamp_interior(u.0, u.1);
    u_idx + (cx - u.0) + (cy - u.1) * stride
}

#[cfg(test)]
mod tests {
    use super::super::grid::{CHUNK, Grid};
    use super::{firsts, firsts_scalar, sources, sources_scalar};

    #[test]
    fn sources_match_their_definition_at_every_column() {
        let mut h = 0x2545_F491u32;
        let mut next = move || {
            h ^= h << 13;
            h ^= h >> 17;
            h ^= h << 5;
            h
        };
        let mut grid = Grid::new();
        for _ in 0..8 {
            for r in 0..5 {
                for j in 0..grid.idx[r].len() {
                    grid.idx[r][j] = (next() >> 1) as i32 - (1 << 30);
                    grid.stride[r][j] = (next() % 5000) as i32;
                }
            }
            // Every column a pixel of a full chunk sits at.
            for c in (2..=2 * CHUNK).step_by(2) {
                assert_eq!(sources(&grid, c), sources_scalar(&grid, c), "column {c}");
            }
        }
    }

    #[test]
    fn a_chunks_table_holds_each_pixels_sources_and_firsts() {
        #[cfg(target_arch = "x86_64")]
        if crate::isa::Isa::Avx2.avx2() {
            let mut grid = Grid::new();
            let mut table = super::Table::new();
            let mut h = 0x0BAD_5EEDu32;
            for round in 0..64 {
                // Few distinct indices, so that neighbours repeat (as in
                // coherent patches); some rounds wide values too.
                for r in 0..5 {
                    for j in 0..grid.idx[r].len() {
                        h ^= h << 13;
                        h ^= h >> 17;
                        h ^= h << 5;
                        let small = (h % 4) as i32 + j as i32 / 2;
                        grid.idx[r][j] = if round % 4 == 0 {
                            (h >> 1) as i32
                        } else {
                            small
                        };
                        grid.stride[r][j] = (h >> 24) as i32 % 3;
                    }
                }
                let n = 1 + round % CHUNK;
                // SAFETY: the CPU has AVX2 (checked above).
                unsafe { super::avx2::tabulate(&grid, n, &mut table) };
                for i in 0..n {
                    let (u, s, first) = super::per_pixel(&grid, 2 * i + 2);
                    let row =
                        |t: &[[i32; CHUNK]; 9]| -> [i32; 9] { std::array::from_fn(|k| t[k][i]) };
                    assert_eq!(
                        (row(&table.u), row(&table.s)),
                        (u, s),
                        "round {round}, pixel {i}"
                    );
                    assert_eq!(table.first[i], first, "round {round}, pixel {i}");
                }
            }
            return;
        }
        eprintln!("skipped: this CPU has no AVX2");
    }

    #[test]
    fn firsts_marks_each_first_occurrence_like_the_pairwise_compares() {
        // Every u over an alphabet of 3 values whose first entry is fixed
        // (3^8 patterns: every arrangement of repeats among the nine), and
        // hashed ones with wide values (sign bits, lanes packed to i16).
        let mut us: Vec<[i32; 9]> = (0..3u32.pow(8))
            .map(|code| {
                std::array::from_fn(|k| {
                    if k == 0 {
                        0
                    } else {
                        (code / 3u32.pow(k as u32 - 1) % 3) as i32
                    }
                })
            })
            .collect();
        let mut h = 0x9E37_79B9u32;
        for _ in 0..4096 {
            us.push(std::array::from_fn(|_| {
                h = h.wrapping_mul(0x0101_0101).wrapping_add(0x7F4A_7C15) ^ (h >> 13);
                [i32::MIN, -1, 0x0001_0000, 0x7FFF_0000][(h >> 30) as usize] | (h & 1) as i32
            }));
        }
        for u in &us {
            assert_eq!(firsts(u), firsts_scalar(u), "u = {u:?}");
        }
    }
}
