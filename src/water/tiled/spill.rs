//! The tiled priority-flood of Barnes (2016, "Parallel priority-flood
//! depression filling for trillion cell digital elevation models"): each
//! tile is flooded from its ring, every ring cell a label of its own, and
//! where two labels meet the flood records the level at which they join;
//! those joins and the steps between neighbouring tiles' rings form a
//! spill graph, whose minimax distances from the world's border are the
//! filled levels of the ring cells. Each tile is then filled again with its
//! ring raised to them ([`super::super::fill::priority_flood`] on the core
//! with the ring replaced).
//!
//! Why it is exact: the filled level of a cell is the least, over paths to
//! the world's border, of the highest height on the path. A path from a
//! tile's cell leaves the tile through a first ring cell `p`, so the level
//! is the least over `p` of max(the best path to `p` inside the tile, the
//! level of `p`) — a flood of the core seeded from its ring at the ring's
//! levels. Inside a tile, the highest level on the way between two ring
//! cells is found by the labelled flood: a join of labels `a` and `b` at
//! cells `c`, `n` costs max(level(c), level(n)), which no path between them
//! can beat (each cell's level is at most the highest height of any path
//! from it to a ring cell), and which a path achieves (the flood's paths
//! from `a` to `c` and from `n` to `b` stay below those levels). Levels are
//! copies of heights, never sums, so the result is bit for bit the
//! whole-world fill.

use super::super::d8::CLOCKWISE;
use super::super::fill::{RadixHeap, key};
use super::ring::{Layout, Rings, ring_cells};
use crate::procedural::grid::neighbour;
use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashMap};

/// A join of two ring cells of one tile: (ring a, ring b, level), a < b.
pub type Join = (u32, u32, f32);

/// The joins of a `w × h` core's ring cells (`z` row-major, no NaN).
pub fn joins(z: &[f32], w: usize, h: usize) -> Vec<Join> {
    let mut label = vec![u32::MAX; w * h];
    let mut level = vec![0.0f32; w * h];
    let mut open = RadixHeap::new();
    for (r, (x, y)) in ring_cells(w, h).into_iter().enumerate() {
        let i = y * w + x;
        label[i] = r as u32;
        level[i] = z[i];
        open.push(key(z[i]), i as u32);
    }
    let mut best: HashMap<(u32, u32), f32> = HashMap::new();
    while let Some((_, c)) = open.pop() {
        let c = c as usize;
        let (lc, ac) = (level[c], label[c]);
        for &(dx, dy, _) in &CLOCKWISE {
            let Some(k) = neighbour(c % w, c / w, dx, dy, w, h) else {
                continue;
            };
            if label[k] == u32::MAX {
                label[k] = ac;
                level[k] = if z[k] > lc { z[k] } else { lc };
                open.push(key(level[k]), k as u32);
            } else if label[k] != ac {
                let e = if level[k] > lc { level[k] } else { lc };
                let pair = (ac.min(label[k]), ac.max(label[k]));
                best.entry(pair)
                    .and_modify(|v| {
                        if e < *v {
                            *v = e
                        }
                    })
                    .or_insert(e);
            }
        }
    }
    let mut v: Vec<Join> = best.into_iter().map(|((a, b), e)| (a, b, e)).collect();
    v.sort_unstable_by_key(|&(a, b, _)| (a, b));
    v
}

/// The filled level of every ring cell of the world, from the rings'
/// heights and each tile's [`joins`].
pub fn solve(layout: &Layout, z: &Rings<f32>, joins: &[Vec<Join>]) -> Rings<f32> {
    let n = z.values.len();
    let mut adj: Vec<Vec<(u32, f32)>> = vec![Vec::new(); n];
    let mut link = |a: usize, b: usize, e: f32| {
        adj[a].push((b as u32, e));
        adj[b].push((a as u32, e));
    };
    for (t, js) in joins.iter().enumerate() {
        for &(a, b, e) in js {
            link(z.node(t, a as usize), z.node(t, b as usize), e);
        }
    }
    let (ww, wh) = layout.world;
    let mut level = Rings::new(layout, f32::INFINITY);
    let mut open = BinaryHeap::new();
    for t in 0..layout.count() {
        let c = layout.core(t);
        for (r, (x, y)) in ring_cells(c.w, c.h).into_iter().enumerate() {
            let (gx, gy) = (c.x0 + x, c.y0 + y);
            let a = z.node(t, r);
            for &(dx, dy, _) in &CLOCKWISE {
                let Some(k) = neighbour(gx, gy, dx, dy, ww, wh) else {
                    continue;
                };
                let (kx, ky) = (k % ww, k / ww);
                if layout.tile_of(kx, ky) > t {
                    let b = z.node_at(layout, kx, ky);
                    let (za, zb) = (z.values[a], z.values[b]);
                    link(a, b, if zb > za { zb } else { za });
                }
            }
            if gx == 0 || gy == 0 || gx == ww - 1 || gy == wh - 1 {
                level.values[a] = z.values[a];
                open.push(Reverse((key(z.values[a]), a as u32)));
            }
        }
    }
    while let Some(Reverse((k, a))) = open.pop() {
        let a = a as usize;
        if k != key(level.values[a]) {
            continue;
        }
        let la = level.values[a];
        for &(b, e) in &adj[a] {
            let nl = if e > la { e } else { la };
            if nl < level.values[b as usize] {
                level.values[b as usize] = nl;
                open.push(Reverse((key(nl), b)));
            }
        }
    }
    level
}
