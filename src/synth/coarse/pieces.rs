//! The pieces of the coarse start: where they lie, what they copy.

use super::{Pool, Source, guide};
use crate::database::layout::MARGIN;
use crate::hash::{below, hash4};
use crate::level::fixed::{Coord, FRAC_BITS};
use crate::level::state::{State, level_size};
use crate::stages::common::ALL_TYPES;
use crate::stages::upsample_jitter;
use crate::synth::cone::Rect;
use rayon::prelude::*;

/// Hash salt of the draw within a piece's band (kept apart from the
/// jitter's `hash4(seed, level, x, y)`, whose level is always < 2^16).
const SALT: u32 = 0xC0A5_0000;

/// The share of the pool a piece draws from: the ranks within ±1 % of the
/// guide's quantile.
///
/// Why a band and not the exact quantile: neighbouring pieces with nearly
/// the same guide rank would copy neighbouring texels of the same place;
/// 2 % of the pool is a few hundred texels of a shared DEM at level 3,
/// spread over its regions at that altitude.
const BAND_PER_MILLE: u32 = 20;

/// Level L of an output over `region` (absolute level-L pixels: the whole
/// level, or a window's cone): the level is cut into pieces, one per cell
/// of a grid of `side` texels anchored at the world's origin, each pixel
/// to the piece whose centre (`feature`) is nearest to it once warped
/// (`Cells::nearest`: a Voronoi mosaic with wavy edges); piece (i, j) copies
/// the exemplar around one texel of the pool, placed at its centre — drawn
/// by a hash of the seed and (i, j) from the pool's ranks around the
/// guide's rank there (balanced among the world's pieces in worlds up to
/// `guide::BALANCED_SIDE`, `guide::balance`) — mirrored at the
/// interior's edges; each pixel gets
/// the level's jitter (`jitter`, fixed point, the same hash as
/// `upsample_jitter`) and offset V = 0 (its own altitude).
///
/// Where `allowed` (the painted type sets of the region's pixels, level L)
/// constrains a pixel, its piece is drawn the same way from the pool of
/// those types' texels; a pixel's piece is thus a function of its own type
/// set, not of its neighbours', so a painted edge cuts a piece in two.
///
/// Why not square pieces: correction reshapes most joins, but not all — a
/// sea piece beside a land piece kept its straight edge as a straight
/// shore, and the grid showed through as box-shaped massifs and
/// staircase coasts (issue 46). Cut along wavy edges at random angles,
/// the joins that survive look like the exemplar's own boundaries (on the
/// 8 shared DEMs the figures are the same to a point or two).
///
/// A piece depends on the seed, its position and the pixel's type set
/// alone, so any window of a world starts from the same pieces.
pub fn pieces(
    src: Source<'_>,
    region: Rect,
    world: (usize, usize),
    (l, side): (usize, i32),
    seed: u32,
    jitter: i32,
    allowed: Option<&[u32]>,
) -> State {
    let (w, h) = (region.width(), region.height());
    // The pieces whose cells lie within the warp's reach of the region,
    // and the texel each is centred on.
    let cell = |v: i32| v.div_euclid(side);
    let reach = 2;
    let (i0, j0) = (
        cell(region.x0 as i32) - reach,
        cell(region.y0 as i32) - reach,
    );
    let (ni, nj) = (
        (cell(region.x1 as i32 - 1) + reach - i0 + 1) as usize,
        (cell(region.y1 as i32 - 1) + reach - j0 + 1) as usize,
    );
    let cells = Cells::new(seed, side, (i0, j0), (ni, nj));
    // A piece's centre in output pixels, where the guide is read.
    let place = |(fx, fy): (i32, i32)| ((2 * fx + 1) << l >> 1, (2 * fy + 1) << l >> 1);
    let places: Vec<(i32, i32)> = cells.features.iter().map(|&f| place(f)).collect();
    let (scale, steps) = (src.pool.scale(), guide::rank_steps(world));
    let mut quantiles = guide::quantiles(seed, scale, steps, &places);
    if world.0.max(world.1) <= guide::BALANCED_SIDE {
        // Every piece of the world, whatever the region: a window is
        // balanced as the whole is.
        let (wl, hl) = level_size(world.0, world.1, l);
        let (ci, cj) = (cell(wl as i32 - 1) + 1, cell(hl as i32 - 1) + 1);
        let all: Vec<(i32, i32)> = (0..ci * cj)
            .map(|k| place(feature(seed, side, (k % ci, k / ci))))
            .collect();
        guide::balance(&mut quantiles, guide::quantiles(seed, scale, steps, &all));
    }
    // The pool of every type set painted in the region (the whole pool
    // where a set has no texel at this level: type seeding then does what
    // it can, as it did before).
    let mut masks: Vec<u32> = allowed.map_or(Vec::new(), |a| {
        a.iter().copied().filter(|&m| m != ALL_TYPES).collect()
    });
    masks.sort_unstable();
    masks.dedup();
    let typed: Vec<(u32, Pool)> = masks
        .into_iter()
        .map(|m| (m, src.pool.of_types(src.atlas, m)))
        .filter(|(_, p)| !p.is_empty())
        .collect();
    let pool_of = |mask: u32| {
        typed
            .iter()
            .find(|(m, _)| *m == mask)
            .map_or(src.pool, |(_, p)| p)
    };
    let centres: Vec<(i32, i32)> = (0..ni * nj)
        .into_par_iter()
        .map(|k| draw(src.pool, quantiles[k], seed, cells.ij(k)))
        .collect();
    let st = State::new(w, h);
    (0..h).into_par_iter().for_each(|r| {
        let y = (region.y0 + r) as i32;
        for c in 0..w {
            let x = (region.x0 + c) as i32;
            let (k, (fx, fy)) = cells.nearest((x, y));
            let (i, j) = cells.ij(k);
            let (cx, cy) = match allowed.map_or(ALL_TYPES, |a| a[r * w + c]) {
                ALL_TYPES => centres[k],
                mask => draw(pool_of(mask), painted(quantiles[k]), seed, (i, j)),
            };
            let col = src.atlas.columns[cx as usize];
            let (x0, y0) = (col.min_x, MARGIN as i32);
            let (nx, ny) = (col.max_x - x0 + 1, col.max_y - y0 + 1);
            let tx = x0 + mirror(cx - x0 + x - fx, nx);
            let ty = y0 + mirror(cy - y0 + y - fy, ny);
            let (jx, jy) = upsample_jitter::jitter(seed, l as u32, x as u32, y as u32, jitter);
            let s = Coord {
                x: inside((tx << FRAC_BITS) + jx, x0, nx),
                y: inside((ty << FRAC_BITS) + jy, y0, ny),
            };
            st.set(r * w + c, s, 0);
        }
    });
    st
}

