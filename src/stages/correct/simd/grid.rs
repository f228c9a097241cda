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
    /// (1 or 0: bytes, so that the AVX2 fill stores eight flags at once.)
    pub edge: Field<u8>,
    /// Per column, whether rows 1–3 (the pixel's 3×3) hold an
    /// [`Grid::edge`] neighbour: formed once per fill, so that a pixel's
    /// test ([`any_edge`]) is one read instead of three rows' (~20
    /// instructions per pixel).
    pub edge3: [u8; GRID_COLS],
}

impl Grid {
    /// An empty grid (every chunk fills what it reads).
    pub fn new() -> Grid {
        Grid {
            idx: [[0; GRID_COLS]; 5],
            stride: [[0; GRID_COLS]; 5],
            v: [[0; GRID_COLS]; 5],
            edge: [[1; GRID_COLS]; 5],
            edge3: [1; GRID_COLS],
        }
    }

    /// Stores the neighbour at row `r`, column `j`.
    #[inline(always)]
    fn put(&mut self, r: usize, j: usize, idx: i32, stride: i32, v: i32, edge: bool) {
        self.idx[r][j] = idx;
        self.stride[r][j] = stride;
        self.v[r][j] = v;
        self.edge[r][j] = edge as u8;
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
        self.put(r, j, idx, stride, n.v, true);
    }

