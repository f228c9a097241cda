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
//! heights between them; here they run fused, each parallel task streaming
//! through a block of rows (resolving a row's texels a few rows ahead of
//! its blend, repairing a row as soon as the blends below it are known),
//! so no level-sized intermediate is needed and the rows in flight stay
//! in cache.

use super::common::{HEIGHT_FRAC_BITS, Texel, texel_height};
use super::repair_extrema::{mean, repair};
use crate::isa::prefetch;
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, div_floor, round};
use crate::level::state::State;
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;
use std::sync::atomic::Ordering::Relaxed;

/// How far from a pixel the S and V its height depends on lie: the blend
/// reads the 3×3 around it, the repair the blends of the 3×3 around it.
pub const REACH: usize = 2;

/// Rows per parallel task. A task streams through its rows and the two
/// around them on each side (the halo, which the neighbouring tasks
/// resolve too): at 64 rows, 1/32 more blends and 1/16 more resolved
/// rows than the level has.
const ROWS: usize = 64;

/// How many rows ahead of the row being blended a task resolves the
/// texels of its pixels, and asks the cache for their appearance and
/// height. The level's texels are scattered over an atlas larger than
/// the L2 cache, one run per patch; blending without the hint waits on
/// those misses one after the other (the stage at 1024² on 2 cores took
/// ~19 ms without it, ~14 with it, on a loaded machine; 2 and 3 rows
/// ahead measured alike, 1 and 6 slower).
const AHEAD: usize = 3;

/// Resolved rows a task keeps: the three a blend reads and the `AHEAD`
/// ones being prefetched fit (a power of two: the slot is `y % RING`).
const RING: usize = 8;

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
    div_floor(sum << HEIGHT_FRAC_BITS, count)
        + detail(heights[own.k as usize], smooth_height(app, own.k))
}

/// The detail `E⁰ − μ` of a texel whose height is `e` and smooth height
/// `mu`, ×2^8.
#[inline(always)]
fn detail(e: u16, mu: i32) -> i32 {
    (e as i32 - mu) << HEIGHT_FRAC_BITS
}

/// One level row's pixels as their neighbours' predictions read them
/// (columns `xa..xb` of the rect): the atlas index of each pixel's texel
/// t(n), of the texel a row above it (`k − stride`: what n predicts for
/// the pixel above it) and a row below it (`k + stride`: for the pixel
/// below), and V(n). Precomputing both saves a multiply per prediction.
struct Resolved {
    up: Vec<i32>,
    k: Vec<i32>,
    down: Vec<i32>,
    v: Vec<i32>,
    /// Whether every pixel's texel block, `up − 1 ..= down + 1`, lies in
    /// the appearance and height arrays: S is interior, so it always
    /// does, and the blend then reads them without bounds checks.
    inside: bool,
}

impl Resolved {
    /// The [`Texel`] of the pixel in column `i` (from `xa`).
    #[inline(always)]
    fn texel(&self, i: usize) -> Texel {
        Texel {
            k: self.k[i],
            stride: self.down[i] - self.k[i],
            v: self.v[i],
        }
    }
}

/// Resolves level row `y`, columns `xa..xa + r.k.len()`, into `r`, and
/// prefetches each pixel's appearance and height.
fn resolve(
    atlas: &AtlasLevel<'_>,
    heights: &[u16],
    st: &State,
    y: usize,
    xa: usize,
    r: &mut Resolved,
) {
    let app = atlas.level.appearance;
    let (s, v) = st.run(y * st.width + xa, r.k.len());
    // Indices the blend forms in i32 must not wrap there either.
    let len = app.len().min(heights.len()).min(1 << 31) as u64;
    let mut inside = true;
    let out = r.up.iter_mut().zip(&mut r.k).zip(&mut r.down).zip(&mut r.v);
    for ((((up, k), down), ov), (s, v)) in out.zip(s.iter().zip(v)) {
        let c = Coord::unpack(s.load(Relaxed));
        let (tx, ty) = (round(c.x), round(c.y));
        let stride = atlas.columns[tx as usize].stride as i32;
        let t = atlas.index(tx, ty) as i32;
        prefetch(app, t);
        prefetch(heights, t);
        (*up, *k, *down, *ov) = (t - stride, t, t + stride, v.load(Relaxed));
        // In i64, the block's ends cannot wrap; as u64, a negative one is
        // out of range too. With stride ≥ 0 the block holds `k ± 1`.
        let (first, last) = (t as i64 - stride as i64 - 1, t as i64 + stride as i64 + 1);
        inside &= (stride >= 0) & ((first as u64) < len) & ((last as u64) < len);
    }
    r.inside = inside;
}