/// The centre of piece (i, j) (level-L texels): a place of its cell of
/// the `side`-texel grid, drawn by a hash, at most 3/8 of a side from the
/// cell's centre (so every piece keeps a share of its cell).
fn feature(seed: u32, side: i32, (i, j): (i32, i32)) -> (i32, i32) {
    let a = side * 3 / 8;
    let off = |salt: u32| {
        below(
            hash4(seed, SALT | salt, i as u32, j as u32),
            (2 * a + 1) as u32,
        ) as i32
            - a
    };
    (i * side + side / 2 + off(1), j * side + side / 2 + off(2))
}

/// The hashed values of the cells of the `side`-texel grid within reach
/// of a region (`ni` × `nj` from cell (`i0`, `j0`), row-major): each
/// piece's centre ([`feature`]) and the warp's lattice values (salts 3 and
/// 4, in `[−side/3, side/3]`).
///
/// Why a table: every texel reads nine centres and eight lattice values;
/// hashed per texel they were a twentieth of a 1024² synthesis.
struct Cells {
    side: i32,
    i0: i32,
    j0: i32,
    ni: usize,
    features: Vec<(i32, i32)>,
    warps: Vec<(i64, i64)>,
}

impl Cells {
    fn new(seed: u32, side: i32, (i0, j0): (i32, i32), (ni, nj): (usize, usize)) -> Cells {
        let amp = side / 3;
        let lattice = |salt: u32, (i, j): (i32, i32)| {
            let h = hash4(seed, SALT | salt, i as u32, j as u32);
            i64::from(below(h, (2 * amp + 1) as u32) as i32 - amp)
        };
        let mut cells = Cells {
            side,
            i0,
            j0,
            ni,
            features: Vec::with_capacity(ni * nj),
            warps: Vec::with_capacity(ni * nj),
        };
        for k in 0..ni * nj {
            let ij = cells.ij(k);
            cells.features.push(feature(seed, side, ij));
            cells.warps.push((lattice(3, ij), lattice(4, ij)));
        }
        cells
    }

    /// The cell (i, j) at table index `k`.
    fn ij(&self, k: usize) -> (i32, i32) {
        (
            self.i0 + (k % self.ni) as i32,
            self.j0 + (k / self.ni) as i32,
        )
    }

    /// The table index of cell (i, j).
    fn at(&self, (i, j): (i32, i32)) -> usize {
        (j - self.j0) as usize * self.ni + (i - self.i0) as usize
    }

