//! Depression filling by priority-flood: every cell ends at the lowest
//! level at which water could leave it — the spill level of its
//! depression, exactly (a copy of a height, no arithmetic), so a filled
//! lake is level.
//!
//! The fill is flat, not ε-raised (Barnes' Priority-Flood+ε): in f32 an ε
//! step per cell climbs by an ulp per cell across a lake (~6 cm over 1 000
//! cells at 1 000 m), which would move the lake's surface off its spill
//! level. Flats are drained instead by [`super::flats`].
//!
//! The grid is filled strip by strip in parallel, with Barnes' (2016)
//! parallel priority-flood, strips of rows for tiles:
//!
//! 1. Each strip is flooded from its own edge (`flood::flood`; Barnes,
//!    Lehman & Mulla 2014 with a queue for pit cells), every edge cell
//!    inside the grid labelled on its own, those on the grid's border and
//!    the sea `OUTLET`: each cell gets the level at which its water leaves
//!    the strip and the edge cell it leaves by, and the flood records the
//!    lowest level at which each pair of labels meets.
//! 2. Those joins, and the steps between facing edge cells of neighbouring
//!    strips, make a graph whose minimax distances from the outlets are
//!    the filled levels of the edge cells (`solve`).
//! 3. Each cell's level is the higher of its strip level and its label's.
//!
//! Why it is exact: a cell's filled level is the least, over paths to an
//! outlet, of the highest height on the path, and every such path leaves
//! the cell's strip by an edge cell. Taking the edge cell `p` the strip's
//! flood chose gives at most max(strip level, level of `p`). No path does
//! better: it climbs at least to the strip level before it leaves the
//! strip, and it joins `p`'s label to wherever it goes through labels that
//! meet below its highest point (so the graph gives `p` a level no
//! higher). Levels are copies of heights, never sums, so the result is bit
//! for bit that of one flood of the whole grid (`tests/water/fast.rs`
//! compares the two).
//!
//! Why strips: the flood visits cells in height order, scattered over the
//! grid, and waited for memory most of the time; a strip of about 2^20
//! cells keeps its heights and labels in the CPU's caches, and two cores
//! flood two strips at once. On a 4096² synthesis the fill took 1.27 s
//! against 2.19 s for one flood of the whole grid (medians, this
//! project's shared two cores at load ≈ 2.5); with no core free for the
//! second strip (load ≈ 4.5) it is slower than that one flood, the labels
//! and the joining costing more than the cache saves.
//!
//! The floods' queue is a radix heap on the heights' order-preserving
//! bits: a flood pops levels in non-decreasing order (a monotone queue),
//! where a radix heap costs O(1) per push and an amortised bucket scan per
//! pop (~3 CPU-seconds for one flood of a 4096² synthesis against 7.8
//! with std's binary heap). The result does not depend on the order in
//! which equal levels are popped.

mod flood;

use flood::{Join, OUTLET, Strip};
use rayon::prelude::*;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Order-preserving key of a finite height: `a < b ⇔ key(a) < key(b)`.
pub(super) fn key(z: f32) -> u32 {
    let b = z.to_bits();
    if b & 0x8000_0000 != 0 {
        !b
    } else {
        b | 0x8000_0000
    }
}

/// A monotone min-queue of (key, cell): every pushed key is at least the
/// last popped one. Bucket `i` holds keys whose highest bit differing from
/// `last` is bit `i − 1` (bucket 0: equal to `last`).
pub(super) struct RadixHeap {
    last: u32,
    buckets: [Vec<(u32, u32)>; 33],
}

impl RadixHeap {
    pub(super) fn new() -> Self {
        RadixHeap {
            last: 0,
            buckets: std::array::from_fn(|_| Vec::new()),
        }
    }

    fn bucket(k: u32, last: u32) -> usize {
        (32 - (k ^ last).leading_zeros()) as usize
    }

    pub(super) fn push(&mut self, k: u32, cell: u32) {
        debug_assert!(k >= self.last, "radix heap keys must not decrease");
        self.buckets[Self::bucket(k, self.last)].push((k, cell));
    }

    /// The cell `ahead` pops from now, if the current bucket holds it.
    fn ahead(&self, ahead: usize) -> Option<u32> {
        let b = &self.buckets[0];
        b.len().checked_sub(ahead + 1).map(|i| b[i].1)
    }

    pub(super) fn pop(&mut self) -> Option<(u32, u32)> {
        if self.buckets[0].is_empty() {
            let i = (1..33).find(|&i| !self.buckets[i].is_empty())?;
            let moved = std::mem::take(&mut self.buckets[i]);
            self.last = moved.iter().map(|e| e.0).min()?;
            for e in &moved {
                self.buckets[Self::bucket(e.0, self.last)].push(*e);
            }
            // Keep the emptied bucket's allocation for later refills.
            let mut moved = moved;
            moved.clear();
            self.buckets[i] = moved;
        }
        self.buckets[0].pop()
    }
}

/// Rows per strip for a grid `w` cells wide: about 2^20 cells, at least 64
/// rows (narrower strips would make the graph as large as the grid).
fn strip_rows(w: usize) -> usize {
    ((1usize << 20) / w).max(64)
}

/// The row ranges of the strips of a grid `h` rows high: `rows` each, the
/// last one also takes the remainder.
fn strips(h: usize, rows: usize) -> Vec<(usize, usize)> {
    let count = (h / rows).max(1);
    (0..count)
        .map(|s| (s * rows, if s + 1 == count { h } else { (s + 1) * rows }))
        .collect()
}