    /// Copies rows 2–4 to rows 0–2 (the next class row's top).
    #[inline(always)]
    fn shift(&mut self) {
        self.idx.copy_within(2..5, 0);
        self.stride.copy_within(2..5, 0);
        self.v.copy_within(2..5, 0);
        self.edge.copy_within(2..5, 0);
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
    grid.put(r, j, idx, col.stride as i32, v.load(Relaxed), !inside);
}

/// Reads the neighbours of the `n` class pixels from column `x0` of row
/// `y` into `grid`. Row y − 2 is read only at odd offsets from the class.
/// `next`: the grid holds the same columns of class row y − 2, whose
/// rows 2–4 are this row's rows 0–2 (unchanged since: the subpass writes
/// neither row y − 1 nor row y − 2 at odd offsets, and row y only after
/// this fill). `more`: the same task corrects class row y + 2 of these
/// columns next, so row 4 (level row y + 2) is read whole, to become that
/// row's row 2 — nothing writes row y + 2 before then, and its pixels
/// are read before they are written. Otherwise row y + 2 may belong to
/// another task, which writes its class pixels meanwhile: only its odd
/// offsets are read.
///
/// Why whole: each level row is then read once per subpass, as row 4 of
/// one class row and kept as row 2 of the next, instead of once at odd
/// offsets (one neighbour at a time) and again whole.
///
/// Neighbours outside the level (within two texels of its border) take
/// the scalar path's reflection one by one; the rest are read as row
/// slices.
///
/// `AVX2`: in the span's AVX2 copy, the whole rows go eight at a time
/// ([`avx2::fill_run`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub(super) fn fill<const AVX2: bool>(
    grid: &mut Grid,
    atlas: &AtlasLevel<'_>,
    st: &State,
    y: usize,
    x0: usize,
    n: usize,
    (next, more): (bool, bool),
) {
    let (w, h) = (st.width, st.height);
    let cols = 2 * n + 3;
    // Grid columns lo..hi are level columns x0 − 2 + j inside the level.
    let lo = 2usize.saturating_sub(x0);
    let hi = cols.min(w + 2 - x0);
    let columns = &atlas.columns[..];
    let first = if next {
        grid.shift();
        3
    } else {
        0
    };
    for r in first..5 {
        // Row y − 2, and row y + 2 unless `more`, only at odd grid columns.
        let step = if r == 0 || (r == 4 && !more) { 2 } else { 1 };
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
    // Every column, filled or stale (a constant count: vectorized); the
    // pixels read only filled ones.
    let Grid { edge, edge3, .. } = grid;
    for (j, e) in edge3.iter_mut().enumerate() {
        *e = edge[1][j] | edge[2][j] | edge[3][j];
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
/// [`Grid::edge`] one: one 4-byte read of [`Grid::edge3`], the fourth
/// byte masked off.
#[inline(always)]
pub(super) fn any_edge(grid: &Grid, c: usize) -> bool {
    let b: [u8; 4] = grid.edge3[c - 1..c + 3].try_into().expect("four columns");
    u32::from_le_bytes(b) & 0x00FF_FFFF != 0
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::{CHUNK, Field, Grid, fill};
    use crate::database::default::build_default;
    use crate::database::layout::MARGIN;
    use crate::level::atlas::AtlasLevel;
    use crate::level::fixed::{Coord, FRAC_BITS};
    use crate::level::state::State;
    use crate::progress::Silent;

    /// A state of short coherent runs (four in a row usually share an
    /// exemplar: the vector path) that jump between exemplars (its
    /// fallback) and often sit on an interior edge (the `edge` flags),
    /// with random fractions and offsets.
    fn runs_state(atlas: &AtlasLevel<'_>, w: usize, h: usize, seed: u64) -> State {
        let mut x = seed | 1;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let rects = &atlas.level.layout.rects;
        let st = State::new(w, h);
        let (mut left, mut at) = (0, (0i32, 0i32, 0i32, 0i32));
        for i in 0..w * h {
            if left == 0 {
                let r = rects[next() as usize % rects.len()];
                let (lo, hi) = ((r.x0 + MARGIN) as i32, (r.x0 + r.width - 1 - MARGIN) as i32);
                let (top, bottom) = (MARGIN as i32, (r.height - 1 - MARGIN) as i32);
                let pick = |b: u64, lo: i32, hi: i32| match b % 4 {
                    0 => lo,
                    1 => hi,
                    _ => lo + (b / 4 % (hi - lo + 1) as u64) as i32,
                };
                at = (pick(next(), lo, hi), pick(next(), top, bottom), lo, hi);
                left = 1 + next() % 12;
            }
            left -= 1;
            let b = next();
            let fx = (b & 0xFF) as i32 - 128;
            let fy = ((b >> 8) & 0xFF) as i32 - 128;
            let v = ((b >> 16) % 801) as i32 - 400;
            let s = Coord {
                x: (at.0 << FRAC_BITS) + fx,
                y: (at.1 << FRAC_BITS) + fy,
            };
            st.set(i, s, v);
            at.0 = (at.0 + 1).min(at.3);
        }
        st
    }

    fn same<T: PartialEq + std::fmt::Debug>(a: &Field<T>, b: &Field<T>, what: &str) {
        assert_eq!(a, b, "{what} differs between the AVX2 and the scalar fill");
    }

    /// `fill::<true>` (row runs eight at a time in AVX2) leaves every field
    /// of the grid as `fill::<false>` does, chunk after chunk, first rows
    /// and continued ones, at the level's borders too.
    #[test]
    fn avx2_fill_matches_the_scalar_fill() {
        if !(std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("bmi2")) {
            eprintln!("skipped: this CPU has no AVX2/BMI2");
            return;
        }
        let db = build_default(&Silent).expect("the default database builds");
        for level in [0, 1, 3] {
            let atlas = AtlasLevel::new(&db, level);
            for (w, h, seed) in [(2 * CHUNK + 9, 11, 7u64), (37, 6, 11), (5, 5, 13)] {
                let st = runs_state(&atlas, w, h, seed);
                let (mut a, mut b) = (Grid::new(), Grid::new());
                for px in 0..2 {
                    let mut x0 = px;
                    while x0 < w {
                        let n = (w - x0).div_ceil(2).min(CHUNK);
                        let rows = (px..h).step_by(2).count();
                        for (j, y) in (px..h).step_by(2).enumerate() {
                            let at = (j > 0, j + 1 < rows);
                            fill::<true>(&mut a, &atlas, &st, y, x0, n, at);
                            fill::<false>(&mut b, &atlas, &st, y, x0, n, at);
                            let at = format!("level {level} {w}x{h} row {y} from {x0}");
                            same(&a.idx, &b.idx, &format!("idx ({at})"));
                            same(&a.stride, &b.stride, &format!("stride ({at})"));
                            same(&a.v, &b.v, &format!("v ({at})"));
                            same(&a.edge, &b.edge, &format!("edge ({at})"));
                        }
                        x0 += 2 * n;
                    }
                }
            }
        }
    }
}
