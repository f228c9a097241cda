//! The flood of one strip of rows from its own edge (the first step of
//! [`super::priority_flood`]): Barnes, Lehman & Mulla's (2014)
//! priority-flood with its own queue for pit cells, Zhou, Sun & Fu's (2016)
//! out-of-order expansion of slope cells, and Barnes' (2016) labels, so
//! that the strips can be joined afterwards.

use super::{RadixHeap, key};
use crate::procedural::grid::neighbour;
use crate::water::d8::CLOCKWISE;

/// How many queue pops ahead [`prefetch`] asks for a cell's memory.
const PREFETCH: usize = 8;

/// Asks the CPU to fetch the three rows around cell `i` (heights and
/// labels): cells leave the queue in height order, scattered over
/// the grid, and waiting for each one's memory was ~80 % of the fill's
/// time at 4096².
#[inline]
fn prefetch(z: &[f32], label: &[u32], i: usize, w: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        for j in [i.saturating_sub(w), i, (i + w).min(z.len() - 1)] {
            // SAFETY: prefetching is a hint with no memory access of its
            // own; the pointers are in bounds anyway.
            unsafe {
                _mm_prefetch::<_MM_HINT_T0>(z.as_ptr().add(j).cast());
                _mm_prefetch::<_MM_HINT_T0>(label.as_ptr().add(j).cast());
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (z, label, i, w);
}

/// Heap entries of a strip's edge cells carry this bit: only they need
/// bounds checks (every other cell the flood reaches is inside the strip,
/// since its whole edge is seeded closed), which spares a division per cell.
const BORDER: u32 = 1 << 31;

/// Label of a cell the flood has not reached.
const UNSEEN: u32 = u32::MAX;

/// Label of the cells flooded from a true outlet (the grid's border or the
/// sea): their level is final.
pub(super) const OUTLET: u32 = u32::MAX - 1;

/// Where the flood of a strip from two of its edge cells' labels meets:
/// (label a, label b, level), a < b. Water at that level crosses between
/// their basins.
pub(super) type Join = (u32, u32, f32);

/// A strip of whole rows of the grid to flood from its own edge.
pub(super) struct Strip<'a> {
    /// Heights on entry, the strip's own fill levels on return.
    pub z: &'a mut [f32],
    /// The label of every cell on return: [`OUTLET`], or the edge cell its
    /// water leaves the strip by ([`edge_label`]).
    pub label: &'a mut [u32],
    pub w: usize,
    pub h: usize,
    /// Whether its first (last) row is the grid's border.
    pub top_open: bool,
    pub bottom_open: bool,
    /// Sea cells (outlets) of the strip and the sea level.
    pub sea: Option<(&'a [bool], f32)>,
}

/// The label of edge cell (x, y) of a `w × h` strip: [`OUTLET`] on the
/// grid's border, else `x` on the first row and `w + x` on the last.
fn edge_label(x: usize, y: usize, w: usize, h: usize, top_open: bool, bottom_open: bool) -> u32 {
    if x == 0 || x == w - 1 || (y == 0 && top_open) || (y == h - 1 && bottom_open) {
        OUTLET
    } else if y == 0 {
        x as u32
    } else {
        (w + x) as u32
    }
}

/// Floods a strip from its edge (every edge cell a seed at its height,
/// labelled [`edge_label`]) and its sea: each cell ends at the lowest level
/// at which its water leaves the strip, labelled with the edge cell it
/// leaves by; returns where labels meet, each pair once at its lowest
/// level ([`super::priority_flood`] joins the strips with them).
pub(super) fn flood(s: Strip<'_>) -> Vec<Join> {
    let Strip {
        z,
        label,
        w,
        h,
        top_open,
        bottom_open,
        sea,
    } = s;
    let n = w * h;
    debug_assert!(n < BORDER as usize, "check_dims caps grids at 2^30 cells");
    label.fill(UNSEEN);
    let mut open = RadixHeap::new();
    if let Some((mask, level)) = sea {
        for (i, _) in mask.iter().enumerate().filter(|p| *p.1) {
            z[i] = level;
            label[i] = OUTLET;
            let (x, y) = (i % w, i / w);
            let edge = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            open.push(key(level), i as u32 | if edge { BORDER } else { 0 });
        }
    }
    let edge = (0..w)
        .flat_map(|x| [(x, 0), (x, h - 1)])
        .chain((0..h).flat_map(|y| [(0, y), (w - 1, y)]));
    for (x, y) in edge {
        let i = y * w + x;
        if label[i] == UNSEEN {
            label[i] = edge_label(x, y, w, h, top_open, bottom_open);
            open.push(key(z[i]), i as u32 | BORDER);
        }
    }
    let offsets: [isize; 8] = CLOCKWISE.map(|(dx, dy, _)| dy * w as isize + dx);
    // Cells raised to the current level. Barnes' queue is FIFO, but every
    // cell in it has the same level (it empties before the next pop), so
    // the order is free: a stack keeps the cells just read in cache.
    let mut pit: Vec<u32> = Vec::new();
    let mut slope: Vec<u32> = Vec::new();
    let mut joins: Vec<Join> = Vec::new();
    loop {
        let stack = if pit.is_empty() { &mut slope } else { &mut pit };
        let entry = match stack.pop() {
            Some(c) => {
                if let Some(&next) = stack.len().checked_sub(PREFETCH).map(|i| &stack[i]) {
                    prefetch(z, label, next as usize, w);
                }
                c
            }
            None => match open.pop() {
                Some((_, c)) => {
                    if let Some(next) = open.ahead(PREFETCH) {
                        prefetch(z, label, (next & !BORDER) as usize, w);
                    }
                    c
                }
                None => break,
            },
        };
        let c = (entry & !BORDER) as usize;
        let (zc, lc) = (z[c], label[c]);
        let mut visit = |nb: usize, z: &mut [f32], label: &mut [u32]| {
            let lk = label[nb];
            if lk != UNSEEN {
                if lk != lc {
                    let (a, b) = if lc < lk { (lc, lk) } else { (lk, lc) };
                    let e = if z[nb] > zc { z[nb] } else { zc };
                    match joins.last_mut() {
                        Some(j) if (j.0, j.1) == (a, b) => {
                            if e < j.2 {
                                j.2 = e;
                            }
                        }
                        _ => joins.push((a, b, e)),
                    }
                }
                return;
            }
            label[nb] = lc;
            let zn = z[nb];
            if zn <= zc {
                z[nb] = zc;
                pit.push(nb as u32);
            } else if offsets.iter().all(|&o| {
                let m = nb.wrapping_add_signed(o);
                label[m] != UNSEEN || z[m] > zn
            }) {
                // Zhou, Sun & Fu (2016): a cell whose open neighbours are
                // all higher raises nothing, so it may be expanded now, out
                // of order, without the queue (nb is inside the strip: its
                // edge is closed from the start).
                slope.push(nb as u32);
            } else {
                open.push(key(zn), nb as u32);
            }
        };
        if entry & BORDER == 0 {
            for off in offsets {
                visit(c.wrapping_add_signed(off), z, label);
            }
        } else {
            let (x, y) = (c % w, c / w);
            for &(dx, dy, _) in &CLOCKWISE {
                if let Some(nb) = neighbour(x, y, dx, dy, w, h) {
                    visit(nb, z, label);
                }
            }
        }
    }
    joins.sort_unstable_by(|p, q| (p.0, p.1).cmp(&(q.0, q.1)).then(p.2.total_cmp(&q.2)));
    joins.dedup_by_key(|j| (j.0, j.1));
    joins
}
