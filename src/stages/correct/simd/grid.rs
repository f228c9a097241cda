//! The neighbours of a chunk of a span, read once: the 5-row grid that
//! consecutive pixels of a subpass share, as a structure of arrays.

use super::super::scalar::neighbour;
use crate::database::layout::MARGIN;
use crate::level::atlas::{AtlasLevel, Column};
use crate::level::fixed::{Coord, round};
use crate::level::state::State;
use std::sync::atomic::{AtomicI32, AtomicU64, Ordering::Relaxed};

#[cfg(target_arch = "x86_64")]
mod avx2;

/// Class pixels per chunk: a chunk's neighbours are read once into a small
/// grid (5 rows × 2·CHUNK + 4 columns, ~14 KiB, in L1) that consecutive
/// pixels share — a 3×3 block and its ring overlap the next pixel's by half.
pub(super) const CHUNK: usize = 64;
pub(super) const GRID_COLS: usize = 2 * CHUNK + 4;

/// One field of every neighbour of a chunk: row r is level row y − 2 + r,
/// column j level column x0 − 2 + j.
pub(super) type Field<T> = [[T; GRID_COLS]; 5];

/// A chunk's neighbours as the kernel needs them, one array per field:
/// the hot loop reads a few fields of many neighbours (the texel index and
/// stride of nine for the candidates, the index and offset of eight for
/// N_S), so each read is one load at a constant offset from the pixel's
/// column, and a neighbour costs no more stores than the fields it has.
pub(super) struct Grid {
    /// Texel index of the rounded coordinate t(n).
    pub idx: Field<i32>,
    /// Row stride of its exemplar.
    pub stride: Field<i32>,
    /// Height offset V.
    pub v: Field<i32>,
    /// Whether some `u = t(n) − Δ` (|Δ| ≤ 1) may leave its exemplar's
    /// interior, so that C₁ = u needs the clamp: t(n) is not strictly
    /// inside the interior, or the neighbour lies outside the level (its
    /// texel is extrapolated). Elsewhere C₁ is u itself.
    pub edge: Field<bool>,
    /// The rounded coordinate t(n), read only to clamp C₁ at an edge and
    /// for the winner's coordinate.
    pub sx: Field<i32>,
    pub sy: Field<i32>,
}

impl Grid {
    /// An empty grid (every chunk fills what it reads).
    pub fn new() -> Grid {
        Grid {
            idx: [[0; GRID_COLS]; 5],
            stride: [[0; GRID_COLS]; 5],
            v: [[0; GRID_COLS]; 5],
            edge: [[true; GRID_COLS]; 5],
            sx: [[0; GRID_COLS]; 5],
            sy: [[0; GRID_COLS]; 5],
        }
    }

    /// Stores the neighbour at row `r`, column `j`.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    fn put(
        &mut self,
        r: usize,
        j: usize,
        idx: i32,
        stride: i32,
        v: i32,
        sx: i32,
        sy: i32,
        edge: bool,
    ) {
        self.idx[r][j] = idx;
        self.stride[r][j] = stride;
        self.v[r][j] = v;
        self.sx[r][j] = sx;
        self.sy[r][j] = sy;
        self.edge[r][j] = edge;
    }

    /// Stores the neighbour at row `r`, column `j`, level position (x, y)
    /// outside the level: the scalar path's [`neighbour`] (reflected, its
    /// coordinate extrapolated), addressed like any other. The extrapolated
    /// texel stays one texel inside the exemplar's interior bounds, as
    /// interior coordinates do, so the index arithmetic around it holds.
    #[cold]
    fn put_outside(
        &mut self,
        r: usize,
        j: usize,
        atlas: &AtlasLevel<'_>,
        st: &State,
        x: isize,
        y: isize,
    ) {
        let n = neighbour(atlas, st, x as i32, y as i32);
        let idx = atlas.index(n.tx, n.ty) as i32;
        let stride = atlas.columns[n.tx as usize].stride as i32;
        self.put(r, j, idx, stride, n.v, n.tx, n.ty, true);
    }

    /// Copies rows 2–3 to rows 0–1 (the next class row's top).
    #[inline(always)]
    fn shift(&mut self) {
        self.idx.copy_within(2..4, 0);
        self.stride.copy_within(2..4, 0);
        self.v.copy_within(2..4, 0);
        self.edge.copy_within(2..4, 0);
        self.sx.copy_within(2..4, 0);
        self.sy.copy_within(2..4, 0);
    }
}

