//! Thermal erosion (seed 002 §7.3.1, after Musgrave et al. 1989): material
//! on slopes steeper than the talus angle crumbles and slides to the lower
//! neighbours, leaving straight talus aprons at the foot of cliffs.
//!
//! # Rule
//!
//! For a cell p and each of its 8 neighbours q at distance `dist` (1 or √2
//! cells), the excess is `e_pq = h_p − h_q − T·dist`, with `T = talus ×
//! cell size` the largest height step per cell that is stable (optionally
//! varying from cell to cell, see [`ThermalParams::variation`]; the source
//! cell's talus applies to what it sheds). If some
//! excess is positive, p sheds `c · max_q e_pq` in total, split among the
//! neighbours in proportion to their positive excess (Musgrave distributes by
//! height difference; by excess, a barely-too-steep neighbour gets barely
//! anything, which converges without ripples).
//!
//! # Jacobi update
//!
//! Every iteration reads only the previous heights: pass 1 stores each cell's
//! shedding factor `k_p = c·max e / Σ e`; pass 2 gives each cell its height
//! minus what it sheds plus what its higher neighbours shed onto it, with the
//! flow p → q evaluated by one expression on both sides, so what leaves p
//! arrives at q bit for bit. The result does not depend on traversal order or
//! thread count, mass is conserved up to summation rounding (the grid edge is
//! closed), and `c ≤ ½` keeps a pair of cells from overshooting each other.

use super::error::{ProceduralError, check_range};
use super::fbm::Fractal;
use super::grid::{MOORE, neighbour, store, sweep, to_f64};
use crate::heightfield::Heightfield;
use crate::progress::Progress;

/// Parameters of [`thermal_erode`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ThermalParams {
    /// Talus slope: the steepest stable slope as rise over run
    /// (dimensionless, tan of the talus angle; 0.7 ≈ 35°), in [0, 100].
    /// Converted to a height step per cell with the heightfield's cell size.
    pub talus: f64,
    /// Fraction `c` of the largest excess shed per iteration, in (0, 0.5].
    pub rate: f64,
    /// Spatial variation of the talus slope, in [0, 0.9]: each cell's talus
    /// is `talus · (1 + variation · n)`, `n ∈ [−1, 1]` a smooth noise with
    /// features about 8 cells across (rock of varying strength). Uniform
    /// talus makes every eroded slope the same plane; a varying one leaves
    /// buttresses, benches and chutes. 0 disables it.
    pub variation: f64,
    /// Seed of the variation noise.
    pub seed: u32,
}

impl ThermalParams {
    pub fn check(&self) -> Result<(), ProceduralError> {
        check_range(
            "talus",
            self.talus,
            0.0,
            100.0,
            "a slope (rise over run) in 0..=100",
        )?;
        check_range("rate", self.rate, 1e-6, 0.5, "a fraction in (0, 0.5]")?;
        check_range(
            "variation",
            self.variation,
            0.0,
            0.9,
            "a fraction in 0..=0.9",
        )
    }

    /// The talus height step per cell (metres per cell of distance) at each cell.
    fn steps(&self, width: usize, height: usize, cell_size: f64) -> Vec<f64> {
        let base = self.talus * cell_size;
        let mut out = vec![base; width * height];
        if self.variation > 0.0 {
            let noise = Fractal {
                octaves: 3,
                h: 0.5,
                ..Fractal::new(self.seed, 1.0 / 8.0)
            };
            let scale = self.variation / noise.amplitude_sum();
            sweep(&mut out, width, |x, y| {
                base * (1.0 + scale * noise.sample(x as f64, y as f64))
            });
        }
        out
    }
}

/// The flow from `src` to `dst` for shedding factor `k` and threshold `t`.
/// Both cells evaluate exactly this expression, which makes the exchange
/// conservative bit for bit.
#[inline]
fn flow(k: f64, h_src: f64, h_dst: f64, t: f64) -> f64 {
    k * ((h_src - h_dst) - t)
}

/// Runs `iterations` Jacobi iterations of thermal erosion on `hf`.
/// Refuses heightfields with nodata (a NaN would spread to its neighbours).
pub fn thermal_erode(
    hf: &mut Heightfield,
    params: &ThermalParams,
    iterations: u32,
    progress: &dyn Progress,
) -> Result<(), ProceduralError> {
    params.check()?;
    let (w, h) = (hf.width(), hf.height());
    let mut cur = to_f64(hf)?;
    let mut next = vec![0.0; cur.len()];
    let mut k = vec![0.0; cur.len()];
    let steps = params.steps(w, h, hf.cell_size());
    progress.start("thermal erosion", iterations as u64);
    for _ in 0..iterations {
        sweep(&mut k, w, |x, y| {
            let hp = cur[y * w + x];
            let step = steps[y * w + x];
            let (mut max, mut sum) = (0.0f64, 0.0f64);
            for &(dx, dy, d) in &MOORE {
                if let Some(q) = neighbour(x, y, dx, dy, w, h) {
                    let e = (hp - cur[q]) - step * d;
                    if e > 0.0 {
                        max = max.max(e);
                        sum += e;
                    }
                }
            }
            if sum > 0.0 {
                params.rate * max / sum
            } else {
                0.0
            }
        });
        sweep(&mut next, w, |x, y| {
            let p = y * w + x;
            let hp = cur[p];
            let mut v = hp;
            for &(dx, dy, d) in &MOORE {
                if let Some(q) = neighbour(x, y, dx, dy, w, h) {
                    let hq = cur[q];
                    let (tp, tq) = (steps[p] * d, steps[q] * d);
                    if (hp - hq) - tp > 0.0 {
                        v -= flow(k[p], hp, hq, tp);
                    } else if (hq - hp) - tq > 0.0 {
                        v += flow(k[q], hq, hp, tq);
                    }
                }
            }
            v
        });
        std::mem::swap(&mut cur, &mut next);
        progress.advance(1);
    }
    progress.finish();
    store(hf, &cur);
    Ok(())
}
