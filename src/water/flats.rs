//! Flat resolution (Barnes, Lehman & Mulla 2014, "An efficient assignment
//! of drainage direction over flat surfaces in raster digital elevation
//! models"): on the filled surface every lake is level, and D8 alone gives
//! its cells no direction. This builds the paper's drainage gradient over
//! each flat — towards lower terrain (weight 2) and away from higher
//! terrain — which [`super::d8`] uses as the second key of its slope
//! comparison, so flow crosses a lake from its inflows to its outlet along
//! the middle of the flat instead of hugging one shore, and every cell
//! drains.
//!
//! Definitions as pysheds implements the paper (its `resolve_flats`), so
//! the two route the same way:
//! - a **flat** cell is an interior cell with no lower neighbour and at
//!   least one neighbour at its height (border and sea cells never are);
//! - a **low edge** is a cell that drains (a lower neighbour, the border or
//!   the sea) next to a flat cell of its height;
//! - a **high edge** is a flat cell with a higher neighbour;
//! - `towards_lower` = 1 on low edges, +1 per 8-connected step into the flat;
//!   `away_from_higher` = 1 on high edges, +1 per step, then inverted within
//!   each flat (its largest value minus it; unreached cells keep 0);
//! - gradient = 2 × towards_lower + away_from_higher (low edges: 2).

use super::d8::CLOCKWISE;
use crate::procedural::grid::neighbour;
use rayon::prelude::*;

pub(super) const FLAT: u8 = 1;
pub(super) const DRAINS: u8 = 2;
pub(super) const HIGHER: u8 = 4;

/// A filled surface with its cells classified.
struct Grid<'a> {
    filled: &'a [f32],
    class: &'a [u8],
    /// Neighbour offsets of interior cells (every flat cell is interior).
    offsets: [isize; 8],
    w: usize,
    h: usize,
}

impl Grid<'_> {
    fn is_flat(&self, k: usize) -> bool {
        self.class[k] & FLAT != 0
    }

    /// The neighbours of an interior cell.
    fn around(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.offsets.iter().map(move |&o| i.wrapping_add_signed(o))
    }

    /// Labels of the flats, 8-connected (adjacent flat cells share a
    /// height, or the higher one would have a lower neighbour), and their
    /// count.
    fn label(&self, flats: &[u32]) -> (Vec<u32>, u32) {
        let mut label = vec![0u32; self.class.len()];
        let mut labels = 0u32;
        let mut stack = Vec::new();
        for &f in flats {
            if label[f as usize] != 0 {
                continue;
            }
            labels += 1;
            label[f as usize] = labels;
            stack.push(f as usize);
            while let Some(c) = stack.pop() {
                for k in self.around(c) {
                    if self.is_flat(k) && label[k] == 0 {
                        label[k] = labels;
                        stack.push(k);
                    }
                }
            }
        }
        (label, labels)
    }

    /// Steps from the low edges (1 on them), breadth-first into the flats.
    fn towards_lower(&self, flats: &[u32]) -> Vec<u32> {
        let mut grad = vec![0u32; self.class.len()];
        let mut ring: Vec<usize> = Vec::new();
        for &f in flats {
            let f = f as usize;
            for k in self.around(f) {
                if self.class[k] & DRAINS != 0 && self.filled[k] == self.filled[f] && grad[k] == 0 {
                    grad[k] = 1;
                    ring.push(k);
                }
            }
        }
        // The first ring (low edges) may lie on the border; later rings
        // are flat cells, interior.
        let mut next = Vec::new();
        for &c in &ring {
            let (x, y) = (c % self.w, c / self.w);
            for &(dx, dy, _) in &CLOCKWISE {
                if let Some(k) = neighbour(x, y, dx, dy, self.w, self.h)
                    && self.is_flat(k)
                    && grad[k] == 0
                    && self.filled[k] == self.filled[c]
                {
                    grad[k] = 2;
                    next.push(k);
                }
            }
        }
        std::mem::swap(&mut ring, &mut next);
        next.clear();
        let mut step = 2;
        while !ring.is_empty() {
            step += 1;
            for &c in &ring {
                for k in self.around(c) {
                    if self.is_flat(k) && grad[k] == 0 {
                        grad[k] = step;
                        next.push(k);
                    }
                }
            }
            std::mem::swap(&mut ring, &mut next);
            next.clear();
        }
        grad
    }

    /// Steps from the high edges (1 on them), breadth-first through the
    /// flats; 0 where none is reached.
    fn away_from_higher(&self, flats: &[u32]) -> Vec<u32> {
        let mut higher = vec![0u32; self.class.len()];
        let mut ring: Vec<usize> = flats
            .iter()
            .map(|&f| f as usize)
            .filter(|&f| self.class[f] & HIGHER != 0)
            .collect();
        for &c in &ring {
            higher[c] = 1;
        }
        let mut next = Vec::new();
        let mut step = 1;
        while !ring.is_empty() {
            step += 1;
            for &c in &ring {
                for k in self.around(c) {
                    if self.is_flat(k) && higher[k] == 0 {
                        higher[k] = step;
                        next.push(k);
                    }
                }
            }
            std::mem::swap(&mut ring, &mut next);
            next.clear();
        }
        higher
    }
}

