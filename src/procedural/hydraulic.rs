//! Grid-based hydraulic (fluvial) erosion (seed 002 §7.3.2, after Musgrave
//! et al. 1989 with Beneš & Forsbach's evaporation): every cell carries
//! terrain height `b`, water depth `d` and suspended sediment `s`, all in
//! metres. One step:
//!
//! 1. **Rain**: `rain` metres of water fall on every cell.
//! 2. **Flow**: water runs to every neighbour whose surface level `L = b + d`
//!    is lower, `k · w · (L_p − L_q)` to each (`w` = 1 for edge neighbours, ½
//!    for diagonal ones; `k` = `flow_rate`), scaled down so that no cell
//!    sends more water than it holds. Sediment travels with the water: a
//!    flow carrying a fraction of a cell's water carries the same fraction of
//!    its sediment. With `k ≤ ⅛` the level exchange is a stable,
//!    non-oscillating explicit diffusion.
//! 3. **Erosion / deposition**: the water leaving a cell can carry
//!    `C = capacity · outflow · slope` of sediment, `slope` being the
//!    steepest descent of the water surface (rise over run). Below capacity
//!    the flow dissolves `dissolve · (C − s)` from the terrain (never cutting
//!    a cell below its lowest neighbour inside the grid, so no pits are dug
//!    and an open edge cannot run away); above it,
//!    `deposit · (s − C)` settles. Fast water on steep ground cuts, slowing
//!    water on flats and in basins drops its load.
//! 4. **Evaporation**: a fraction `evaporation` of each cell's water leaves,
//!    which bounds how far water and sediment travel.
//!
//! Concentrated flow erodes more, deepening the channels that concentrate it:
//! this feedback carves branching drainage.
//!
//! # Determinism and mass
//!
//! Each step is two Jacobi passes (flow factors, then a gather of inflows),
//! each cell reading only the previous step's buffers; every flow is
//! evaluated by the same expression at its source and at its destination,
//! so terrain + sediment is conserved bit for bit per exchange (up to
//! summation rounding) and water changes only by rain, evaporation and what
//! leaves through an open edge. [`Budget`] accounts for those, summed per row
//! and then in row order, so it too is independent of the thread count.

use super::error::{ProceduralError, check_range};
use super::grid::{MOORE, neighbour, store, to_f64};
use crate::heightfield::Heightfield;
use crate::progress::Progress;
use rayon::prelude::*;

/// What happens at the grid edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Boundary {
    /// A wall: nothing leaves, so mass is conserved exactly.
    Closed,
    /// The terrain continues outside with the edge's slope (linear
    /// extrapolation) and without water: rivers that reach the edge leave the
    /// map with their sediment, as from a crop of a larger landscape.
    Open,
}

/// Parameters of [`hydraulic_erode`]; lengths in metres, rates per step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HydraulicParams {
    /// Water added to every cell per step, in metres; in [0, 10].
    pub rain: f64,
    /// Fraction of each cell's water that evaporates per step; in [0, 1).
    pub evaporation: f64,
    /// Fraction `k` of a level difference that flows per step; in (0, 0.125].
    pub flow_rate: f64,
    /// Sediment (metres) carried per metre of outflowing water and unit slope; in [0, 100].
    pub capacity: f64,
    /// Fraction of the capacity deficit dissolved per step; in [0, 1].
    pub dissolve: f64,
    /// Fraction of the sediment excess deposited per step; in [0, 1].
    pub deposit: f64,
    pub boundary: Boundary,
}

impl HydraulicParams {
    pub fn check(&self) -> Result<(), ProceduralError> {
        check_range("rain", self.rain, 0.0, 10.0, "metres per step in 0..=10")?;
        check_range(
            "evaporation",
            self.evaporation,
            0.0,
            0.999_999,
            "a fraction in [0, 1)",
        )?;
        check_range(
            "flow_rate",
            self.flow_rate,
            1e-6,
            0.125,
            "a fraction in (0, 0.125]",
        )?;
        check_range("capacity", self.capacity, 0.0, 100.0, "a value in 0..=100")?;
        check_range("dissolve", self.dissolve, 0.0, 1.0, "a fraction in [0, 1]")?;
        check_range("deposit", self.deposit, 0.0, 1.0, "a fraction in [0, 1]")
    }
}