/// The blends of an interior row's pixels in resolved columns `lo..`
/// (at least 1 from each end of the resolved rows), one per element of
/// `out`: `above`, `mid` and `below` are the resolved rows y − 1, y and
/// y + 1, `vcol[i]` the sum of the three rows' V in column i. Inside the
/// level every pixel has nine neighbours: no edge tests, and the mean
/// divides by the constant 9. Where `resolve` proved the rows' texels
/// inside the arrays (always, for a valid state) they are read without
/// bounds checks (together with index rows read as slices checked once
/// per row, ~70 fewer instructions per pixel: cachegrind, 512²).
#[inline(always)]
fn blend_interior(
    app: &[u64],
    heights: &[u16],
    [above, mid, below]: [&Resolved; 3],
    vcol: &[i32],
    lo: usize,
    out: &mut [i32],
) {
    if above.inside && mid.inside && below.inside {
        // SAFETY: every index `blend_row` reads is in one pixel's texel
        // block `up − 1 ..= down + 1` of these rows (row y − 1 gives
        // `down ± 1`, row y `k ± 1`, row y + 1 `up ± 1`, the height
        // `k`), which `resolve` found inside `app` and `heights` (and
        // below 2^31, so the i32 index arithmetic did not wrap).
        let mu = |k: i32| texel_height(unsafe { *app.get_unchecked(k as usize) });
        let e = |k: i32| unsafe { *heights.get_unchecked(k as usize) };
        blend_row([above, mid, below], vcol, lo, out, mu, e);
    } else {
        let mu = |k: i32| smooth_height(app, k);
        blend_row([above, mid, below], vcol, lo, out, mu, |k| {
            heights[k as usize]
        });
    }
}

/// [`blend_interior`] with μ and E⁰ of a texel read by `mu` and `e`.
#[inline(always)]
fn blend_row(
    [above, mid, below]: [&Resolved; 3],
    vcol: &[i32],
    lo: usize,
    out: &mut [i32],
    mu: impl Fn(i32) -> i32,
    e: impl Fn(i32) -> u16,
) {
    // The row above predicts from the texels below its own (`down`), the
    // row below from those above (`up`); the neighbours at dx = ±1 from
    // one texel back across (−dx).
    let (a, b, c) = (&above.down, &mid.k, &below.up);
    // Each column's indices and V sum are read once and kept for the
    // next two pixels (as their centre and left neighbour): 3 loads of
    // indices per pixel, not 9.
    let (hi, at) = (lo + out.len(), |r: &[i32], i| (r[i - 1], r[i]));
    let ((mut a0, mut a1), (mut b0, mut b1), (mut c0, mut c1)) = (at(a, lo), at(b, lo), at(c, lo));
    let (mut v0, mut v1) = at(vcol, lo);
    let next = a[lo + 1..=hi]
        .iter()
        .zip(&b[lo + 1..=hi])
        .zip(&c[lo + 1..=hi])
        .zip(&vcol[lo + 1..=hi]);
    for ((((&a2, &b2), &c2), &v2), o) in next.zip(out) {
        let own = mu(b1);
        let sum = mu(a0 + 1)
            + mu(a1)
            + mu(a2 - 1)
            + mu(b0 + 1)
            + own
            + mu(b2 - 1)
            + mu(c0 + 1)
            + mu(c1)
            + mu(c2 - 1)
            + v0
            + v1
            + v2;
        *o = div_floor(sum << HEIGHT_FRAC_BITS, 9) + detail(e(b1), own);
        (a0, a1, b0, b1, c0, c1, v0, v1) = (a1, a2, b1, b2, c1, c2, v1, v2);
    }
}

