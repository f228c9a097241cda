//! Drainage: D8 flow accumulation and pits, on the raw surface (no pit
//! filling — real DEMs drain almost everywhere, and the pits a synthesis
//! makes are exactly what this should see).

use super::interior;
use crate::heightfield::Heightfield;
use crate::procedural::grid::{MOORE, neighbour};
use rayon::prelude::*;

/// What flow does at the edge of the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edges {
    /// Edge cells are outlets: they collect but pass nothing on, as if the
    /// terrain went on beyond them. What a descriptor wants: otherwise a
    /// slope falling outwards turns every edge into a channel running along
    /// the border, collecting a quarter of a cone at each corner.
    Outlets,
    /// Edge cells pass their flow on like any other, to neighbours inside
    /// the grid (`masks`: the grid is all there is, and its lowest edge
    /// cell should show the river that leaves it).
    Inside,
}

/// No downslope neighbour: the flow ends here.
const SINK: u32 = u32::MAX;

/// D8 drainage area in cells (O'Callaghan & Mark 1984; the cell itself
/// included) of every cell: each cell sends everything it collects to the
/// neighbour of steepest descent (drop over distance, diagonals at √2; the
/// first of [`MOORE`] wins a tie), or nowhere when no neighbour is lower (a
/// pit or a flat: no depression filling). `edges` says what edge cells do.
pub fn d8_area(hf: &Heightfield, edges: Edges) -> Vec<u32> {
    let (w, h) = (hf.width(), hf.height());
    let data = hf.data();
    let mut receiver = vec![SINK; w * h];
    receiver.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, r) in row.iter_mut().enumerate() {
            let edge = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            if edge && edges == Edges::Outlets {
                continue;
            }
            let c = data[y * w + x] as f64;
            let mut best = 0.0;
            for &(dx, dy, dist) in &MOORE {
                let Some(k) = neighbour(x, y, dx, dy, w, h) else {
                    continue;
                };
                let drop = (c - data[k] as f64) / dist;
                if drop > best {
                    best = drop;
                    *r = k as u32;
                }
            }
        }
    });
    // Accumulate in topological order: a cell passes its area on once every
    // donor has passed theirs (heights strictly fall along the flow, so
    // there are no cycles).
    let mut donors = vec![0u8; w * h];
    for &r in &receiver {
        if r != SINK {
            donors[r as usize] += 1;
        }
    }
    let mut area = vec![1u32; w * h];
    let mut ready: Vec<u32> = (0..(w * h) as u32)
        .filter(|&i| donors[i as usize] == 0)
        .collect();
    while let Some(i) = ready.pop() {
        let r = receiver[i as usize];
        if r != SINK {
            area[r as usize] += area[i as usize];
            donors[r as usize] -= 1;
            if donors[r as usize] == 0 {
                ready.push(r);
            }
        }
    }
    area
}

/// log₁₀ of [`d8_area`], the form its distribution is compared in.
pub fn log_area(hf: &Heightfield) -> Vec<f32> {
    d8_area(hf, Edges::Outlets)
        .par_iter()
        .map(|&a| (a as f32).log10())
        .collect()
}

/// Fraction of the interior cells (one in from each edge) that are strict
/// local minima: lower than all 8 neighbours.
pub fn pit_fraction(hf: &Heightfield) -> f64 {
    let pits = interior(hf, 1, |n| {
        let c = n.at(0, 0);
        let pit = MOORE.iter().all(|&(dx, dy, _)| n.at(dx, dy) > c);
        pit as u8 as f32
    });
    if pits.is_empty() {
        0.0
    } else {
        pits.iter().filter(|&&p| p > 0.0).count() as f64 / pits.len() as f64
    }
}
