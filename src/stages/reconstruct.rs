//! Stage `reconstruct`: level-0 heights from E⁰, S⁰ and V⁰ — each pixel the
//! mean of what its 3×3 neighbourhood predicts for it.
//!
//! Neighbour n (at offset Δ from p) predicts `E⁰(round(S(n)) − Δ) + V(n)`:
//! the height its own patch continues with at p. Inside a coherent patch
//! all nine predictions are the same exemplar texel, so the output is the
//! exemplar's heights exactly — crisp, as real terrain is. Where patches
//! meet, the predictions of both sides are averaged over two or three
//! pixels, which hides the joins (single-pixel pits and steps, the repeated
//! or skipped texels of jittered coordinates) without blurring anything
//! else. The paper samples E⁰ bilinearly at the fractional S⁰ instead; at
//! the finest level every pixel carries a random fraction of jitter, so
//! that low-passed the whole terrain (measured on the shared DEMs: the
//! Laplacian's spread 2–6× off the exemplar's) while leaving the joins'
//! pits (≈ 2× the exemplar's count) in place.
//!
//! The kernel output is an i32 height in database units with 8 fractional
//! bits (bit-exact on CPU and GPU): the sum of the predictions (each
//! `(E⁰ + V) << 8`, nine at most: |sum| < 2^31 for |V| < 2^22) divided by
//! their count with floor division. Neighbours outside the level do not
//! predict. Conversion to metres is a CPU-side `offset + scale · value / 256`
//! (DESIGN §6 rule 5).

use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{div_floor, round};
use crate::level::state::State;
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

/// Fractional bits of reconstructed heights.
pub const HEIGHT_FRAC_BITS: u32 = 8;

/// Rows per parallel task: each task first resolves the texel index, row
/// stride and offset of its rows and the two around them, so the nine
/// predictions of a pixel cost nine height loads, not nine coordinate
/// decodes and column lookups (the same bytes; 20.8 → 18.1 ms at 1024²
/// on 2 cores).
const ROWS: usize = 16;

/// Heights of level 0, row-major, in units × 2^8.
pub fn reconstruct(atlas: &AtlasLevel<'_>, heights: &[u16], st: &State) -> Vec<i32> {
    let mut out = vec![0i32; st.width * st.height];
    reconstruct_rect(atlas, heights, st, &mut out, [0, 0, st.width, st.height]);
    out
}

/// [`reconstruct`] of the pixels in `[x0, y0, x1, y1)` only, into `out`
/// (level-sized; the rest is left as it is). An edit's re-synthesis
/// changes S and V in a window, and a height depends on its 3×3
/// neighbourhood only, so the previous frame's heights with the window
/// widened by one pixel recomputed are the whole reconstruction.
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
    // The columns whose S and V the rect's predictions read.
    let (xa, xb) = (x0.saturating_sub(1), (x1 + 1).min(w));
    out[y0 * w..y1 * w]
        .par_chunks_mut(w * ROWS)
        .enumerate()
        .for_each(|(b, block)| {
            let y_start = y0 + b * ROWS;
            let (ya, yb) = (
                y_start.saturating_sub(1),
                (y_start + block.len() / w + 1).min(h),
            );
            // Per pixel of rows ya..yb, columns xa..xb: the index of its
            // rounded texel, its exemplar's row stride, and its offset V.
            let cols = xb - xa;
            let mut base: Vec<(i32, i32, i32)> = Vec::with_capacity((yb - ya) * cols);
            for y in ya..yb {
                base.extend((y * w + xa..y * w + xb).map(|n| {
                    let s = st.s(n);
                    let (tx, ty) = (round(s.x), round(s.y));
                    let stride = atlas.columns[tx as usize].stride as i32;
                    (atlas.index(tx, ty) as i32, stride, st.v(n))
                }));
            }
            // The prediction of neighbour (nx, ny) for the pixel at offset
            // (−dx, −dy) from it. S(n) is interior (two texels from every
            // exemplar edge), so the texel one step away is in its
            // exemplar, at index − dx − dy·stride.
            let predict = |(k, stride, v): (i32, i32, i32), dx: i32, dy: i32| {
                (heights[(k - dx - dy * stride) as usize] as i32 + v) << HEIGHT_FRAC_BITS
            };
            let line = |ny: usize| &base[(ny - ya) * cols..(ny - ya + 1) * cols];
            // Any pixel, the level's edges included.
            let pixel = |x: usize, y: usize| {
                let (mut sum, mut count) = (0i32, 0i32);
                for dy in -1..=1i32 {
                    let ny = y as i32 + dy;
                    if ny < 0 || ny >= h as i32 {
                        continue;
                    }
                    let l = line(ny as usize);
                    for dx in -1..=1i32 {
                        let nx = x as i32 + dx;
                        if nx < 0 || nx >= w as i32 {
                            continue;
                        }
                        sum += predict(l[nx as usize - xa], dx, dy);
                        count += 1;
                    }
                }
                div_floor(sum, count)
            };
            for (r, row) in block.chunks_mut(w).enumerate() {
                let y = y_start + r;
                if y == 0 || y + 1 == h || w < 3 {
                    for (x, o) in row.iter_mut().enumerate().take(x1).skip(x0) {
                        *o = pixel(x, y);
                    }
                    continue;
                }
                // Inside the level every pixel has nine neighbours: no edge
                // tests, and the mean divides by the constant 9 (the same
                // sum and floor division as at the edges).
                let lines = [line(y - 1), line(y), line(y + 1)];
                let (lo, hi) = (x0.max(1), x1.min(w - 1));
                for x in (x0..lo).chain(hi.max(lo)..x1) {
                    row[x] = pixel(x, y);
                }
                for (x, o) in row.iter_mut().enumerate().take(hi).skip(lo) {
                    let mut sum = 0i32;
                    for (l, dy) in lines.iter().zip(-1..=1i32) {
                        let n: &[_; 3] = l[x - 1 - xa..x + 2 - xa]
                            .try_into()
                            .expect("three neighbours");
                        sum += predict(n[0], -1, dy) + predict(n[1], 0, dy) + predict(n[2], 1, dy);
                    }
                    *o = div_floor(sum, 9);
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
