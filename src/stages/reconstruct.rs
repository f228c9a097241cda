//! Stage `reconstruct`: level-0 heights from E⁰, S⁰ and V⁰ — each pixel
//! the smooth part of what its 3×3 neighbourhood predicts for it plus the
//! fine detail of its own texel; then spurious pits and peaks at patch
//! joins are repaired ([`super::repair_extrema`]).
//!
//! Neighbour n (at offset Δ from p) predicts the height its own patch
//! continues with at p, from texel `t(n) − Δ` (t(n) = round(S(n))): the
//! prediction is split into the texel's smooth height μ (appearance mode 1,
//! the Gaussian-weighted mean of its 5×5 window) plus its detail `E⁰ − μ`.
//! The pixel takes the mean of the nine smooth predictions, each with its
//! offset V(n), plus the detail of its own texel:
//!
//! `b(p) = ⌊Σ_n (μ(t(n) − Δ) + V(n)) / count⌋ + E⁰(t(p)) − μ(t(p))`
//!
//! Inside a coherent patch all nine texels are one, so the output is the
//! exemplar's heights exactly — crisp, as real terrain is. Where patches
//! meet, the smooth heights of both sides are averaged over two or three
//! pixels, which hides the joins' steps; the detail is not averaged. Why:
//! averaging whole predictions (the previous rule) blended two unrelated
//! micro-reliefs at every join, and on a plain, where joins are everywhere
//! and micro-relief is all there is, that levelled the terrain — the north
//! German plain kept ~0.84× of its source texels' pits and scored a
//! realism ratio of 1.68 (median of seeds 11–13; 0.98 with own detail).
//! The paper samples E⁰ bilinearly at the fractional S⁰ instead; at the
//! finest level every pixel carries a random fraction of jitter, so that
//! low-passed the whole terrain.
//!
//! The kernel output is an i32 height in database units with 8 fractional
//! bits (bit-exact on CPU and GPU): the sum of the smooth predictions (each
//! `(μ + V) << 8`, nine at most: no overflow while |V| < 2^19, eight times
//! the database's range) floor-divided by their count, plus the detail
//! `<< 8`. Neighbours outside the level do not predict. Conversion to
//! metres is a CPU-side `offset + scale · value / 256` (DESIGN §6 rule 5).
//!
//! On the GPU the blend (`kernels/reconstruct.wgsl`) and the repair
//! (`kernels/repair_extrema.wgsl`) are two dispatches with the blended
//! heights between them; here they run fused, one block of rows at a time
//! (the block's blend plus a row above and below, then its repair), so no
//! level-sized intermediate is needed.

use super::correct::scalar::texel_height;
use super::repair_extrema::{mean, repair};
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{div_floor, round};
use crate::level::state::State;
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

/// Fractional bits of reconstructed heights.
pub const HEIGHT_FRAC_BITS: u32 = 8;

/// How far from a pixel the S and V its height depends on lie: the blend
/// reads the 3×3 around it, the repair the blends of the 3×3 around it.
pub const REACH: usize = 2;

/// Rows per parallel task: each task first resolves the texel index, row
/// stride and offset of its rows and the two around them on each side, so
/// the predictions of a pixel cost one load each, not a coordinate decode
/// and a column lookup, and blends its rows and one more on each side.
/// Those halo rows are the overhead: 64 rows (1/16 more blends) rather
/// than 16 (1/8) took the stage from ~15 to ~13 ms at 1024² on 2 cores,
/// together with the branch-free extrema sweep.
const ROWS: usize = 64;

/// What a pixel gives its neighbours' predictions: the atlas index of its
/// rounded texel t(n), its exemplar's row stride and its offset V(n).
/// S(n) is interior (two texels from every exemplar edge), so the texel one
/// step away is in its exemplar, at `k − dx − dy·stride`.
#[derive(Debug, Clone, Copy)]
pub struct Texel {
    pub k: i32,
    pub stride: i32,
    pub v: i32,
}

/// The smooth height μ of atlas texel `k`: its appearance mode 1, the
/// height `correct` attributes to a texel.
#[inline(always)]
fn smooth_height(app: &[u64], k: i32) -> i32 {
    texel_height(app[k as usize])
}