/// The class of an interior cell at height `z` (not the sea) from its
/// eight neighbours' heights.
pub(super) fn classify(z: f32, around: [f32; 8]) -> u8 {
    let (mut lower, mut equal, mut higher) = (false, false, false);
    for zk in around {
        lower |= zk < z;
        equal |= zk == z;
        higher |= zk > z;
    }
    (if lower {
        DRAINS
    } else if equal {
        FLAT
    } else {
        0
    }) | if higher { HIGHER } else { 0 }
}

/// The drainage gradient of every cell of a filled surface (`sea` cells
/// drain, like the border); `None` when the surface has no flat.
pub fn gradient(filled: &[f32], w: usize, h: usize, sea: Option<&[bool]>) -> Option<Vec<u32>> {
    // Flat cells are interior: their neighbours are at fixed offsets.
    let offsets: [isize; 8] = CLOCKWISE.map(|(dx, dy, _)| dy * w as isize + dx);
    let mut class = vec![0u8; w * h];
    class.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, c) in row.iter_mut().enumerate() {
            let i = y * w + x;
            if x == 0 || y == 0 || x == w - 1 || y == h - 1 || sea.is_some_and(|m| m[i]) {
                *c = DRAINS;
                continue;
            }
            *c = classify(filled[i], offsets.map(|o| filled[i.wrapping_add_signed(o)]));
        }
    });
    let flats: Vec<u32> = class
        .par_iter()
        .enumerate()
        .filter(|(_, c)| **c & FLAT != 0)
        .map(|(i, _)| i as u32)
        .collect();
    if flats.is_empty() {
        return None;
    }
    let grid = Grid {
        filled,
        class: &class,
        offsets,
        w,
        h,
    };
    // Three independent sweeps: two cores run them side by side.
    let ((label, labels), (mut grad, higher)) = rayon::join(
        || grid.label(&flats),
        || {
            rayon::join(
                || grid.towards_lower(&flats),
                || grid.away_from_higher(&flats),
            )
        },
    );
    let mut top = vec![0u32; labels as usize + 1];
    for &f in &flats {
        let f = f as usize;
        let l = label[f] as usize;
        top[l] = top[l].max(higher[f]);
    }
    // Low edges (not flat) keep 2 × 1; flat cells add the inverted climb.
    for g in grad.iter_mut() {
        *g *= 2;
    }
    for &f in &flats {
        let f = f as usize;
        if higher[f] > 0 {
            grad[f] += top[label[f] as usize] - higher[f];
        }
    }
    Some(grad)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_slopes_towards_its_outlet_and_away_from_its_shore() {
        // 7×3: a level strip at 5 m (row 1, x 1..=5) walled at 9 m, open
        // to the west border at 5 m: the gradient falls westwards.
        let (w, h) = (7, 3);
        let mut z = vec![9.0f32; w * h];
        for x in 0..6 {
            z[w + x] = 5.0;
        }
        let g = gradient(&z, w, h, None).unwrap();
        let row: Vec<u32> = (0..w).map(|x| g[w + x]).collect();
        // The border cell is the low edge (2); towards_lower 2..6 doubled,
        // away_from_higher is 1 everywhere (all touch the walls): inverted 0.
        assert_eq!(row, vec![2, 4, 6, 8, 10, 12, 0]);
    }
}