/// Water and sediment that entered or left the grid, in cubic metres per
/// square metre of one cell (i.e. metres summed over cells).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Budget {
    pub rained: f64,
    pub evaporated: f64,
    /// Water that left through an open edge.
    pub drained_water: f64,
    /// Sediment that left through an open edge.
    pub drained_sediment: f64,
}

#[derive(Debug, Clone, Copy, Default)]
struct Cell {
    terrain: f64,
    water: f64,
    sediment: f64,
    /// Surface level including the rain of the coming step.
    level: f64,
}

#[derive(Debug, Clone, Copy, Default)]
struct Share {
    /// `k` times the scale that keeps the outflow within the cell's water.
    k: f64,
    /// Sediment per metre of water, carried along with every outflow.
    ratio: f64,
}

/// Flow weight of the neighbour at `MOORE[i]`: 1 along an edge, ½ diagonally.
const WEIGHTS: [f64; 8] = [0.5, 1.0, 0.5, 1.0, 1.0, 0.5, 1.0, 0.5];

/// The water flow from a cell with share `k` and level `l_src` to a lower
/// level `l_dst` through a link of weight `w`. Source and destination both
/// evaluate exactly this, so every exchange conserves mass bit for bit.
#[inline]
fn flow(k: f64, w: f64, l_src: f64, l_dst: f64) -> f64 {
    k * (w * (l_src - l_dst))
}

/// A running hydraulic erosion simulation.
#[derive(Debug, Clone)]
pub struct Hydraulic {
    width: usize,
    height: usize,
    cell_size: f64,
    params: HydraulicParams,
    cells: Vec<Cell>,
    next: Vec<Cell>,
    shares: Vec<Share>,
    budget: Budget,
}

impl Hydraulic {
    /// Starts a dry simulation on `hf`'s terrain.
    pub fn new(hf: &Heightfield, params: HydraulicParams) -> Result<Self, ProceduralError> {
        params.check()?;
        let cells: Vec<Cell> = to_f64(hf)?
            .into_iter()
            .map(|b| Cell {
                terrain: b,
                water: 0.0,
                sediment: 0.0,
                level: b + params.rain,
            })
            .collect();
        Ok(Hydraulic {
            width: hf.width(),
            height: hf.height(),
            cell_size: hf.cell_size(),
            params,
            next: cells.clone(),
            shares: vec![Share::default(); cells.len()],
            cells,
            budget: Budget::default(),
        })
    }