/// Stores the neighbour at row `r`, column `j` of `grid`, a pixel of the
/// level whose S and V are `s` and `v`.
#[inline(always)]
fn put_pixel(
    grid: &mut Grid,
    r: usize,
    j: usize,
    columns: &[Column],
    s: &AtomicU64,
    v: &AtomicI32,
) {
    let s = Coord::unpack(s.load(Relaxed));
    let (sx, sy) = (round(s.x), round(s.y));
    let col = &columns[sx as usize];
    // Strictly inside the interior (`&`, not `&&`: no branches).
    let m = MARGIN as i32;
    let inside = (col.min_x < sx) & (sx < col.max_x) & (m < sy) & (sy < col.max_y);
    let idx = col.base + sy * col.stride as i32 + sx;
    grid.put(
        r,
        j,
        idx,
        col.stride as i32,
        v.load(Relaxed),
        sx,
        sy,
        !inside,
    );
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
///
/// `AVX2`: in the span's AVX2 copy, the row runs go four at a time
/// ([`avx2::fill_run`]).
#[inline(always)]
pub(super) fn fill<const AVX2: bool>(
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
        grid.shift();
        2
    } else {
        0
    };
    for r in first..5 {
        // Rows y ± 2 only at odd grid columns.
        let step = if r == 0 || r == 4 { 2 } else { 1 };
        let (ly, lx) = ((y + r) as isize - 2, x0 as isize - 2);
        if ly < 0 || ly >= h as isize {
            for j in (step - 1..cols).step_by(step) {
                grid.put_outside(r, j, atlas, st, lx + j as isize, ly);
            }
            continue;
        }
        let (s, v) = st.run(ly as usize * w + x0 + lo - 2, hi - lo);
        if step == 2 {
            for k in ((lo + 1) % 2..hi - lo).step_by(2) {
                put_pixel(grid, r, lo + k, columns, &s[k], &v[k]);
            }
        } else if cfg!(target_arch = "x86_64") && AVX2 {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `AVX2` is set only in the span's AVX2 copy, which runs
            // only where the CPU has AVX2 and BMI2; rows 1–3 are level rows
            // y − 1 … y + 1, which no other task writes during the subpass
            // (see `fill_run`).
            unsafe {
                avx2::fill_run(grid, r, lo, columns, s, v)
            };
        } else {
            for (k, (s, v)) in s.iter().zip(v).enumerate() {
                put_pixel(grid, r, lo + k, columns, s, v);
            }
        }
        let left = (step - 1..lo).step_by(step);
        for j in left.chain((hi + (hi + 1) % step..cols).step_by(step)) {
            grid.put_outside(r, j, atlas, st, lx + j as isize, ly);
        }
    }
}

/// The 5×5 neighbours of the pixel in grid column `c` in one field: rows
/// y − 2 … y + 2, columns x − 2 … x + 2 (not all are read). Taken once
/// per use, so that the reads at constant offsets need no bounds checks of
/// their own.
#[inline(always)]
pub(super) fn window<T>(field: &Field<T>, c: usize) -> [&[T; 5]; 5] {
    field.each_ref().map(|row| {
        row[c - 2..c + 3]
            .try_into()
            .expect("a pixel's window is 5 columns wide")
    })
}

/// The neighbour at offset (dx, dy) in a [`window`].
#[inline(always)]
pub(super) fn at<T: Copy>(win: &[&[T; 5]; 5], dx: i32, dy: i32) -> T {
    win[(2 + dy) as usize][(2 + dx) as usize]
}

/// Whether any of the 3×3 neighbours of the pixel in grid column `c` is an
/// [`Grid::edge`] one: three 4-byte reads, one per row, the fourth byte
/// masked off.
#[inline(always)]
pub(super) fn any_edge(grid: &Grid, c: usize) -> bool {
    let row = |r: usize| {
        let b: [bool; 4] = grid.edge[r][c - 1..c + 3].try_into().expect("four columns");
        u32::from_le_bytes(b.map(u8::from))
    };
    (row(1) | row(2) | row(3)) & 0x00FF_FFFF != 0
}
