//! Drainage: D8 flow accumulation and pits on the raw surface (no pit
//! filling — real DEMs drain almost everywhere, and the pits a synthesis
//! makes are exactly what this should see), and the closed depressions
//! that filling would find.

use super::interior;
use crate::heightfield::Heightfield;
use crate::procedural::grid::MOORE;
use crate::water::d8::{Edges, Surface, accumulate, receivers};
use crate::water::fill::priority_flood;
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

/// How far below its spill level a cell must lie to count as closed
/// ([`closed_share`]), metres: SRTM's vertical error is a few metres, so a
/// shallower hollow may be noise; a deeper one is a landform.
pub const CLOSED_DEPTH_M: f32 = 5.0;

/// Share of the area in closed depressions: cells more than
/// [`CLOSED_DEPTH_M`] below their spill level (the depression-filled
/// surface of [`crate::water::fill`], every border cell an outlet).
///
/// Why: a valley network is what the eye finds missing in a field of
/// rounded massifs with hollows between them, and none of the nine
/// descriptors sees it — `drainage` is dominated by hillslope cells
/// (median 3 cells everywhere) and `pits` counts one-cell dimples. Real
/// land is drained: rivers cut through to the sea or the map's edge, and
/// on the shared DEMs 0–2 % of the area lies in hollows deeper than 5 m.
/// Where a synthesis lays lowlands with no valley out of them, water
/// pools there: 5–38 % of its area (issue 46).
pub fn closed_share(hf: &Heightfield) -> f64 {
    let heights = hf.data();
    let filled = priority_flood(heights, hf.width(), hf.height(), None);
    let closed = filled
        .par_iter()
        .zip(heights)
        .filter(|&(f, h)| f - h > CLOSED_DEPTH_M)
        .count();
    closed as f64 / heights.len() as f64
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

#[cfg(test)]
mod tests {
    use super::*;

    /// 64 × 64 cells of 30 m, the ground at 100 m, with a `side`-cell
    /// square at `floor` m whose corner is at (x, y).
    fn hollow(x: usize, y: usize, side: usize, floor: f32) -> Heightfield {
        Heightfield::from_fn(64, 64, 30.0, |i, j| {
            let inside = (x..x + side).contains(&i) && (y..y + side).contains(&j);
            if inside { floor } else { 100.0 }
        })
        .unwrap()
    }

    #[test]
    fn a_hollow_deeper_than_the_threshold_is_closed() {
        let c = closed_share(&hollow(20, 20, 10, 80.0));
        assert_eq!(c, 100.0 / 4096.0);
    }

    /// A hollow as shallow as SRTM's noise is not a landform.
    #[test]
    fn a_shallow_hollow_is_not_closed() {
        let depth = CLOSED_DEPTH_M - 1.0;
        assert_eq!(closed_share(&hollow(20, 20, 10, 100.0 - depth)), 0.0);
    }

    /// A hollow open to the map's edge drains there: a valley, not a lake.
    #[test]
    fn a_hollow_open_to_the_edge_drains() {
        assert_eq!(closed_share(&hollow(0, 20, 10, 80.0)), 0.0);
    }

    /// Every cell of a tilted plane drains.
    #[test]
    fn a_plane_has_no_closed_depression() {
        let plane = Heightfield::from_fn(64, 64, 30.0, |x, y| (x + 2 * y) as f32).unwrap();
        assert_eq!(closed_share(&plane), 0.0);
    }
}
