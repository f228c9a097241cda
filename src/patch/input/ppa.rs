//! Profile recognition and Polygon breaking Algorithm (PPA; Chang et al.
//! 1998, as used by seed 001 §3) in the spanning-tree form of seed 004 §4.1
//! (Bangay et al. 2010, Tasse et al. 2011): polygon breaking is replaced by
//! a maximum spanning forest (Kruskal), which removes exactly the least
//! important segment of every closed polygon.
//!
//! Ridges of `h` are extracted; valleys are the ridges of `−h`.
//!
//! 1. **Profile recognition**: a pixel is a candidate when, along at least
//!    one of the 4 profile directions (N–S, E–W, NE–SW, NW–SE), both sides
//!    within `reach` pixels dip below it by more than `threshold`. (Seed 004
//!    says "at least one point lower on both sides", seed 001 "dips below by
//!    more than a threshold"; we use both: lower by > threshold on both sides.)
//! 2. **Target connection**: 8-adjacent candidates are joined by segments of
//!    importance `h(a) + h(b)`; where two diagonals of a 2×2 block cross,
//!    the less important one is dropped.
//! 3. **Polygon breaking**: maximum spanning forest of the segments (ties
//!    broken by segment index so the result is deterministic).
//! 4. **Branch reduction**: side branches (leaf to junction) shorter than
//!    `min_branch` pixels are deleted, for `passes` rounds; whole components
//!    shorter than `min_component` are dropped.
//! 5. **Line smoothing**: each node moves to the height-weighted mean of
//!    itself and its neighbours (weights grow with elevation, so a ridge
//!    line is pulled toward the crest; less than one pixel per round).

use rayon::prelude::*;

/// Parameters of [`extract`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PpaParams {
    /// Profile half-length in pixels.
    pub reach: usize,
    /// Minimum dip on both sides of a profile, in height units.
    pub threshold: f32,
    /// Side branches shorter than this (pixels) are removed.
    pub min_branch: f32,
    /// Rounds of branch reduction.
    pub passes: usize,
    /// Components with less total length (pixels) are removed.
    pub min_component: f32,
    /// Rounds of line smoothing.
    pub smooth: usize,
}

/// A forest of feature lines: node positions (pixel centres at integer +
/// 0.5 before smoothing) and undirected adjacency.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tree {
    pub pos: Vec<[f32; 2]>,
    pub adj: Vec<Vec<u32>>,
}

impl Tree {
    /// Number of undirected edges.
    pub fn edge_count(&self) -> usize {
        self.adj.iter().map(Vec::len).sum::<usize>() / 2
    }

    /// Number of connected components.
    pub fn components(&self) -> usize {
        let mut seen = vec![false; self.pos.len()];
        let mut count = 0;
        for s in 0..self.pos.len() {
            if seen[s] {
                continue;
            }
            count += 1;
            let mut stack = vec![s];
            seen[s] = true;
            while let Some(n) = stack.pop() {
                for &m in &self.adj[n] {
                    if !seen[m as usize] {
                        seen[m as usize] = true;
                        stack.push(m as usize);
                    }
                }
            }
        }
        count
    }
}

const DIRS: [(isize, isize); 4] = [(1, 0), (0, 1), (1, 1), (1, -1)];

/// Step 1: candidate mask.
pub fn profile_candidates(w: usize, h: usize, hts: &[f32], reach: usize, t: f32) -> Vec<bool> {
    let mut out = vec![false; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let c = hts[y * w + x];
            let lim = c - t;
            let dips = |dx: isize, dy: isize| {
                let (mut px, mut py) = (x as isize, y as isize);
                for _ in 0..reach {
                    px += dx;
                    py += dy;
                    if px < 0 || py < 0 || px >= w as isize || py >= h as isize {
                        return false;
                    }
                    if hts[py as usize * w + px as usize] < lim {
                        return true;
                    }
                }
                false
            };
            *o = DIRS.iter().any(|&(dx, dy)| dips(dx, dy) && dips(-dx, -dy));
        }
    });
    out
}