/// Heights of level 0, row-major, in units × 2^8.
pub fn reconstruct(atlas: &AtlasLevel<'_>, heights: &[u16], st: &State) -> Vec<i32> {
    let mut out = vec![0i32; st.width * st.height];
    crate::pages::advise_huge(&out);
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
    let cols = Cols {
        x0,
        x1,
        ca: x0.saturating_sub(1),
        cb: (x1 + 1).min(w),
        xa: x0.saturating_sub(2),
        xb: (x1 + 2).min(w),
    };
    out[y0 * w..y1 * w]
        .par_chunks_mut(w * ROWS)
        .enumerate()
        .for_each(|(b, block)| {
            let ys = y0 + b * ROWS;
            reconstruct_block(atlas, heights, st, &cols, ys, block);
        });
}

/// The columns a rect's rows involve: its own `x0..x1`, those whose blends
/// the repair reads (`ca..cb`) and those whose S and V they read (`xa..xb`).
struct Cols {
    x0: usize,
    x1: usize,
    ca: usize,
    cb: usize,
    xa: usize,
    xb: usize,
}

/// The rows `ys..` of `block` (whole level rows; columns `x0..x1` written),
/// streamed: row y + [`AHEAD`] is resolved, row y blended, row y − 1
/// repaired, so the rows in flight stay in the L1 and L2 caches.
fn reconstruct_block(
    atlas: &AtlasLevel<'_>,
    heights: &[u16],
    st: &State,
    c: &Cols,
    ys: usize,
    block: &mut [i32],
) {
    let (w, h) = (st.width, st.height);
    let app = atlas.level.appearance;
    let ye = ys + block.len() / w;
    // Blended rows ra..rb, resolved rows ya..yb.
    let (ra, rb) = (ys.saturating_sub(1), (ye + 1).min(h));
    let (ya, yb) = (ys.saturating_sub(2), (ye + 2).min(h));
    let (cols, bcols) = (c.xb - c.xa, c.cb - c.ca);
    let mut ring: Vec<Resolved> = (0..RING)
        .map(|_| {
            let row = || vec![0i32; cols];
            Resolved {
                up: row(),
                k: row(),
                down: row(),
                v: row(),
                inside: false,
            }
        })
        .collect();
    let mut blends = vec![vec![0i32; bcols]; 4];
    let mut vcol = vec![0i32; cols];
    let mut sweep = Sweep::new(bcols);
    let mut next = ya;
    for y in ra..rb {
        // Resolve up to AHEAD rows past the ones this blend reads.
        while next < yb && next <= y + 1 + AHEAD {
            resolve(atlas, heights, st, next, c.xa, &mut ring[next % RING]);
            next += 1;
        }
        let tex = |x: usize, y: usize| ring[y % RING].texel(x - c.xa);
        let brow = &mut blends[y % 4];
        let edge = |x: usize| {
            blend(app, heights, |dx, dy| {
                let (nx, ny) = (x as i32 + dx, y as i32 + dy);
                let ok = nx >= 0 && ny >= 0 && nx < w as i32 && ny < h as i32;
                ok.then(|| tex(nx as usize, ny as usize))
            })
        };
        if y == 0 || y + 1 == h || w < 3 {
            for (x, o) in (c.ca..c.cb).zip(brow.iter_mut()) {
                *o = edge(x);
            }
        } else {
            let rows = [
                &ring[(y - 1) % RING],
                &ring[y % RING],
                &ring[(y + 1) % RING],
            ];
            for (((o, a), b), d) in vcol
                .iter_mut()
                .zip(&rows[0].v)
                .zip(&rows[1].v)
                .zip(&rows[2].v)
            {
                *o = a + b + d;
            }
            let (inner0, inner1) = (c.ca.max(1), c.cb.min(w - 1));
            for x in (c.ca..inner0).chain(inner1.max(inner0)..c.cb) {
                brow[x - c.ca] = edge(x);
            }
            if inner0 < inner1 {
                let dst = &mut brow[inner0 - c.ca..inner1 - c.ca];
                blend_interior(app, heights, rows, &vcol, inner0 - c.xa, dst);
            }
        }
        if y > ys && y - 1 < ye {
            let r = y - 1;
            let out = &mut block[(r - ys) * w..(r - ys + 1) * w];
            let near = [&blends[(r + 3) % 4], &blends[r % 4], &blends[(r + 1) % 4]];
            sweep.finish(heights, c, (w, h), r, near, &tex, out);
        }
    }
    if rb == ye {
        // The level's last row: an edge row, kept as blended.
        let r = ye - 1;
        let out = &mut block[(r - ys) * w..(r - ys + 1) * w];
        out[c.x0..c.x1].copy_from_slice(&blends[r % 4][c.x0 - c.ca..c.x1 - c.ca]);
    }
}

