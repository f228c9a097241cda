//! A local erosion filter (issue 41; `terrasynth erode`, `synth --erode`):
//! a few steps of a landscape-evolution model, each one local, so any
//! window of a world erodes to the same bytes as the same crop of the
//! whole world eroded.
//!
//! Each of [`STEPS`] steps, on the heights of the step before:
//! 1. **D8** receivers (steepest drop over distance; ties to the first
//!    neighbour clockwise from north).
//! 2. **Local drainage area**: the cells whose flow reaches a cell in at
//!    most [`REACH`] D8 steps (itself included) — flow accumulation cut
//!    off at a bounded distance upstream, by [`REACH`] rounds of every
//!    cell summing its donors' counts.
//! 3. **Stream-power incision and hillslope diffusion**: a cell sinks
//!    towards its receiver by the fraction `min(½, k·√A)` of the drop
//!    (detachment-limited stream power, E ∝ A^½·S: channels cut in more
//!    where more water gathers, and a cell never sinks below its receiver,
//!    so no pit is made), and its height moves by `d·Σ w·(neighbour −
//!    itself)` (linear creep, diagonals at half weight), which rounds off
//!    the metre-scale dimples and spikes no erosion leaves. `k = 0.01·s`,
//!    `d = 0.015·s` for strength `s`.
//!
//! **Windows ≡ crops.** A cell after a step depends on the heights within
//! `REACH + 1` cells of it, so after every step it depends on the input
//! within [`HALO`] cells: a window is eroded by eroding its extent widened
//! by [`HALO`] (clipped to the world, whose edges are the array's edges in
//! both cases) and cropping ([`window`]). Every value is computed by the
//! same f32 operations in the same order whatever the window or thread
//! count (no sums across cells but fixed neighbour orders), so the bytes
//! agree (`tests/terrain/erode.rs`).
//!
//! Measured with `eval` (README, *Erosion*): it moves the drainage and pit
//! terms towards the real exemplar on steep terrain and on real DEMs made
//! noisy, and away on gentle terrain whose real DEM owes its pits to
//! SRTM's metre steps.

use crate::heightfield::{FirstNodata, Heightfield};
use crate::synth::cone::Rect;
use rayon::prelude::*;
use thiserror::Error;

/// Erosion steps.
pub const STEPS: usize = 3;
/// D8 steps upstream the local drainage area counts.
pub const REACH: usize = 10;
/// Cells around a window its erosion reads.
pub const HALO: usize = STEPS * (REACH + 1);
/// The largest strength: diffusion stays stable (its weights sum to 6, and
/// 6·0.015·s ≤ 1).
pub const MAX_STRENGTH: f32 = 10.0;
/// The default strength.
pub const DEFAULT_STRENGTH: f32 = 1.0;

/// Why a heightfield could not be eroded.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum ErodeError {
    #[error("strength {0} is invalid: expected a finite value in 0..={MAX_STRENGTH}")]
    Strength(f32),
    #[error(
        "{count} nodata samples (the first at pixel ({x}, {y})): erosion needs every height; fill them first (terrasynth convert --fill-nodata IN OUT)"
    )]
    Nodata { count: usize, x: usize, y: usize },
    #[error("window {window:?} does not lie inside the eroded extent {extent:?}")]
    Window { window: Rect, extent: Rect },
}

/// Neighbours clockwise from north: (dx, dy), rows running south.
const AROUND: [(isize, isize); 8] = [
    (0, -1),
    (1, -1),
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
];
const R2: f32 = std::f32::consts::FRAC_1_SQRT_2;
/// 1 / distance of each neighbour.
const INV_DIST: [f32; 8] = [1.0, R2, 1.0, R2, 1.0, R2, 1.0, R2];
/// Diffusion weight of each neighbour.
const WEIGHT: [f32; 8] = [1.0, 0.5, 1.0, 0.5, 1.0, 0.5, 1.0, 0.5];
/// No receiver.
const NONE: u8 = 8;

/// A grid's neighbour geometry.
struct Grid {
    w: usize,
    h: usize,
    off: [isize; 8],
}

impl Grid {
    /// Calls `f(j, q)` for every neighbour `q` of (x, y) inside the grid,
    /// in [`AROUND`] order (the edges' path; rows inside use slices).
    fn around(&self, x: usize, y: usize, mut f: impl FnMut(usize, usize)) {
        for (j, &(dx, dy)) in AROUND.iter().enumerate() {
            if let (Some(nx), Some(ny)) = (x.checked_add_signed(dx), y.checked_add_signed(dy))
                && nx < self.w
                && ny < self.h
            {
                f(j, ny * self.w + nx);
            }
        }
    }

    /// Fills every row of `out` with `cell(x, y, neighbours)` on interior
    /// cells (`neighbours` in [`AROUND`] order, from `src`) and `edge(x, y)`
    /// on the grid's edges.
    fn rows<S: Copy + Sync, T: Send>(
        &self,
        src: &[S],
        out: &mut [T],
        cell: impl Fn(usize, usize, [S; 8]) -> T + Sync,
        edge: impl Fn(usize, usize) -> T + Sync,
    ) {
        let (w, h) = (self.w, self.h);
        out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            if y == 0 || y + 1 == h || w < 3 {
                for (x, o) in row.iter_mut().enumerate() {
                    *o = edge(x, y);
                }
                return;
            }
            let (up, mid, dn) = (
                &src[(y - 1) * w..y * w],
                &src[y * w..(y + 1) * w],
                &src[(y + 1) * w..(y + 2) * w],
            );
            row[0] = edge(0, y);
            row[w - 1] = edge(w - 1, y);
            for x in 1..w - 1 {
                let nb = [
                    up[x],
                    up[x + 1],
                    mid[x + 1],
                    dn[x + 1],
                    dn[x],
                    dn[x - 1],
                    mid[x - 1],
                    up[x - 1],
                ];
                row[x] = cell(x, y, nb);
            }
        });
    }
}

