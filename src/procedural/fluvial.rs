//! Fluvial incision by the stream-power law (seed 002 §4.5 "River
//! Networks": drainage first, then the terrain around it), solved with the
//! implicit scheme of Braun & Willett (2013, "A very efficient O(n),
//! implicit and parallel method to solve the stream power equation").
//!
//! Each step routes water down the terrain and lowers every cell toward its
//! downstream neighbour at a rate `K · √A · S` (`A` the drainage area, `S`
//! the slope to the receiver): big rivers cut fast, small gullies slowly, so
//! the valleys organise into a branching (dendritic) network and the ground
//! between them is left standing as ridges. This is the large-scale,
//! long-time-scale counterpart of the water-and-sediment simulation in
//! [`super::hydraulic`], which cannot move water far enough in a practical
//! number of iterations to organise whole drainage basins.
//!
//! # One step
//!
//! 1. **Routing** (Priority-Flood + ε, Barnes et al. 2014): flooding inward
//!    from the grid edge in order of height fills every closed depression
//!    to its spill level plus a slope of `ε` per cell, so that every cell
//!    drains to the edge; the filled surface becomes the terrain (a lake
//!    fills with sediment). Each cell's receiver is its steepest-descent
//!    neighbour; edge cells without a lower neighbour are outlets and keep
//!    their height (the base level).
//! 2. **Drainage area**: cells in descending order pass their area on to
//!    their receiver.
//! 3. **Uplift and incision**, cells in ascending order (receiver first):
//!    `h' = (h + U + F·h'_r) / (1 + F)`, `F = K·√A / d` with `U` the uplift
//!    of the step and `d` the distance to the receiver; stable for any `K`,
//!    never lowers a cell below its receiver. Under steady uplift the
//!    terrain tends to the equilibrium `S = U / (K·√A)` (Cordonnier et al.
//!    2016): steep headwaters, gentle trunk valleys.
//!
//! The order is a heap order with ties broken by cell index, so the result is
//! fully determined by the input; the work is sequential (a flow tree has no
//! useful row parallelism) and meant for coarse levels, where a step costs
//! a few milliseconds.

use super::error::{ProceduralError, check_range};
use super::grid::{MOORE, neighbour, store, to_f64};
use super::noise::{hash2, pcg, unit};
use crate::heightfield::Heightfield;
use crate::order::Ranked;
use crate::progress::Progress;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Parameters of [`fluvial_erode`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FluvialParams {
    /// `K·Δt` of the stream-power law with area exponent ½ and slope
    /// exponent 1: a channel draining `A` square metres sinks toward its
    /// receiver by the fraction `F/(1+F)`, `F = K·√A/d`, per step.
    /// Dimensionless; in [0, 10].
    pub erodibility: f64,
    /// Minimum drop per cell across filled depressions, in metres; in [0, 1].
    pub epsilon: f64,
    pub routing: Routing,
}

/// How a cell chooses the neighbour it drains to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Routing {
    /// The steepest-descent neighbour (D8). On planar slopes D8 draws
    /// parallel channels along the 8 grid directions.
    Steepest,
    /// A downhill neighbour drawn with probability proportional to its
    /// slope, from a hash of (seed, step, cell): over many steps water
    /// spreads like multiple-flow routing and channels follow the terrain
    /// instead of the grid directions. Deterministic for a seed.
    Random(u32),
}

impl FluvialParams {
    pub fn check(&self) -> Result<(), ProceduralError> {
        check_range(
            "erodibility",
            self.erodibility,
            0.0,
            10.0,
            "a value in 0..=10",
        )?;
        check_range("epsilon", self.epsilon, 0.0, 1.0, "metres in 0..=1")
    }
}

/// Drainage of one terrain state.
struct Drainage {
    /// Cells from the lowest (outlets) up; every receiver comes before its donors.
    order: Vec<u32>,
    /// Receiver of each cell (itself for outlets).
    receiver: Vec<u32>,
    /// Distance to the receiver, metres.
    distance: Vec<f64>,
}