/// The blended height b(p) of a pixel whose neighbour at offset (dx, dy)
/// is `texel(dx, dy)`, `None` outside the level.
#[inline(always)]
fn blend(app: &[u64], heights: &[u16], texel: impl Fn(i32, i32) -> Option<Texel>) -> i32 {
    let (mut sum, mut count) = (0i32, 0i32);
    for dy in -1..=1 {
        for dx in -1..=1 {
            if let Some(t) = texel(dx, dy) {
                sum += smooth_height(app, t.k - dx - dy * t.stride) + t.v;
                count += 1;
            }
        }
    }
    let own = texel(0, 0).expect("the pixel itself is in the level");
    // Σ (a << 8) = (Σ a) << 8, in wrapping arithmetic too: shifted once.
    div_floor(sum << HEIGHT_FRAC_BITS, count) + detail(app, heights, own.k)
}

/// The detail `E⁰ − μ` of texel `k`, ×2^8.
#[inline(always)]
fn detail(app: &[u64], heights: &[u16], k: i32) -> i32 {
    (heights[k as usize] as i32 - smooth_height(app, k)) << HEIGHT_FRAC_BITS
}

/// Heights of level 0, row-major, in units × 2^8.
pub fn reconstruct(atlas: &AtlasLevel<'_>, heights: &[u16], st: &State) -> Vec<i32> {
    let mut out = vec![0i32; st.width * st.height];
    reconstruct_rect(atlas, heights, st, &mut out, [0, 0, st.width, st.height]);
    out
}

