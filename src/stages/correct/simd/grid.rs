//! The neighbours of a chunk of a span, read once: the 5-row grid of
//! [`Tap`]s that consecutive pixels of a subpass share, and each pixel's
//! 5×5 [`Window`] into it.

use super::super::scalar::neighbour;
use crate::level::atlas::{AtlasLevel, Column};
use crate::level::fixed::{Coord, round};
use crate::level::state::State;
use std::sync::atomic::{AtomicI32, AtomicU64, Ordering::Relaxed};

/// A neighbour as the kernel needs it.
#[derive(Clone, Copy, Default)]
pub(super) struct Tap {
    /// Texel index of the rounded coordinate.
    pub idx: i32,
    /// Row stride of its exemplar.
    pub stride: i32,
    /// Rounded coordinate.
    pub sx: i32,
    pub sy: i32,
    /// Height offset V.
    pub v: i32,
}

/// The tap of a pixel whose S and V are `s` and `v`.
#[inline(always)]
fn tap(columns: &[Column], s: &AtomicU64, v: &AtomicI32) -> Tap {
    let s = Coord::unpack(s.load(Relaxed));
    let (sx, sy) = (round(s.x), round(s.y));
    let col = &columns[sx as usize];
    Tap {
        idx: col.base + sy * col.stride as i32 + sx,
        stride: col.stride as i32,
        sx,
        sy,
        v: v.load(Relaxed),
    }
}

/// Class pixels per chunk: a chunk's neighbours are read once into a small
/// grid (5 rows × 2·CHUNK + 4 columns, ~16 KiB, in L1) that consecutive
/// pixels share — a 3×3 block and its ring overlap the next pixel's by half.
pub(super) const CHUNK: usize = 64;
pub(super) const GRID_COLS: usize = 2 * CHUNK + 4;

/// A chunk's grid: row r is level row y − 2 + r, column j level column
/// x0 − 2 + j.
pub(super) type Grid = [[Tap; GRID_COLS]; 5];

/// The tap of level position (x, y), which may lie outside the level: the
/// scalar path's [`neighbour`] (reflected, its coordinate extrapolated),
/// addressed like any other. The extrapolated texel stays one texel inside
/// the exemplar's interior bounds, as interior coordinates do, so the index
/// arithmetic around it holds.
#[cold]
fn outside(atlas: &AtlasLevel<'_>, st: &State, x: isize, y: isize) -> Tap {
    let n = neighbour(atlas, st, x as i32, y as i32);
    Tap {
        idx: atlas.index(n.tx, n.ty) as i32,
        stride: atlas.columns[n.tx as usize].stride as i32,
        sx: n.tx,
        sy: n.ty,
        v: n.v,
    }
}

/// Reads the neighbours of the `n` class pixels from column `x0` of row
/// `y` into `grid`. Rows y ± 2 are read only at odd offsets from the
/// class. `next`: the grid holds the same columns of class row y − 2,
/// whose rows 2–3 are this row's rows 0–1 (unchanged: the subpass writes
/// neither row y − 1 nor row y − 2 at odd offsets).
///
/// Neighbours outside the level (within two texels of its border) take
/// the scalar path's reflection one by one; the rest are read as row
/// slices.
#[inline(always)]
pub(super) fn fill(
    grid: &mut Grid,
    atlas: &AtlasLevel<'_>,
    st: &State,
    y: usize,
    x0: usize,
    n: usize,
    next: bool,
) {
    let (w, h) = (st.width, st.height);
    let cols = 2 * n + 3;
    // Grid columns lo..hi are level columns x0 − 2 + j inside the level.
    let lo = 2usize.saturating_sub(x0);
    let hi = cols.min(w + 2 - x0);
    let columns = &atlas.columns[..];
    let first = if next {
        grid.copy_within(2..4, 0);
        2
    } else {
        0
    };
    for (r, row) in grid.iter_mut().enumerate().skip(first) {
        // Rows y ± 2 only at odd grid columns.
        let step = if r == 0 || r == 4 { 2 } else { 1 };
        let (ly, lx) = ((y + r) as isize - 2, x0 as isize - 2);
        if ly < 0 || ly >= h as isize {
            for j in (step - 1..cols).step_by(step) {
                row[j] = outside(atlas, st, lx + j as isize, ly);
            }
            continue;
        }
        let (s, v) = st.run(ly as usize * w + x0 + lo - 2, hi - lo);
        let (row_in, j0) = (&mut row[lo..hi], (lo + 1) % step);
        if step == 2 {
            for j in (j0..hi - lo).step_by(2) {
                row_in[j] = tap(columns, &s[j], &v[j]);
            }
        } else {
            for ((t, s), v) in row_in.iter_mut().zip(s).zip(v) {
                *t = tap(columns, s, v);
            }
        }
        let left = (step - 1..lo).step_by(step);
        for j in left.chain((hi + (hi + 1) % step..cols).step_by(step)) {
            row[j] = outside(atlas, st, lx + j as isize, ly);
        }
    }
}

/// The 5×5 neighbours of one pixel: rows y − 2 … y + 2, columns x − 2 …
/// x + 2 (not all are read). Taken once per use, so that the reads at
/// constant offsets need no bounds checks of their own.
pub(super) type Window<'g> = [&'g [Tap; 5]; 5];

/// The [`Window`] of the pixel in grid column `c`.
#[inline(always)]
pub(super) fn window(grid: &Grid, c: usize) -> Window<'_> {
    grid.each_ref().map(|row| {
        row[c - 2..c + 3]
            .try_into()
            .expect("a pixel's window is 5 columns wide")
    })
}

/// The neighbour at offset (dx, dy) of the window's pixel.
#[inline(always)]
pub(super) fn at<'g>(win: &Window<'g>, dx: i32, dy: i32) -> &'g Tap {
    &win[(2 + dy) as usize][(2 + dx) as usize]
}