/// Steepest descent among `nb` (heights in [`AROUND`] order) from `z`.
fn steepest(z: f32, nb: impl Iterator<Item = (usize, f32)>) -> u8 {
    let (mut best, mut d) = (0.0f32, NONE);
    for (j, zn) in nb {
        let s = (z - zn) * INV_DIST[j];
        if s > best {
            (best, d) = (s, j as u8);
        }
    }
    d
}

/// Erodes `hf` (no nodata) with `strength` in 0..=[`MAX_STRENGTH`]; cell
/// size, georeference and size are kept.
pub fn erode(hf: &Heightfield, strength: f32) -> Result<Heightfield, ErodeError> {
    if !(strength.is_finite() && (0.0..=MAX_STRENGTH).contains(&strength)) {
        return Err(ErodeError::Strength(strength));
    }
    if let Some(FirstNodata { count, x, y }) = hf.first_nodata() {
        return Err(ErodeError::Nodata { count, x, y });
    }
    let (w, h) = (hf.width(), hf.height());
    let g = Grid {
        w,
        h,
        off: AROUND.map(|(dx, dy)| dy * w as isize + dx),
    };
    let (k, d) = (0.01 * strength, 0.015 * strength);
    let n = w * h;
    let mut z = hf.data().to_vec();
    let mut next = vec![0.0f32; n];
    let mut dirs = vec![NONE; n];
    let mut donors = vec![0u8; n];
    let (mut acc, mut acc_next) = (vec![1u16; n], vec![1u16; n]);
    for _ in 0..STEPS {
        g.rows(
            &z,
            &mut dirs,
            |x, y, nb| steepest(z[y * w + x], nb.into_iter().enumerate()),
            |x, y| {
                let mut nb = Vec::with_capacity(8);
                g.around(x, y, |j, q| nb.push((j, z[q])));
                steepest(z[y * w + x], nb.into_iter())
            },
        );
        // Donors: bit j set when neighbour j drains here.
        let opposite = |j: usize| ((j + 4) % 8) as u8;
        g.rows(
            &dirs,
            &mut donors,
            |_, _, nb| (0..8).fold(0u8, |m, j| m | (((nb[j] == opposite(j)) as u8) << j)),
            |x, y| {
                let mut m = 0u8;
                g.around(x, y, |j, q| m |= ((dirs[q] == opposite(j)) as u8) << j);
                m
            },
        );
        // A ≤ (2·REACH + 1)² = 441 fits u16.
        acc.fill(1);
        for _ in 0..REACH {
            g.rows(
                &acc,
                &mut acc_next,
                |x, y, nb| {
                    let m = donors[y * w + x] as u16;
                    (0..8).fold(1u16, |s, j| s + ((m >> j) & 1) * nb[j])
                },
                |x, y| {
                    let i = y * w + x;
                    let m = donors[i];
                    (0..8)
                        .filter(|j| m >> j & 1 != 0)
                        .fold(1u16, |s, j| s + acc[i.wrapping_add_signed(g.off[j])])
                },
            );
            std::mem::swap(&mut acc, &mut acc_next);
        }
        let update = |x: usize, y: usize, lap: f32| {
            let i = y * w + x;
            let zi = z[i];
            let cut = match dirs[i] {
                NONE => 0.0,
                r => {
                    let drop = zi - z[i.wrapping_add_signed(g.off[r as usize])];
                    (k * (acc[i] as f32).sqrt()).min(0.5) * drop
                }
            };
            zi + d * lap - cut
        };
        g.rows(
            &z,
            &mut next,
            |x, y, nb| {
                let zi = z[y * w + x];
                let lap = (0..8).fold(0.0f32, |s, j| s + WEIGHT[j] * (nb[j] - zi));
                update(x, y, lap)
            },
            |x, y| {
                let zi = z[y * w + x];
                let mut lap = 0.0f32;
                g.around(x, y, |j, q| lap += WEIGHT[j] * (z[q] - zi));
                update(x, y, lap)
            },
        );
        std::mem::swap(&mut z, &mut next);
    }
    let mut out = Heightfield::from_vec(w, h, hf.cell_size(), z).expect("the input's size");
    out.set_georef(hf.georef().cloned());
    Ok(out)
}

/// The extent whose erosion a window of a `world` needs: the window
/// widened by [`HALO`], clipped to the world.
pub fn extent(world: (usize, usize), window: Rect) -> Rect {
    window.widen(HALO, world)
}

/// Erodes `window` of a world from its [`extent`]'s heights `hf`: the same
/// bytes as the window's crop of the whole world eroded.
pub fn window(
    hf: &Heightfield,
    extent: Rect,
    window: Rect,
    strength: f32,
) -> Result<Heightfield, ErodeError> {
    let inside = window.x0 >= extent.x0
        && window.y0 >= extent.y0
        && window.x1 <= extent.x1
        && window.y1 <= extent.y1
        && (hf.width(), hf.height()) == (extent.width(), extent.height());
    if !inside {
        return Err(ErodeError::Window { window, extent });
    }
    let e = erode(hf, strength)?;
    Ok(e.crop(
        window.x0 - extent.x0,
        window.y0 - extent.y0,
        window.width(),
        window.height(),
    )
    .expect("the window lies inside the extent"))
}