/// Runs all five steps on `hts` (`w × h`, finite).
pub fn extract(w: usize, h: usize, hts: &[f32], p: &PpaParams) -> Tree {
    let cand = profile_candidates(w, h, hts, p.reach, p.threshold);
    // Node ids for candidates.
    let mut id = vec![u32::MAX; w * h];
    let mut pix = Vec::new();
    for (i, &c) in cand.iter().enumerate() {
        if c {
            id[i] = pix.len() as u32;
            pix.push(i);
        }
    }
    // Step 2: segments E, S, SE, SW with crossing diagonals resolved.
    let at = |x: usize, y: usize| id[y * w + x];
    let mut edges: Vec<(u32, u32, f32)> = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let a = at(x, y);
            if a == u32::MAX {
                continue;
            }
            let ha = hts[y * w + x];
            let mut push = |bx: usize, by: usize| {
                let b = at(bx, by);
                if b != u32::MAX {
                    edges.push((a, b, ha + hts[by * w + bx]));
                }
            };
            if x + 1 < w {
                push(x + 1, y);
            }
            if y + 1 < h {
                push(x, y + 1);
                if x + 1 < w {
                    // SE crosses the SW diagonal of (x+1, y) → (x, y+1).
                    let sw_a = at(x + 1, y);
                    let sw_b = at(x, y + 1);
                    let se_b = at(x + 1, y + 1);
                    let crossing = sw_a != u32::MAX && sw_b != u32::MAX;
                    let se_w = ha + hts[(y + 1) * w + x + 1];
                    let sw_w = hts[y * w + x + 1] + hts[(y + 1) * w + x];
                    if se_b != u32::MAX && !(crossing && sw_w > se_w) {
                        push(x + 1, y + 1);
                    }
                }
                if x > 0 {
                    // SW of (x, y) crosses SE of (x−1, y) → (x, y+1).
                    let se_a = at(x - 1, y);
                    let se_b = at(x, y + 1);
                    let crossing = se_a != u32::MAX && se_b != u32::MAX;
                    let sw_w = ha + hts[(y + 1) * w + x - 1];
                    let se_w = hts[y * w + x - 1] + hts[(y + 1) * w + x];
                    if at(x - 1, y + 1) != u32::MAX && !(crossing && se_w >= sw_w) {
                        push(x - 1, y + 1);
                    }
                }
            }
        }
    }
    // Step 3: maximum spanning forest (Kruskal, heaviest first, ties by index).
    let mut order: Vec<u32> = (0..edges.len() as u32).collect();
    order.par_sort_unstable_by(|&i, &j| {
        edges[j as usize]
            .2
            .total_cmp(&edges[i as usize].2)
            .then(i.cmp(&j))
    });
    let n = pix.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(parent: &mut [u32], mut a: u32) -> u32 {
        while parent[a as usize] != a {
            let g = parent[parent[a as usize] as usize];
            parent[a as usize] = g;
            a = g;
        }
        a
    }
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &e in &order {
        let (a, b, _) = edges[e as usize];
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[ra as usize] = rb;
            adj[a as usize].push(b);
            adj[b as usize].push(a);
        }
    }
    let mut pos: Vec<[f32; 2]> = pix
        .iter()
        .map(|&i| [(i % w) as f32 + 0.5, (i / w) as f32 + 0.5])
        .collect();
    let mut alive = vec![true; n];
    // Step 4: branch reduction. Each pass finds the short side branches
    // (leaf → first junction) on the pass's starting state and deletes them
    // together — except that a junction never loses all its branches but
    // one: then the longest short one is kept, because it is the end of a
    // main line (deleting it every pass would eat lines from their tips).
    let dist = |a: [f32; 2], b: [f32; 2]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    for _ in 0..p.passes {
        // (junction, length, chain) of every short branch.
        let mut short: Vec<(usize, f32, Vec<usize>)> = Vec::new();
        for s in 0..n {
            if !alive[s] || adj[s].len() != 1 {
                continue;
            }
            let mut chain = vec![s];
            let (mut prev, mut cur) = (s, adj[s][0] as usize);
            let mut len = dist(pos[s], pos[cur]);
            while adj[cur].len() == 2 && len < p.min_branch {
                let next = if adj[cur][0] as usize == prev {
                    adj[cur][1]
                } else {
                    adj[cur][0]
                } as usize;
                chain.push(cur);
                len += dist(pos[cur], pos[next]);
                prev = cur;
                cur = next;
            }
            if adj[cur].len() >= 3 && len < p.min_branch {
                short.push((cur, len, chain));
            }
        }
        if short.is_empty() {
            break;
        }
        // Group by junction (stable: by junction, then length, then leaf).
        short.sort_by(|a, b| {
            a.0.cmp(&b.0)
                .then(b.1.total_cmp(&a.1))
                .then(a.2[0].cmp(&b.2[0]))
        });
        let mut i = 0;
        while i < short.len() {
            let j = short[i].0;
            let mut k = i;
            while k < short.len() && short[k].0 == j {
                k += 1;
            }
            // short[i] is the longest at this junction.
            let keep_longest = k - i + 1 >= adj[j].len();
            for (idx, (_, _, chain)) in short[i..k].iter().enumerate() {
                if keep_longest && idx == 0 {
                    continue;
                }
                let last = *chain.last().expect("chain starts with the leaf");
                adj[j].retain(|&m| m as usize != last);
                for &c in chain {
                    alive[c] = false;
                    adj[c].clear();
                }
            }
            i = k;
        }
    }
    // Drop short components.
    let mut comp = vec![u32::MAX; n];
    for s in 0..n {
        if !alive[s] || comp[s] != u32::MAX {
            continue;
        }
        let mut members = vec![s];
        comp[s] = s as u32;
        let mut k = 0;
        let mut length = 0.0f32;
        while k < members.len() {
            let a = members[k];
            k += 1;
            for &m in &adj[a] {
                let m = m as usize;
                if comp[m] == u32::MAX {
                    comp[m] = s as u32;
                    members.push(m);
                    length += dist(pos[a], pos[m]);
                }
            }
        }
        if length < p.min_component {
            for &m in &members {
                alive[m] = false;
                adj[m].clear();
            }
        }
    }
    // Step 5: smoothing, weights = elevation above the lowest node + 1.
    let hmin = pix
        .iter()
        .zip(&alive)
        .filter(|(_, a)| **a)
        .map(|(&i, _)| hts[i])
        .fold(f32::INFINITY, f32::min);
    let range = pix
        .iter()
        .zip(&alive)
        .filter(|(_, a)| **a)
        .map(|(&i, _)| hts[i] - hmin)
        .fold(0.0f32, f32::max)
        .max(1e-6);
    let wt: Vec<f32> = pix.iter().map(|&i| 1.0 + (hts[i] - hmin) / range).collect();
    for _ in 0..p.smooth {
        let next: Vec<[f32; 2]> = (0..n)
            .map(|a| {
                if !alive[a] || adj[a].len() != 2 {
                    return pos[a];
                }
                let (mut sx, mut sy, mut sw) = (pos[a][0] * wt[a], pos[a][1] * wt[a], wt[a]);
                for &m in &adj[a] {
                    let m = m as usize;
                    sx += pos[m][0] * wt[m];
                    sy += pos[m][1] * wt[m];
                    sw += wt[m];
                }
                [sx / sw, sy / sw]
            })
            .collect();
        pos = next;
    }
    // Compact.
    let mut new_id = vec![u32::MAX; n];
    let mut tree = Tree::default();
    for a in 0..n {
        if alive[a] {
            new_id[a] = tree.pos.len() as u32;
            tree.pos.push(pos[a]);
        }
    }
    for a in 0..n {
        if alive[a] {
            tree.adj
                .push(adj[a].iter().map(|&m| new_id[m as usize]).collect());
        }
    }
    tree
}