/// Fills depressions in `h` (in place) and routes every cell; `draw` is the
/// hash seed of this step for random routing.
fn route(
    h: &mut [f64],
    width: usize,
    height: usize,
    cell: f64,
    epsilon: f64,
    draw: Option<u32>,
) -> Drainage {
    let n = h.len();
    let mut done = vec![false; n];
    let mut heap = BinaryHeap::new();
    for y in 0..height {
        for x in 0..width {
            if x == 0 || y == 0 || x + 1 == width || y + 1 == height {
                let i = y * width + x;
                done[i] = true;
                heap.push(Reverse(Ranked(h[i], i as u32)));
            }
        }
    }
    let mut order = Vec::with_capacity(n);
    while let Some(Reverse(Ranked(hp, p))) = heap.pop() {
        order.push(p);
        let (x, y) = (p as usize % width, p as usize / width);
        for &(dx, dy, d) in &MOORE {
            if let Some(q) = neighbour(x, y, dx, dy, width, height)
                && !done[q]
            {
                done[q] = true;
                let floor = hp + epsilon * d;
                if h[q] < floor {
                    h[q] = floor;
                }
                heap.push(Reverse(Ranked(h[q], q as u32)));
            }
        }
    }
    let mut receiver: Vec<u32> = (0..n as u32).collect();
    let mut distance = vec![0.0; n];
    for y in 0..height {
        for x in 0..width {
            let p = y * width + x;
            let mut slopes = [0.0f64; 8];
            let (mut best, mut total) = (0usize, 0.0f64);
            for (i, &(dx, dy, d)) in MOORE.iter().enumerate() {
                if let Some(q) = neighbour(x, y, dx, dy, width, height) {
                    let s = (h[p] - h[q]) / d;
                    if s > 0.0 {
                        slopes[i] = s;
                        total += s;
                        if s > slopes[best] {
                            best = i;
                        }
                    }
                }
            }
            if total == 0.0 {
                continue;
            }
            let pick = match draw {
                None => best,
                Some(seed) => {
                    let mut u = unit(hash2(seed, x as i32, y as i32)) * total;
                    let mut pick = best;
                    for (i, &s) in slopes.iter().enumerate() {
                        if s > 0.0 {
                            pick = i;
                            if u < s {
                                break;
                            }
                            u -= s;
                        }
                    }
                    pick
                }
            };
            let (dx, dy, d) = MOORE[pick];
            receiver[p] =
                neighbour(x, y, dx, dy, width, height).expect("downhill neighbour exists") as u32;
            distance[p] = d * cell;
        }
    }
    Drainage {
        order,
        receiver,
        distance,
    }
}

/// Runs `iterations` stream-power steps on `hf`, raising every cell except
/// the outlets by `uplift` (metres per step, same size as `hf`) if given.
/// Refuses nodata in either.
pub fn fluvial_erode(
    hf: &mut Heightfield,
    params: &FluvialParams,
    uplift: Option<&Heightfield>,
    iterations: u32,
    progress: &dyn Progress,
) -> Result<(), ProceduralError> {
    params.check()?;
    let (w, h) = (hf.width(), hf.height());
    let cell = hf.cell_size();
    let mut heights = to_f64(hf)?;
    let uplift = match uplift {
        Some(u) if (u.width(), u.height()) == (w, h) => to_f64(u)?,
        Some(u) => {
            return Err(ProceduralError::Param {
                name: "uplift map width",
                value: u.width() as f64,
                allowed: "the size of the heightfield",
            });
        }
        None => vec![0.0; heights.len()],
    };
    let mut area = vec![0.0; heights.len()];
    progress.start("fluvial erosion", iterations as u64);
    for step in 0..iterations {
        let draw = match params.routing {
            Routing::Steepest => None,
            Routing::Random(seed) => Some(pcg(seed ^ pcg(step))),
        };
        let r = route(&mut heights, w, h, cell, params.epsilon, draw);
        area.fill(cell * cell);
        for &p in r.order.iter().rev() {
            let rcv = r.receiver[p as usize] as usize;
            if rcv != p as usize {
                area[rcv] += area[p as usize];
            }
        }
        for &p in &r.order {
            let p = p as usize;
            let rcv = r.receiver[p] as usize;
            if rcv != p {
                let f = params.erodibility * area[p].sqrt() / r.distance[p];
                heights[p] = (heights[p] + uplift[p] + f * heights[rcv]) / (1.0 + f);
            }
        }
        progress.advance(1);
    }
    progress.finish();
    store(hf, &heights);
    Ok(())
}
