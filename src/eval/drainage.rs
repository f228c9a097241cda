//! Drainage: D8 flow accumulation and pits, on the raw surface (no pit
//! filling — real DEMs drain almost everywhere, and the pits a synthesis
//! makes are exactly what this should see).

use super::interior;
use crate::heightfield::Heightfield;
use crate::procedural::grid::MOORE;
use crate::water::d8::{Edges, Surface, accumulate, receivers};
use rayon::prelude::*;

/// D8 drainage area in cells (the cell itself included) of every cell of
/// the raw surface ([`crate::water::d8`]: steepest descent, ties clockwise
/// from north), or nowhere when no neighbour is lower (a pit or a flat: no
/// depression filling, unlike `water`). `edges` says what edge cells do.
pub fn d8_area(hf: &Heightfield, edges: Edges) -> Vec<u32> {
    let surface = Surface {
        heights: hf.data(),
        width: hf.width(),
        height: hf.height(),
        gradient: None,
        sinks: None,
    };
    accumulate(&receivers(&surface, edges))
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
