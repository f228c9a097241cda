//! D8 flow directions and flow accumulation (O'Callaghan & Mark 1984): every
//! cell sends everything it collects to one neighbour, the one of steepest
//! descent (drop over distance, diagonals at √2 cells). The one D8 of the
//! crate: `water` runs it on the filled surface, `eval`'s drainage
//! descriptor on the raw one.
//!
//! **Tie rule.** Slopes are compared lexicographically: first the height
//! drop over distance, then — only between exactly equal drops — the drop
//! of the flat-resolution gradient ([`super::flats`]) over distance, which
//! is Barnes, Lehman & Mulla's (2014) gradient added with an infinitesimal
//! ε. Still equal, the first neighbour clockwise from north wins (N, NE, E,
//! SE, S, SW, W, NW: pysheds' `dirmap` order, so the reference picks the
//! same one). pysheds adds the gradient with a finite ε (1e-5 m per step) to
//! the heights; the two agree wherever that ε times a gradient difference is
//! below the height differences around a flat (see the README's `water`
//! section for how often it is not, per DEM).

use crate::procedural::grid::neighbour;
use rayon::prelude::*;

/// No receiver: the flow leaves the grid here (a border outlet), ends in
/// the sea, or (raw surfaces only) stops in a pit.
pub const OUTLET: u32 = u32::MAX;

/// The eight neighbours in tie order, clockwise from north: (dx, dy,
/// distance in cells); rows run south.
pub const CLOCKWISE: [(isize, isize, f64); 8] = [
    (0, -1, 1.0),
    (1, -1, std::f64::consts::SQRT_2),
    (1, 0, 1.0),
    (1, 1, std::f64::consts::SQRT_2),
    (0, 1, 1.0),
    (-1, 1, std::f64::consts::SQRT_2),
    (-1, 0, 1.0),
    (-1, -1, std::f64::consts::SQRT_2),
];

/// What flow does at the edge of the grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Edges {
    /// Edge cells are outlets: they collect but pass nothing on, as if the
    /// terrain went on beyond them. What a descriptor wants: otherwise a
    /// slope falling outwards turns every edge into a channel running along
    /// the border, collecting a quarter of a cone at each corner.
    Outlets,
    /// Edge cells pass their flow on like any other, to a lower neighbour
    /// inside the grid, and are outlets only where none is lower (`water`
    /// and `masks`: the grid is all there is, and its lowest edge cell shows
    /// the river that leaves it; pysheds routes edges the same way).
    Inside,
}

/// A surface for D8: heights and what decides ties and ends flow.
#[derive(Debug, Clone, Copy)]
pub struct Surface<'a> {
    /// Row-major heights, `width × height`, no NaN.
    pub heights: &'a [f32],
    pub width: usize,
    pub height: usize,
    /// The flat-resolution gradient ([`super::flats::gradient`]): the second
    /// key of the slope comparison. `None`: zero everywhere.
    pub gradient: Option<&'a [u32]>,
    /// Cells where flow ends whatever their neighbours (the sea).
    pub sinks: Option<&'a [bool]>,
}

/// The D8 receiver of every cell (an index, or [`OUTLET`]): the neighbour
/// of steepest descent under the tie rule of this module; a cell whose best
/// slope is not above zero has none.
pub fn receivers(s: &Surface<'_>, edges: Edges) -> Vec<u32> {
    let (w, h) = (s.width, s.height);
    let offsets: [isize; 8] = CLOCKWISE.map(|(dx, dy, _)| dy * w as isize + dx);
    let mut out = vec![OUTLET; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, r) in row.iter_mut().enumerate() {
            let i = y * w + x;
            let edge = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            if (edge && edges == Edges::Outlets) || s.sinks.is_some_and(|m| m[i]) {
                continue;
            }
            *r = if edge {
                let around = CLOCKWISE.map(|(dx, dy, _)| neighbour(x, y, dx, dy, w, h));
                steepest(s, i, around)
            } else {
                steepest_inside(s, i, offsets)
            };
        }
    });
    out
}

/// The receiver of cell `i` among its neighbours `around` (clockwise from
/// north, `None` off the grid): the lexicographically steepest (drop over
/// distance, then gradient drop over distance) that beats (0, 0), the
/// first clockwise among equals.
fn steepest(s: &Surface<'_>, i: usize, around: [Option<usize>; 8]) -> u32 {
    let grad = |i: usize| s.gradient.map_or(0.0, |g| g[i] as f64);
    let (z, g) = (s.heights[i] as f64, grad(i));
    let (mut best_dz, mut best_dg, mut best) = (0.0, 0.0, OUTLET);
    for (k, &(_, _, dist)) in around.into_iter().zip(&CLOCKWISE) {
        let Some(k) = k else { continue };
        let dz = (z - s.heights[k] as f64) / dist;
        let dg = (g - grad(k)) / dist;
        if dz > best_dz || (dz == best_dz && dg > best_dg) {
            (best_dz, best_dg, best) = (dz, dg, k as u32);
        }
    }
    best
}