/// Splits `v` (row-major, `w` wide) into the rows of each strip.
fn split<'a, T>(mut v: &'a mut [T], bounds: &[(usize, usize)], w: usize) -> Vec<&'a mut [T]> {
    let mut out = Vec::with_capacity(bounds.len());
    for &(y0, y1) in bounds {
        let (head, tail) = v.split_at_mut((y1 - y0) * w);
        out.push(head);
        v = tail;
    }
    out
}

/// The filled surface of `heights` (`width × height`, no NaN): every cell
/// raised to its spill level. `sea` cells (when given) are outlets like
/// the border; their level is `sea_level`, the water surface.
pub fn priority_flood(
    heights: &[f32],
    width: usize,
    height: usize,
    sea: Option<(&[bool], f32)>,
) -> Vec<f32> {
    let w = width;
    let bounds = strips(height, strip_rows(w));
    let mut z = heights.to_vec();
    let mut label = vec![0u32; z.len()];
    let last = bounds.len() - 1;
    let joins: Vec<Vec<Join>> = split(&mut z, &bounds, w)
        .into_par_iter()
        .zip(split(&mut label, &bounds, w))
        .enumerate()
        .map(|(s, (z, label))| {
            let (y0, y1) = bounds[s];
            flood::flood(Strip {
                z,
                label,
                w,
                h: y1 - y0,
                top_open: s == 0,
                bottom_open: s == last,
                sea: sea.map(|(m, l)| (&m[y0 * w..y1 * w], l)),
            })
        })
        .collect();
    if bounds.len() == 1 {
        return z; // one strip: its edge is the grid's border, all outlets
    }
    let level = solve(&z, &label, &bounds, w, &joins);
    let stride = 2 * w;
    split(&mut z, &bounds, w)
        .into_par_iter()
        .zip(split(&mut label, &bounds, w))
        .enumerate()
        .for_each(|(s, (z, label))| {
            for (v, &l) in z.iter_mut().zip(label.iter()) {
                if l != OUTLET {
                    let lv = level[s * stride + l as usize];
                    if lv > *v {
                        *v = lv;
                    }
                }
            }
        });
    z
}

/// The filled level of every label of every strip (index `strip × 2w +
/// label`): minimax distances from the outlets over the strips' joins and
/// the steps between facing edge rows. `z` and `label` are the strips'
/// floods; an edge cell keeps its height (or the sea level) there.
fn solve(
    z: &[f32],
    label: &[u32],
    bounds: &[(usize, usize)],
    w: usize,
    joins: &[Vec<Join>],
) -> Vec<f32> {
    let stride = 2 * w;
    let source = bounds.len() * stride;
    let node = |s: usize, l: u32| {
        if l == OUTLET {
            source
        } else {
            s * stride + l as usize
        }
    };
    let mut edges: Vec<(u32, u32, f32)> = Vec::new();
    for (s, js) in joins.iter().enumerate() {
        edges.extend(
            js.iter()
                .map(|&(a, b, e)| (node(s, a) as u32, node(s, b) as u32, e)),
        );
    }
    for (s, &(_, y)) in bounds.iter().enumerate().take(bounds.len() - 1) {
        // y: the next strip's first row
        for x in 0..w {
            let a = (y - 1) * w + x;
            for b in (x.saturating_sub(1)..(x + 2).min(w)).map(|bx| y * w + bx) {
                let e = if z[b] > z[a] { z[b] } else { z[a] };
                edges.push((node(s, label[a]) as u32, node(s + 1, label[b]) as u32, e));
            }
        }
    }
    // Adjacency in compressed rows.
    let nodes = source + 1;
    let mut start = vec![0u32; nodes + 1];
    for &(a, b, _) in &edges {
        start[a as usize + 1] += 1;
        start[b as usize + 1] += 1;
    }
    let mut sum = 0;
    for v in start.iter_mut() {
        sum += *v;
        *v = sum;
    }
    let mut next = start.clone();
    let mut adj = vec![(0u32, 0.0f32); 2 * edges.len()];
    for &(a, b, e) in &edges {
        for (from, to) in [(a, b), (b, a)] {
            adj[next[from as usize] as usize] = (to, e);
            next[from as usize] += 1;
        }
    }
    let mut level = vec![f32::INFINITY; nodes];
    level[source] = f32::NEG_INFINITY;
    let mut open = BinaryHeap::new();
    open.push(Reverse((key(f32::NEG_INFINITY), source as u32)));
    while let Some(Reverse((k, a))) = open.pop() {
        let a = a as usize;
        let la = level[a];
        if k != key(la) {
            continue;
        }
        for &(b, e) in &adj[start[a] as usize..start[a + 1] as usize] {
            let nl = if e > la { e } else { la };
            if nl < level[b as usize] {
                level[b as usize] = nl;
                open.push(Reverse((key(nl), b)));
            }
        }
    }
    level
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_keep_the_order_of_heights() {
        let v = [-1e6f32, -3.5, -0.0, 0.0, 1e-30, 2.0, 8848.0];
        for p in v.windows(2) {
            assert!(key(p[0]) <= key(p[1]), "{p:?}");
        }
        assert!(key(-3.5) < key(-1.0) && key(1.0) < key(1.5));
    }

    #[test]
    fn a_pit_fills_to_its_spill_level_and_nothing_else_moves() {
        // 5×5 at 10 m with a pit at 1 m whose rim's lowest cell is 7 m,
        // next to a 5 m border cell: the pit fills to exactly 7 m.
        let mut z = vec![10.0f32; 25];
        for i in [6, 8, 11, 13, 16, 17, 18] {
            z[i] = 9.0;
        }
        z[7] = 7.0;
        z[2] = 5.0;
        z[12] = 1.0;
        let f = priority_flood(&z, 5, 5, None);
        assert_eq!(f[12], 7.0);
        for i in (0..25).filter(|&i| i != 12) {
            assert_eq!(f[i], z[i], "cell {i}");
        }
    }
}
