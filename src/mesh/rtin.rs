//! The adaptive triangulation: a right-triangulated irregular network
//! (RTIN, Evans, Kirkpatrick & Townsend 2001; the bintree of mapbox's
//! Martini), with the **true** vertical error of each triangle instead of
//! Martini's midpoint estimate, so that the bound holds at every sample.
//!
//! - An RTIN lives on a (2^k + 1)² grid: the grid is covered by square
//!   blocks of B = 2^k cells, B the largest power of two that fits its
//!   shorter side (and a tile), padded on the east and south to whole
//!   blocks. A triangle with a corner in the padding but its box reaching
//!   into the grid is always split; one wholly in the padding is dropped.
//!   Bintree triangles have their corners on samples, so at the finest
//!   level (legs of one cell) each lies in the grid or out of it: the
//!   result covers the grid exactly, whatever its size.
//! - A triangle is split at its hypotenuse's midpoint when the error stored
//!   there exceeds the bound. That error is the larger of the two
//!   triangles sharing the hypotenuse (whole blocks included: blocks
//!   share their border samples) and of their children's, so a split
//!   always splits the neighbour too (no T-junctions, across blocks and
//!   tiles as well), and a kept triangle is within the bound at every
//!   sample it covers.
//! - Tiles are unions of blocks, so every triangle lies in one tile and
//!   the tiles of one triangulation share their border vertices exactly.

use super::MeshError;
use super::measure::triangle_error;
use crate::heightfield::Heightfield;
use crate::io::check_memory;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering};

/// A triangle as (a, b, c): hypotenuse a–b, right angle at c, in samples.
type Tri = [[i64; 2]; 3];

/// The split errors of every sample of a heightfield's RTIN.
pub struct Errors<'a> {
    hf: &'a Heightfield,
    /// Block side in cells (a power of two).
    block: usize,
    /// Blocks per row and column.
    blocks: (usize, usize),
    /// Samples per padded row (`blocks.0 × block + 1`).
    stride: usize,
    /// Per padded sample: the bits of a non-negative f32 (ordered like the
    /// floats, so an atomic max on them is a max on the errors).
    err: Vec<AtomicU32>,
}

/// The depth of the triangles whose hypotenuse midpoints are samples run
/// from 1 (the two halves of a block) to 2k for B = 2^k.
fn depths(block: usize) -> u32 {
    2 * block.trailing_zeros()
}

/// The bintree's triangle `id` (depth ⌊log₂ id⌋ ≥ 1) of a block of side
/// `b` at `origin` (Martini's numbering: the low bit picks the root, the
/// next ones the children on the way down).
fn decode(mut id: usize, b: i64, origin: [i64; 2]) -> Tri {
    let (mut a, mut bb, mut c) = if id & 1 == 1 {
        ([0, 0], [b, b], [b, 0])
    } else {
        ([b, b], [0, 0], [0, b])
    };
    loop {
        id >>= 1;
        if id <= 1 {
            break;
        }
        let m = mid(a, bb);
        if id & 1 == 1 {
            (a, bb, c) = (c, a, m);
        } else {
            (a, bb, c) = (bb, c, m);
        }
    }
    [a, bb, c].map(|p| [p[0] + origin[0], p[1] + origin[1]])
}

fn mid(a: [i64; 2], b: [i64; 2]) -> [i64; 2] {
    [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2]
}

impl<'a> Errors<'a> {
    /// Computes the errors of `hf` (no nodata, at least 2×2) with blocks of
    /// at most `max_block` cells.
    pub fn compute(hf: &'a Heightfield, max_block: usize) -> Result<Self, MeshError> {
        let (w, h) = (hf.width() - 1, hf.height() - 1);
        let fit = w.min(h).min(max_block).max(1);
        let block = 1usize << fit.ilog2();
        let blocks = (w.div_ceil(block), h.div_ceil(block));
        let stride = blocks.0 * block + 1;
        let len = stride * (blocks.1 * block + 1);
        check_memory(
            &format!("the adaptive triangulation of a {}x{} grid", w + 1, h + 1),
            len as u64 * 4,
        )?;
        let mut e = Errors {
            hf,
            block,
            blocks,
            stride,
            err: (0..len).map(|_| AtomicU32::new(0)).collect(),
        };
        e.fill();
        Ok(e)
    }