    pub fn terrain(&self) -> impl Iterator<Item = f64> + '_ {
        self.cells.iter().map(|c| c.terrain)
    }
    pub fn water(&self) -> impl Iterator<Item = f64> + '_ {
        self.cells.iter().map(|c| c.water)
    }
    pub fn sediment(&self) -> impl Iterator<Item = f64> + '_ {
        self.cells.iter().map(|c| c.sediment)
    }
    /// Totals of what entered and left so far.
    pub fn budget(&self) -> Budget {
        self.budget
    }

    /// The level of the ghost cell beyond the edge at offset (dx, dy) of
    /// (x, y): the terrain extrapolated linearly, without water.
    fn ghost_level(&self, x: usize, y: usize, dx: isize, dy: isize) -> f64 {
        let (w, h) = (self.width, self.height);
        let here = self.cells[y * w + x].terrain;
        match neighbour(x, y, -dx, -dy, w, h) {
            Some(o) => here + (here - self.cells[o].terrain),
            None => here,
        }
    }

    /// Calls `f(i, level, terrain, inside)` for each of the 8 neighbours of
    /// (x, y): in-grid neighbours by index, open-edge ghosts with `None`.
    #[inline]
    fn neighbours(&self, x: usize, y: usize, mut f: impl FnMut(usize, f64, f64, Option<usize>)) {
        let (w, h) = (self.width, self.height);
        for (i, &(dx, dy, _)) in MOORE.iter().enumerate() {
            match neighbour(x, y, dx, dy, w, h) {
                Some(q) => f(i, self.cells[q].level, self.cells[q].terrain, Some(q)),
                None if self.params.boundary == Boundary::Open => {
                    let g = self.ghost_level(x, y, dx, dy);
                    f(i, g, g, None)
                }
                None => {}
            }
        }
    }

    /// Pass 1: each cell's flow share and sediment ratio.
    fn shares(&mut self) {
        let w = self.width;
        let rain = self.params.rain;
        let k = self.params.flow_rate;
        let mut shares = std::mem::take(&mut self.shares);
        shares.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, out) in row.iter_mut().enumerate() {
                let c = self.cells[y * w + x];
                let avail = c.water + rain;
                let mut total = 0.0;
                self.neighbours(x, y, |i, lq, _, _| {
                    if c.level > lq {
                        total += flow(k, WEIGHTS[i], c.level, lq);
                    }
                });
                *out = if avail > 0.0 && total > 0.0 {
                    Share {
                        k: if total > avail {
                            k * (avail / total)
                        } else {
                            k
                        },
                        ratio: c.sediment / avail,
                    }
                } else {
                    Share::default()
                };
            }
        });
        self.shares = shares;
    }

    /// One step (rain, flow, erosion/deposition, evaporation).
    pub fn step(&mut self) {
        self.shares();
        let (w, p) = (self.width, self.params);
        let inv_cell = 1.0 / self.cell_size;
        let mut next = std::mem::take(&mut self.next);
        let rows: Vec<Budget> = next
            .par_chunks_mut(w)
            .enumerate()
            .map(|(y, row)| {
                let mut b = Budget::default();
                for (x, out) in row.iter_mut().enumerate() {
                    let i = y * w + x;
                    let (c, share) = (self.cells[i], self.shares[i]);
                    let (mut water, mut sediment) = (c.water + p.rain, c.sediment);
                    let (mut outflow, mut slope, mut lowest) = (0.0f64, 0.0f64, c.terrain);
                    self.neighbours(x, y, |n, lq, bq, q| {
                        let wt = WEIGHTS[n];
                        if c.level > lq {
                            let f = flow(share.k, wt, c.level, lq);
                            let s = share.ratio * f;
                            water -= f;
                            sediment -= s;
                            outflow += f;
                            slope = slope.max((c.level - lq) * inv_cell / MOORE[n].2);
                            if q.is_none() {
                                b.drained_water += f;
                                b.drained_sediment += s;
                            }
                        } else if let Some(q) = q
                            && lq > c.level
                        {
                            let sq = self.shares[q];
                            let f = flow(sq.k, wt, lq, c.level);
                            water += f;
                            sediment += sq.ratio * f;
                        }
                        if q.is_some() {
                            lowest = lowest.min(bq);
                        }
                    });
                    let capacity = p.capacity * outflow * slope;
                    let mut terrain = c.terrain;
                    if sediment > capacity {
                        let settle = p.deposit * (sediment - capacity);
                        terrain += settle;
                        sediment -= settle;
                    } else {
                        let cut = (p.dissolve * (capacity - sediment)).min(c.terrain - lowest);
                        terrain -= cut;
                        sediment += cut;
                    }
                    let evaporated = water * p.evaporation;
                    water -= evaporated;
                    b.rained += p.rain;
                    b.evaporated += evaporated;
                    *out = Cell {
                        terrain,
                        water,
                        sediment,
                        level: terrain + water + p.rain,
                    };
                }
                b
            })
            .collect();
        self.next = std::mem::replace(&mut self.cells, next);
        for r in rows {
            self.budget.rained += r.rained;
            self.budget.evaporated += r.evaporated;
            self.budget.drained_water += r.drained_water;
            self.budget.drained_sediment += r.drained_sediment;
        }
    }

    /// Runs `steps` steps, reporting each to `progress` (no start/finish).
    pub fn run(&mut self, steps: u32, progress: &dyn Progress) {
        for _ in 0..steps {
            self.step();
            progress.advance(1);
        }
    }

    /// Ends the simulation: suspended sediment settles where it is and the
    /// water is drained; the terrain is written into `hf` (same size).
    pub fn finish_into(&self, hf: &mut Heightfield) {
        let heights: Vec<f64> = self.cells.iter().map(|c| c.terrain + c.sediment).collect();
        store(hf, &heights);
    }
}

/// Runs `iterations` steps of hydraulic erosion on `hf`, starting dry, and
/// settles the remaining sediment. Refuses heightfields with nodata.
pub fn hydraulic_erode(
    hf: &mut Heightfield,
    params: &HydraulicParams,
    iterations: u32,
    progress: &dyn Progress,
) -> Result<(), ProceduralError> {
    let mut sim = Hydraulic::new(hf, *params)?;
    progress.start("hydraulic erosion", iterations as u64);
    sim.run(iterations, progress);
    progress.finish();
    sim.finish_into(hf);
    Ok(())
}