/// [`steepest`] for an interior cell, without a branch per neighbour: the
/// eight drops first (their divisions overlap), then their maximum, and
/// only where that maximum is shared or zero (on every flat), the
/// gradient's. The same choice: the lexicographic maximum, the first of
/// equals. The branches of the one-by-one comparison, taken at random,
/// cost most of D8's time.
#[inline]
fn steepest_inside(s: &Surface<'_>, i: usize, offsets: [isize; 8]) -> u32 {
    let z = s.heights[i] as f64;
    let around = offsets.map(|o| i.wrapping_add_signed(o));
    let dz: [f64; 8] = std::array::from_fn(|j| {
        let d = z - s.heights[around[j]] as f64;
        // A cardinal's distance is 1: the division would change nothing.
        if j % 2 == 0 { d } else { d / CLOCKWISE[j].2 }
    });
    let top = dz.iter().fold(0.0f64, |m, &v| if v > m { v } else { m });
    let mut ties = 0;
    let mut first = 0;
    for (j, &v) in dz.iter().enumerate().rev() {
        let eq = v == top;
        ties += eq as u32;
        first = if eq { j } else { first };
    }
    if top > 0.0 && ties == 1 {
        return around[first] as u32;
    }
    // Among the steepest, the largest gradient drop wins (the first of
    // equals), and on level ground only a positive one.
    let grad = |i: usize| s.gradient.map_or(0.0, |g| g[i] as f64);
    let g = grad(i);
    let (mut best_dg, mut best) = (f64::NEG_INFINITY, 0);
    for (j, (&k, &v)) in around.iter().zip(&dz).enumerate() {
        let d = g - grad(k);
        let dg = if j % 2 == 0 { d } else { d / CLOCKWISE[j].2 };
        let dg = if v == top { dg } else { f64::NEG_INFINITY };
        if dg > best_dg {
            (best_dg, best) = (dg, j);
        }
    }
    if top > 0.0 || best_dg > 0.0 {
        around[best] as u32
    } else {
        OUTLET
    }
}

/// Flow accumulation in cells (the cell itself included) from D8
/// receivers. Receivers must form no cycle (heights, then the gradient,
/// strictly fall along the flow, so those of [`receivers`] do not).
pub fn accumulate(receivers: &[u32]) -> Vec<u32> {
    let mut acc = vec![1u32; receivers.len()];
    accumulate_into(receivers, &mut acc);
    acc
}

/// Flow accumulation of weights: `acc` holds each cell's own weight on
/// entry (1 for its own area, more where flow enters from elsewhere) and
/// its upstream total on return; each cell passes its total on once every
/// donor has passed theirs. Sequential and O(n): the walk follows the
/// network, which no row split divides.
pub fn accumulate_into<T: Copy + std::ops::AddAssign>(receivers: &[u32], acc: &mut [T]) {
    let n = receivers.len();
    // Donor counts; at most 8, and u8::MAX marks a cell already passed on.
    let mut pending = vec![0u8; n];
    for &r in receivers {
        if r != OUTLET {
            pending[r as usize] += 1;
        }
    }
    for start in 0..n {
        if pending[start] != 0 {
            continue;
        }
        let mut c = start;
        loop {
            let r = receivers[c];
            if r == OUTLET {
                break;
            }
            let r = r as usize;
            let a = acc[c];
            acc[r] += a;
            pending[r] -= 1;
            if pending[r] != 0 {
                break;
            }
            pending[r] = u8::MAX;
            c = r;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ties_go_clockwise_from_north_then_down_the_gradient() {
        // A 3×3 bowl-free plate: the centre at 1, every neighbour at 0.
        let mut z = vec![0.0f32; 9];
        z[4] = 1.0;
        let s = Surface {
            heights: &z,
            width: 3,
            height: 3,
            gradient: None,
            sinks: None,
        };
        // Cardinals (drop 1) beat diagonals (1/√2); north is first.
        assert_eq!(receivers(&s, Edges::Inside)[4], 1);
        // A level plate drains only down the gradient: the centre (4) to
        // the lowest-gradient neighbour (the east, 5, at equal distance
        // with the west, 3, but lower).
        let flat = vec![0.0f32; 9];
        let g = [9, 9, 9, 2, 5, 1, 9, 9, 9];
        let s = Surface {
            heights: &flat,
            width: 3,
            height: 3,
            gradient: Some(&g),
            sinks: None,
        };
        let r = receivers(&s, Edges::Inside);
        assert_eq!(r[4], 5);
        assert_eq!(r[5], OUTLET, "nothing lower: an outlet");
    }

    #[test]
    fn accumulation_counts_every_upstream_cell_once() {
        // A chain 0 → 1 → 2 with 3 joining at 1 and 4 at 2.
        let r = [1, 2, OUTLET, 1, 2];
        assert_eq!(accumulate(&r), vec![1, 3, 5, 1, 1]);
    }
}