    /// The piece texel (x, y) belongs to (its table index), and its
    /// centre: of the features of the 3×3 cells around the place
    /// displaced by [`Cells::warp`], the nearest (squared distance; ties
    /// to the first in row order), so the cells' straight Voronoi edges
    /// come out wavy. (A feature two cells away can rarely be nearer;
    /// leaving it out keeps the piece a function of the 3×3 alone.) The
    /// displaced place lies within a cell of (x, y)'s and the chosen centre
    /// within a cell of it: `pieces` takes the cells two around the region.
    fn nearest(&self, (x, y): (i32, i32)) -> (usize, (i32, i32)) {
        let side = self.side;
        let (dx, dy) = self.warp(x, y);
        let (wx, wy) = (x + dx, y + dy);
        let (ci, cj) = (wx.div_euclid(side), wy.div_euclid(side));
        let mut best = (0, (0, 0), i64::MAX);
        for dj in -1..=1 {
            for di in -1..=1 {
                let k = self.at((ci + di, cj + dj));
                let f = self.features[k];
                let (dx, dy) = (i64::from(f.0 - wx), i64::from(f.1 - wy));
                let d = dx * dx + dy * dy;
                if d < best.2 {
                    best = (k, f, d);
                }
            }
        }
        (best.0, best.1)
    }

    /// The displacement of (x, y): two value noises of up to a third of a
    /// side on the cells' lattice, interpolated bilinearly in integers.
    fn warp(&self, x: i32, y: i32) -> (i32, i32) {
        let side = self.side;
        let k = self.at((x.div_euclid(side), y.div_euclid(side)));
        let (fx, fy) = (i64::from(x.rem_euclid(side)), i64::from(y.rem_euclid(side)));
        let n = i64::from(side);
        let (v00, v10) = (self.warps[k], self.warps[k + 1]);
        let (v01, v11) = (self.warps[k + self.ni], self.warps[k + self.ni + 1]);
        let mix = |a: i64, b: i64, c: i64, d: i64| {
            let top = a * (n - fx) + b * fx;
            let bottom = c * (n - fx) + d * fx;
            (top * (n - fy) + bottom * fy).div_euclid(n * n) as i32
        };
        (
            mix(v00.0, v10.0, v01.0, v11.0),
            mix(v00.1, v10.1, v01.1, v11.1),
        )
    }
}

/// The quantile a painted pixel draws at: the guide's `u` pulled halfway
/// to the median (1/2^16 units).
///
/// Why: a type's extreme ranks are its odd places — the flats at the top
/// of their altitudes are mountain plateaus, the mountains at the bottom
/// valley floors — and across a painted region the guide's rank sweeps
/// most of its range, so neighbouring pieces came from places hundreds of
/// metres apart in altitude, joined by ramps. Halved, a painted disc (512²,
/// embedded database, seeds 11–13) has its type's local relief on sea 84,
/// flat 73, hills 82, mountains 79 % of its area (at the full range 83,
/// 67, 80, 74 %; a quarter of it: 85, 71, 81, 75 %).
fn painted(u: u32) -> u32 {
    (u + (1 << 15)) / 2
}

/// The texel piece (i, j) copies from `pool`: drawn by a hash of the seed
/// and (i, j) among the [`BAND_PER_MILLE`] of the pool around the guide's
/// quantile `u` (in 1/2^16).
fn draw(pool: &Pool, u: u32, seed: u32, (i, j): (i32, i32)) -> (i32, i32) {
    let n = pool.len();
    let band = ((u64::from(n) * u64::from(BAND_PER_MILLE) / 1000) as u32).clamp(1, n);
    let target = ((u64::from(u) * u64::from(n - 1)) >> 16) as u32;
    let lo = target.saturating_sub(band / 2).min(n - band);
    pool.at(lo + below(hash4(seed, SALT, i as u32, j as u32), band))
}

/// Texel `t` of an axis of `n` interior texels, mirrored at both ends
/// (…, 1, 0 | 0, 1, …, n − 1 | n − 1, n − 2, …).
fn mirror(t: i32, n: i32) -> i32 {
    let r = t.rem_euclid(2 * n);
    if r < n { r } else { 2 * n - 1 - r }
}

/// Fixed-point `v` clamped to `[min − ½, min + n − ½)` texels, so that it
/// rounds (half up) to one of the `n` interior texels from `min` (jitter may
/// carry a mirrored edge texel half a texel out).
fn inside(v: i32, min: i32, n: i32) -> i32 {
    let half = 1 << (FRAC_BITS - 1);
    v.clamp(
        (min << FRAC_BITS) - half,
        ((min + n) << FRAC_BITS) - half - 1,
    )
}