/// The repair of one row's blends: per pixel the least and greatest of its
/// eight neighbours' blends (a vectorisable sweep: column extremes of the
/// rows above and below, then across), and [`repair`] of the few pixels
/// outside that range.
struct Sweep {
    lo: Vec<i32>,
    hi: Vec<i32>,
    near_lo: Vec<i32>,
    near_hi: Vec<i32>,
}

impl Sweep {
    fn new(bcols: usize) -> Sweep {
        let row = || vec![0i32; bcols];
        Sweep {
            lo: row(),
            hi: row(),
            near_lo: row(),
            near_hi: row(),
        }
    }

    /// Writes row y's heights (columns `x0..x1` of `row`) from the blends
    /// of rows y − 1, y and y + 1 (`[up, mid, down]`, columns `ca..cb`;
    /// only `mid` on the level's first and last rows); `tex(x, y)` is a
    /// resolved pixel.
    #[allow(clippy::too_many_arguments)]
    fn finish(
        &mut self,
        heights: &[u16],
        c: &Cols,
        (w, h): (usize, usize),
        y: usize,
        [up, mid, down]: [&Vec<i32>; 3],
        tex: &impl Fn(usize, usize) -> Texel,
        row: &mut [i32],
    ) {
        let row = &mut row[c.x0..c.x1];
        row.copy_from_slice(&mid[c.x0 - c.ca..c.x1 - c.ca]);
        if y == 0 || y + 1 == h || w < 3 {
            return;
        }
        for (((l, g), a), b) in self.lo.iter_mut().zip(&mut self.hi).zip(up).zip(down) {
            (*l, *g) = ((*a).min(*b), (*a).max(*b));
        }
        // Interior columns of the row, as indices into the blends; first
        // the range of each one's eight neighbours (a branch-free sweep),
        // then the few outside theirs.
        let (ia, ib) = (c.x0.max(1) - c.ca, c.x1.min(w - 1) - c.ca);
        if ia >= ib {
            return;
        }
        let n = ib - ia;
        let (lo, hi) = (&self.lo, &self.hi);
        let cols = (&lo[ia - 1..], &lo[ia..], &lo[ia + 1..]);
        let gcols = (&hi[ia - 1..], &hi[ia..], &hi[ia + 1..]);
        let sides = (&mid[ia - 1..], &mid[ia..], &mid[ia + 1..]);
        let near = self.near_lo[..n].iter_mut().zip(&mut self.near_hi[..n]);
        for (k, (l, g)) in near.enumerate() {
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
        for (k, &v) in sides.1[..n].iter().enumerate() {
            let range = (self.near_lo[k], self.near_hi[k]);
            if v >= range.0 && v <= range.1 {
                continue;
            }
            let x = ia + k + c.ca;
            row[x - c.x0] = repair(heights, v, range, tex(x, y), || {
                mean(heights, |dx, dy| {
                    tex((x as i32 + dx) as usize, (y as i32 + dy) as usize)
                })
            });
        }
    }
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