    /// Depth by depth, finest first, so that every child's error is final
    /// (both of its sides done) before its parents read it.
    fn fill(&mut self) {
        let nblocks = self.blocks.0 * self.blocks.1;
        let deepest = depths(self.block);
        for depth in (1..=deepest).rev() {
            let per_block = 1usize << depth;
            (0..nblocks * per_block).into_par_iter().for_each(|k| {
                let t = decode(
                    per_block + k % per_block,
                    self.block as i64,
                    self.origin(k / per_block),
                );
                let e = match self.place(&t) {
                    Place::Inside => {
                        let mut e = triangle_error(self.hf, t);
                        if depth < deepest {
                            let [a, b, c] = t;
                            e = e.max(self.get(mid(c, a))).max(self.get(mid(b, c)));
                        }
                        e
                    }
                    Place::Straddles => f32::INFINITY,
                    Place::Outside => return,
                };
                self.err[self.index(mid(t[0], t[1]))].fetch_max(e.to_bits(), Ordering::Relaxed);
            });
        }
    }

    fn origin(&self, block: usize) -> [i64; 2] {
        let b = self.block as i64;
        [
            (block % self.blocks.0) as i64 * b,
            (block / self.blocks.0) as i64 * b,
        ]
    }

    fn index(&self, p: [i64; 2]) -> usize {
        p[1] as usize * self.stride + p[0] as usize
    }

    fn get(&self, p: [i64; 2]) -> f32 {
        f32::from_bits(self.err[self.index(p)].load(Ordering::Relaxed))
    }

    fn place(&self, t: &Tri) -> Place {
        let (w, h) = (self.hf.width() as i64 - 1, self.hf.height() as i64 - 1);
        if t.iter().all(|p| p[0] <= w && p[1] <= h) {
            Place::Inside
        } else if t.iter().map(|p| p[0]).min() < Some(w) && t.iter().map(|p| p[1]).min() < Some(h) {
            Place::Straddles
        } else {
            Place::Outside
        }
    }

    /// Walks the kept triangles of every block for `bound`, handing each
    /// to `emit`.
    fn walk(&self, bound: f32, emit: &mut impl FnMut(&Tri)) {
        let b = self.block as i64;
        for k in 0..self.blocks.0 * self.blocks.1 {
            for root in [2, 3] {
                let mut stack = vec![decode(root, b, self.origin(k))];
                while let Some(t) = stack.pop() {
                    let [a, bb, c] = t;
                    match self.place(&t) {
                        Place::Outside => continue,
                        _ if (a[0] - c[0]).abs() + (a[1] - c[1]).abs() > 1
                            && self.get(mid(a, bb)) > bound =>
                        {
                            let m = mid(a, bb);
                            stack.push([bb, c, m]);
                            stack.push([c, a, m]);
                        }
                        _ => emit(&t),
                    }
                }
            }
        }
    }

    /// How many triangles `bound` keeps.
    pub fn count(&self, bound: f32) -> usize {
        let mut n = 0;
        self.walk(bound, &mut |_| n += 1);
        n
    }

    /// The triangles `bound` keeps, as sample indices (`y × width + x`)
    /// counter-clockwise seen from above.
    pub fn extract(&self, bound: f32) -> Vec<[u32; 3]> {
        let w = self.hf.width() as i64;
        let mut out = Vec::new();
        self.walk(bound, &mut |t| {
            let [a, b, c] = *t;
            // Counter-clockwise from above is clockwise in (column, row).
            let t = if super::measure::orient(a, b, c) < 0 {
                [a, b, c]
            } else {
                [a, c, b]
            };
            out.push(t.map(|p| (p[1] * w + p[0]) as u32));
        });
        out
    }

    /// The smallest bound that keeps at most `n` triangles (the coarsest
    /// triangulation's bound when none does): a binary search on the
    /// bits of the non-negative floats, which order like the floats.
    pub fn bound_for(&self, n: usize) -> f32 {
        let top = self
            .err
            .iter()
            .map(|e| f32::from_bits(e.load(Ordering::Relaxed)))
            .filter(|e| e.is_finite())
            .fold(0.0f32, f32::max);
        let (mut lo, mut hi) = (0u32, top.to_bits());
        if self.count(top) > n {
            return top;
        }
        while lo < hi {
            let m = lo + (hi - lo) / 2;
            if self.count(f32::from_bits(m)) <= n {
                hi = m;
            } else {
                lo = m + 1;
            }
        }
        f32::from_bits(lo)
    }
}

enum Place {
    /// Every corner a sample of the grid.
    Inside,
    /// A corner in the padding, the box reaching into the grid: split.
    Straddles,
    /// In the padding: dropped.
    Outside,
}
