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

/// What the sweeps' arrays hold outside the flats.
const NOT_FLAT: u32 = u32::MAX;

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
    /// A sweep's array: 0 on flat cells (not reached yet), [`NOT_FLAT`]
    /// elsewhere, so a sweep reads one array per neighbour, not two.
    fn sweep_array(&self) -> Vec<u32> {
        let mut v = vec![0u32; self.class.len()];
        v.par_chunks_mut(self.w)
            .zip(self.class.par_chunks(self.w))
            .for_each(|(v, c)| {
                for (v, c) in v.iter_mut().zip(c) {
                    if c & FLAT == 0 {
                        *v = NOT_FLAT;
                    }
                }
            });
        v
    }

    /// The neighbours of an interior cell.
    fn around(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.offsets.iter().map(move |&o| i.wrapping_add_signed(o))
    }

    /// Labels of the flats, 8-connected (adjacent flat cells share a
    /// height, or the higher one would have a lower neighbour), and their
    /// count.
    fn label(&self, flats: &[u32]) -> (Vec<u32>, u32) {
        let mut label = self.sweep_array();
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
                    if label[k] == 0 {
                        label[k] = labels;
                        stack.push(k);
                    }
                }
            }
        }
        (label, labels)
    }

    /// Steps from the low edges (1 on them), breadth-first into the flats,
    /// doubled (the gradient's weight of 2).
    fn towards_lower(&self, flats: &[u32]) -> Vec<u32> {
        let mut grad = self.sweep_array();
        let mut ring: Vec<usize> = Vec::new();
        for &f in flats {
            let f = f as usize;
            for k in self.around(f) {
                if self.class[k] & DRAINS != 0
                    && self.filled[k] == self.filled[f]
                    && grad[k] == NOT_FLAT
                {
                    grad[k] = 2;
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
                    && grad[k] == 0
                    && self.filled[k] == self.filled[c]
                {
                    grad[k] = 4;
                    next.push(k);
                }
            }
        }
        self.sweep(&mut grad, next, 2, 2);
        grad
    }

    /// Steps from the high edges (1 on them), breadth-first through the
    /// flats; 0 where none is reached.
    fn away_from_higher(&self, flats: &[u32]) -> Vec<u32> {
        let mut higher = self.sweep_array();
        let ring: Vec<usize> = flats
            .iter()
            .map(|&f| f as usize)
            .filter(|&f| self.class[f] & HIGHER != 0)
            .collect();
        for &c in &ring {
            higher[c] = 1;
        }
        self.sweep(&mut higher, ring, 1, 1);
        higher
    }

    /// Breadth-first from `ring`, whose cells are set, through the cells
    /// still 0: ring n after it gets `weight × (step + n)`. The two sweeps
    /// differ only in their first rings and these numbers.
    fn sweep(&self, grid: &mut [u32], mut ring: Vec<usize>, mut step: u32, weight: u32) {
        let mut next = Vec::new();
        while !ring.is_empty() {
            step += 1;
            for (j, &c) in ring.iter().enumerate() {
                if let Some(&ahead) = ring.get(j + PREFETCH) {
                    prefetch(grid, ahead, self.w);
                }
                for k in self.around(c) {
                    if grid[k] == 0 {
                        grid[k] = weight * step;
                        next.push(k);
                    }
                }
            }
            std::mem::swap(&mut ring, &mut next);
            next.clear();
        }
    }
}

/// How many cells ahead of the one a sweep expands it asks for memory.
const PREFETCH: usize = 16;

/// Asks the CPU to fetch the rows above and below cell `i` of a sweep's
/// array: a ring of a sweep runs along a flat's contour, every cell on
/// other cache lines, and the sweeps waited for memory most of their time.
#[inline]
fn prefetch(v: &[u32], i: usize, w: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        for j in [i - w, i + w] {
            // SAFETY: prefetching is a hint with no memory access of its
            // own; ring cells are interior, so the pointers are in bounds.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(v.as_ptr().add(j).cast()) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (v, i, w);
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
    // Three independent sweeps: two cores run them side by side, the
    // longest (away from higher ground) against the other two.
    let (higher, ((label, labels), mut grad)) = rayon::join(
        || grid.away_from_higher(&flats),
        || rayon::join(|| grid.label(&flats), || grid.towards_lower(&flats)),
    );
    let mut top = vec![0u32; labels as usize + 1];
    for &f in &flats {
        let f = f as usize;
        let l = label[f] as usize;
        top[l] = top[l].max(higher[f]);
    }
    // Low edges (not flat) keep 2 × 1; flat cells add the inverted climb.
    grad.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, g) in row.iter_mut().enumerate() {
            let i = y * w + x;
            if *g == NOT_FLAT {
                *g = 0; // neither flat nor a low edge
            } else if higher[i] != NOT_FLAT && higher[i] > 0 {
                *g += top[label[i] as usize] - higher[i];
            }
        }
    });
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
