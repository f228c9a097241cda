//! Multiple flow direction (MFD) accumulation: `terrasynth water --routing
//! mfd`. Each cell passes what it collects to every lower neighbour in
//! proportion to the slope towards it (drop over distance, diagonals at √2
//! cells: Freeman's 1991 MFD with exponent 1, what pysheds' `routing='mfd'`
//! computes), so flow spreads over hillslopes where D8 draws one line.
//!
//! It runs on the same surface as D8 ([`super::d8::Surface`]): the filled
//! heights, then on a flat (no lower neighbour) the flat-resolution
//! gradient as an infinitesimal ε, so a flat cell sends its flow to its
//! level neighbours lower on the gradient, in proportion to the gradient's
//! drop over distance (the limit of pysheds' finite ε as it goes to zero).
//! Edges and sinks are D8's ([`super::d8::Edges::Inside`]): edge cells
//! drain into the grid, sea cells take flow and pass none on.
//!
//! Every share goes strictly down (heights, then the gradient), so the
//! routing has no cycle; cells are taken in a topological order (a cell
//! once all its donors are done), one after the other, so sums are added
//! in the same order on every run and thread count: the result is
//! deterministic. Rivers and Strahler orders stay on D8.

use super::d8::{CLOCKWISE, Surface};
use crate::procedural::grid::neighbour;
use rayon::prelude::*;

/// Bytes per cell [`accumulate`] holds beyond D8's (receiver bits, donor
/// counts, the f64 sums, at most every cell waiting, the f32 result).
pub const BYTES_PER_CELL: u64 = 18;

/// The neighbours of cell `i` of a `w × h` grid, clockwise from north,
/// `None` off the grid.
fn around(i: usize, w: usize, h: usize) -> [Option<usize>; 8] {
    CLOCKWISE.map(|(dx, dy, _)| neighbour(i % w, i / w, dx, dy, w, h))
}

/// The weights of cell `i`'s outflow towards its eight neighbours (0: none):
/// drop over distance towards every lower neighbour; with none lower, the
/// gradient's drop over distance towards level neighbours lower on it.
fn weights(s: &Surface<'_>, i: usize) -> [f64; 8] {
    let mut out = [0.0f64; 8];
    if s.sinks.is_some_and(|m| m[i]) {
        return out;
    }
    let nb = around(i, s.width, s.height);
    let z = s.heights[i] as f64;
    let mut any = false;
    for (j, k) in nb.iter().enumerate() {
        if let Some(k) = *k {
            let drop = z - s.heights[k] as f64;
            if drop > 0.0 {
                out[j] = drop / CLOCKWISE[j].2;
                any = true;
            }
        }
    }
    if let (false, Some(g)) = (any, s.gradient) {
        for (j, k) in nb.iter().enumerate() {
            if let Some(k) = *k
                && s.heights[k] == s.heights[i]
                && g[k] < g[i]
            {
                out[j] = (g[i] - g[k]) as f64 / CLOCKWISE[j].2;
            }
        }
    }
    out
}

/// MFD flow accumulation in cells (the cell itself included) on a D8
/// surface.
pub fn accumulate(s: &Surface<'_>) -> Vec<f32> {
    let (w, h) = (s.width, s.height);
    let n = w * h;
    // Which neighbours each cell sends to (bit j: CLOCKWISE[j]).
    let sends: Vec<u8> = (0..n)
        .into_par_iter()
        .map(|i| {
            let wt = weights(s, i);
            (0..8).fold(0u8, |b, j| b | (((wt[j] > 0.0) as u8) << j))
        })
        .collect();
    // Donor counts: at most 8.
    let mut pending = vec![0u8; n];
    for (i, &b) in sends.iter().enumerate() {
        for (j, k) in around(i, w, h).into_iter().enumerate() {
            if let Some(k) = k.filter(|_| b & (1 << j) != 0) {
                pending[k] += 1;
            }
        }
    }
    let mut acc = vec![1.0f64; n];
    let mut ready: Vec<u32> = (0..n as u32)
        .rev()
        .filter(|&i| pending[i as usize] == 0)
        .collect();
    while let Some(c) = ready.pop() {
        let c = c as usize;
        if sends[c] == 0 {
            continue;
        }
        let wt = weights(s, c);
        let total: f64 = wt.iter().sum();
        let a = acc[c];
        for (j, k) in around(c, w, h).into_iter().enumerate() {
            if let Some(k) = k.filter(|_| sends[c] & (1 << j) != 0) {
                acc[k] += a * (wt[j] / total);
                pending[k] -= 1;
                if pending[k] == 0 {
                    ready.push(k as u32);
                }
            }
        }
    }
    acc.into_iter().map(|v| v as f32).collect()
}