/// [`reconstruct`] of the pixels in `[x0, y0, x1, y1)` only, into `out`
/// (level-sized; the rest is left as it is). An edit's re-synthesis
/// changes S and V in a window, and a height depends on the S and V within
/// two pixels of it (blend 3×3, repair 3×3 of blends), so the previous
/// frame's heights with the window widened by two recomputed are the whole
/// reconstruction.
pub fn reconstruct_rect(
    atlas: &AtlasLevel<'_>,
    heights: &[u16],
    st: &State,
    out: &mut [i32],
    [x0, y0, x1, y1]: [usize; 4],
) {
    let (w, h) = (st.width, st.height);
    assert_eq!(out.len(), w * h, "a level-sized output");
    let (x1, y1) = (x1.min(w), y1.min(h));
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let app = atlas.level.appearance;
    // Columns whose blends the repair reads, and whose S and V they read.
    let (ca, cb) = (x0.saturating_sub(1), (x1 + 1).min(w));
    let (xa, xb) = (x0.saturating_sub(2), (x1 + 2).min(w));
    out[y0 * w..y1 * w]
        .par_chunks_mut(w * ROWS)
        .enumerate()
        .for_each(|(b, block)| {
            let ys = y0 + b * ROWS;
            let ye = ys + block.len() / w;
            let (ra, rb) = (ys.saturating_sub(1), (ye + 1).min(h));
            let (ya, yb) = (ys.saturating_sub(2), (ye + 2).min(h));
            // Rows ya..yb, columns xa..xb: each pixel's texel and offset.
            let cols = xb - xa;
            let mut base: Vec<Texel> = Vec::with_capacity((yb - ya) * cols);
            for y in ya..yb {
                base.extend((y * w + xa..y * w + xb).map(|n| {
                    let s = st.s(n);
                    let (tx, ty) = (round(s.x), round(s.y));
                    Texel {
                        k: atlas.index(tx, ty) as i32,
                        stride: atlas.columns[tx as usize].stride as i32,
                        v: st.v(n),
                    }
                }));
            }
            let tex = |x: usize, y: usize| base[(y - ya) * cols + x - xa];
            let line = |y: usize| &base[(y - ya) * cols..(y - ya + 1) * cols];
            // Rows ra..rb, columns ca..cb: the blended heights.
            let bcols = cb - ca;
            let mut blended = vec![0i32; (rb - ra) * bcols];
            for (y, brow) in (ra..rb).zip(blended.chunks_mut(bcols)) {
                let edge = |x: usize| {
                    blend(app, heights, |dx, dy| {
                        let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                        let ok = nx >= 0 && ny >= 0 && nx < w as i32 && ny < h as i32;
                        ok.then(|| tex(nx as usize, ny as usize))
                    })
                };
                if y == 0 || y + 1 == h || w < 3 {
                    for (x, o) in (ca..cb).zip(brow.iter_mut()) {
                        *o = edge(x);
                    }
                    continue;
                }
                // Inside the level every pixel has nine neighbours: no edge
                // tests, and the mean divides by the constant 9.
                let lines = [line(y - 1), line(y), line(y + 1)];
                let (inner0, inner1) = (ca.max(1), cb.min(w - 1));
                for x in (ca..inner0).chain(inner1.max(inner0)..cb) {
                    brow[x - ca] = edge(x);
                }
                for (x, o) in brow
                    .iter_mut()
                    .enumerate()
                    .take(inner1 - ca)
                    .skip(inner0 - ca)
                {
                    let x = x + ca;
                    let mut sum = 0i32;
                    for (l, dy) in lines.iter().zip(-1..=1i32) {
                        let n: &[Texel; 3] = l[x - 1 - xa..x + 2 - xa]
                            .try_into()
                            .expect("three neighbours");
                        for (t, dx) in n.iter().zip(-1..=1i32) {
                            sum += smooth_height(app, t.k - dx - dy * t.stride) + t.v;
                        }
                    }
                    *o = div_floor(sum << HEIGHT_FRAC_BITS, 9)
                        + detail(app, heights, lines[1][x - xa].k);
                }
            }
            // Per row, the least and greatest of each pixel's eight
            // neighbours' blends (a vectorisable sweep: column extremes of
            // the rows above and below, then across), and the repair of the
            // few pixels outside that range.
            let brow = |y: usize| &blended[(y - ra) * bcols..(y - ra + 1) * bcols];
            let (mut lo, mut hi) = (vec![0i32; bcols], vec![0i32; bcols]);
            let (mut near_lo, mut near_hi) = (vec![0i32; bcols], vec![0i32; bcols]);
            for (r, row) in block.chunks_mut(w).enumerate() {
                let y = ys + r;
                let mid = brow(y);
                let row = &mut row[x0..x1];
                row.copy_from_slice(&mid[x0 - ca..x1 - ca]);
                if y == 0 || y + 1 == h || w < 3 {
                    continue;
                }
                let (up, down) = (brow(y - 1), brow(y + 1));
                for (((l, g), a), b) in lo.iter_mut().zip(hi.iter_mut()).zip(up).zip(down) {
                    (*l, *g) = ((*a).min(*b), (*a).max(*b));
                }
                // Interior columns of the row, as indices into the blends;
                // first the range of each one's eight neighbours (a
                // branch-free sweep), then the few outside theirs.
                let (ia, ib) = (x0.max(1) - ca, x1.min(w - 1) - ca);
                if ia >= ib {
                    continue;
                }
                let n = ib - ia;
                let cols = (&lo[ia - 1..], &lo[ia..], &lo[ia + 1..]);
                let gcols = (&hi[ia - 1..], &hi[ia..], &hi[ia + 1..]);
                let sides = (&mid[ia - 1..], &mid[ia..], &mid[ia + 1..]);
                for (k, (l, g)) in near_lo[..n].iter_mut().zip(&mut near_hi[..n]).enumerate() {
                    *l = cols.0[k]
                        .min(cols.1[k])
                        .min(cols.2[k])
                        .min(sides.0[k])
                        .min(sides.2[k]);
                    *g = gcols.0[k]
                        .max(gcols.1[k])
                        .max(gcols.2[k])
                        .max(sides.0[k])
                        .max(sides.2[k]);
                }
                for (k, &c) in sides.1[..n].iter().enumerate() {
                    let range = (near_lo[k], near_hi[k]);
                    if c >= range.0 && c <= range.1 {
                        continue;
                    }
                    let x = ia + k + ca;
                    row[x - x0] = repair(heights, c, range, tex(x, y), || {
                        mean(heights, |dx, dy| {
                            tex((x as i32 + dx) as usize, (y as i32 + dy) as usize)
                        })
                    });
                }
            }
        });
}

/// `ReconstructParams` of `kernels/reconstruct.wgsl` (padded to 16 bytes,
/// the uniform block granularity).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct ReconstructUniform {
    pub width: u32,
    pub height: u32,
    pub pad0: u32,
    pub pad1: u32,
}
