//! The feature graph (seed 001 §4, seed 004 §4.2.1): PPA's forest reduced to
//! *key nodes* (branch points, degree ≥ 3, and endpoints, degree 1) joined by
//! *paths* (polylines). On it:
//! - breadth-first patch placement from the highest-degree node, a patch
//!   every ½ patch along paths;
//! - control points: where feature paths leave a circle of radius ≈ patch/4
//!   around a patch centre (their count is the node's type: 1 endpoint,
//!   2 path, ≥ 3 branch);
//! - culling: junctions joined by a path shorter than `merge_len` are one
//!   junction (a thick stroke's crossing yields two or three close ones),
//!   and a new patch centre closer than patch/4 to a placed one is skipped.

use crate::patch::input::ppa::Tree;

/// A polyline between two key nodes; `points` runs from `a`'s position to `b`'s.
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    pub a: usize,
    pub b: usize,
    pub points: Vec<[f32; 2]>,
}

impl Path {
    pub fn length(&self) -> f32 {
        self.points.windows(2).map(|s| dist(s[0], s[1])).sum()
    }
}

/// Key nodes and the paths between them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FeatureGraph {
    pub nodes: Vec<[f32; 2]>,
    pub paths: Vec<Path>,
}

pub(crate) fn dist(a: [f32; 2], b: [f32; 2]) -> f32 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

impl FeatureGraph {
    /// Builds the graph from a PPA forest, merging junctions joined by paths
    /// shorter than `merge_len`.
    pub fn from_tree(tree: &Tree, merge_len: f32) -> FeatureGraph {
        let n = tree.pos.len();
        let key: Vec<bool> = tree.adj.iter().map(|a| a.len() != 2).collect();
        let mut key_id = vec![usize::MAX; n];
        let mut g = FeatureGraph::default();
        for i in 0..n {
            if key[i] && !tree.adj[i].is_empty() {
                key_id[i] = g.nodes.len();
                g.nodes.push(tree.pos[i]);
            }
        }
        // Walk every path once (from its lower-index end).
        for s in 0..n {
            if key_id[s] == usize::MAX {
                continue;
            }
            for &first in &tree.adj[s] {
                let mut pts = vec![tree.pos[s]];
                let (mut prev, mut cur) = (s, first as usize);
                while !key[cur] {
                    pts.push(tree.pos[cur]);
                    let next = if tree.adj[cur][0] as usize == prev {
                        tree.adj[cur][1]
                    } else {
                        tree.adj[cur][0]
                    } as usize;
                    prev = cur;
                    cur = next;
                }
                pts.push(tree.pos[cur]);
                // Each path is seen from both ends; keep one copy.
                let keep = (s, pts.get(1).map(|p| (p[0].to_bits(), p[1].to_bits())))
                    < (
                        cur,
                        pts.get(pts.len() - 2)
                            .map(|p| (p[0].to_bits(), p[1].to_bits())),
                    );
                if keep {
                    g.paths.push(Path {
                        a: key_id[s],
                        b: key_id[cur],
                        points: pts,
                    });
                }
            }
        }
        g.merge_junctions(merge_len);
        g
    }

    /// Degree of each key node.
    pub fn degrees(&self) -> Vec<usize> {
        let mut d = vec![0; self.nodes.len()];
        for p in &self.paths {
            d[p.a] += 1;
            d[p.b] += 1;
        }
        d
    }

    /// Contracts short junction–junction paths.
    fn merge_junctions(&mut self, merge_len: f32) {
        let deg = self.degrees();
        let m = self.nodes.len();
        let mut parent: Vec<usize> = (0..m).collect();
        fn find(p: &mut [usize], mut a: usize) -> usize {
            while p[a] != a {
                p[a] = p[p[a]];
                a = p[a];
            }
            a
        }
        let mut drop = vec![false; self.paths.len()];
        for (k, p) in self.paths.iter().enumerate() {
            if deg[p.a] >= 3 && deg[p.b] >= 3 && p.length() < merge_len {
                let (ra, rb) = (find(&mut parent, p.a), find(&mut parent, p.b));
                if ra != rb {
                    parent[ra.max(rb)] = ra.min(rb);
                }
                drop[k] = true;
            }
        }
        if !drop.iter().any(|&d| d) {
            return;
        }
        // New nodes: mean position of each merged group.
        let mut root_new = vec![usize::MAX; m];
        let mut sums: Vec<([f32; 2], f32)> = Vec::new();
        for i in 0..m {
            let r = find(&mut parent, i);
            if root_new[r] == usize::MAX {
                root_new[r] = sums.len();
                sums.push(([0.0, 0.0], 0.0));
            }
            let s = &mut sums[root_new[r]];
            s.0[0] += self.nodes[i][0];
            s.0[1] += self.nodes[i][1];
            s.1 += 1.0;
        }
        let nodes: Vec<[f32; 2]> = sums.iter().map(|(p, c)| [p[0] / c, p[1] / c]).collect();
        let mut paths = Vec::new();
        for (k, p) in self.paths.iter().enumerate() {
            if drop[k] {
                continue;
            }
            let a = root_new[find(&mut parent, p.a)];
            let b = root_new[find(&mut parent, p.b)];
            let mut pts = p.points.clone();
            pts[0] = nodes[a];
            let last = pts.len() - 1;
            pts[last] = nodes[b];
            paths.push(Path { a, b, points: pts });
        }
        self.nodes = nodes;
        self.paths = paths;
    }

    /// Key nodes with their incident paths (path index, whether the node is `a`).
    pub fn incidence(&self) -> Vec<Vec<(usize, bool)>> {
        let mut inc = vec![Vec::new(); self.nodes.len()];
        for (k, p) in self.paths.iter().enumerate() {
            inc[p.a].push((k, true));
            inc[p.b].push((k, false));
        }
        inc
    }

    /// Points along the graph where patches go, in breadth-first order from
    /// the highest-degree node of each component (components by decreasing
    /// top degree, then index): key nodes and a point every `step` along
    /// each path. Points closer than `cull` to an earlier one are skipped.
    pub fn placements(&self, step: f32, cull: f32) -> Vec<[f32; 2]> {
        let deg = self.degrees();
        let inc = self.incidence();
        let m = self.nodes.len();
        // Components and their roots.
        let mut comp = vec![usize::MAX; m];
        let mut roots = Vec::new();
        for s in 0..m {
            if comp[s] != usize::MAX {
                continue;
            }
            let mut stack = vec![s];
            comp[s] = s;
            let mut best = s;
            while let Some(a) = stack.pop() {
                if (deg[a], std::cmp::Reverse(a)) > (deg[best], std::cmp::Reverse(best)) {
                    best = a;
                }
                for &(k, is_a) in &inc[a] {
                    let o = if is_a {
                        self.paths[k].b
                    } else {
                        self.paths[k].a
                    };
                    if comp[o] == usize::MAX {
                        comp[o] = s;
                        stack.push(o);
                    }
                }
            }
            roots.push(best);
        }
        roots.sort_by_key(|&r| (std::cmp::Reverse(deg[r]), r));
        let mut out: Vec<[f32; 2]> = Vec::new();
        let place = |p: [f32; 2], out: &mut Vec<[f32; 2]>| {
            if out.iter().all(|&q| dist(p, q) >= cull) {
                out.push(p);
            }
        };
        let mut seen_node = vec![false; m];
        let mut seen_path = vec![false; self.paths.len()];
        for r in roots {
            let mut queue = std::collections::VecDeque::from([r]);
            seen_node[r] = true;
            while let Some(a) = queue.pop_front() {
                place(self.nodes[a], &mut out);
                for &(k, is_a) in &inc[a] {
                    if seen_path[k] {
                        continue;
                    }
                    seen_path[k] = true;
                    let path = &self.paths[k];
                    let mut pts = path.points.clone();
                    if !is_a {
                        pts.reverse();
                    }
                    let total = path.length();
                    let mut s = step;
                    while s < total - step * 0.5 {
                        place(point_at(&pts, s), &mut out);
                        s += step;
                    }
                    let o = if is_a { path.b } else { path.a };
                    if !seen_node[o] {
                        seen_node[o] = true;
                        queue.push_back(o);
                    }
                }
            }
        }
        out
    }

    /// Where the graph's lines leave the circle of radius `r` around `c`
    /// (which should lie on the graph): one point per exit, sorted by angle.
    /// A line that ends inside the circle counts if its end is at least
    /// `r / 2` from `c`.
    pub fn exits(&self, c: [f32; 2], r: f32) -> Vec<[f32; 2]> {
        // Every path segment that enters the circle contributes; we walk each
        // path and record crossings of the circle from inside to outside,
        // seen from the point of the path nearest to c.
        self.exits_in(&self.exit_index(), c, r)
    }

    /// Degrees and path bounding boxes, for many [`FeatureGraph::exits_in`] queries.
    pub fn exit_index(&self) -> ExitIndex {
        let bbox = self
            .paths
            .iter()
            .map(|p| {
                p.points.iter().fold(
                    [
                        f32::INFINITY,
                        f32::INFINITY,
                        f32::NEG_INFINITY,
                        f32::NEG_INFINITY,
                    ],
                    |b, q| {
                        [
                            b[0].min(q[0]),
                            b[1].min(q[1]),
                            b[2].max(q[0]),
                            b[3].max(q[1]),
                        ]
                    },
                )
            })
            .collect();
        ExitIndex {
            deg: self.degrees(),
            bbox,
        }
    }

    /// [`FeatureGraph::exits`] with a prebuilt index (paths whose bounding
    /// box is farther than `r` are skipped without looking at their points).
    pub fn exits_in(&self, idx: &ExitIndex, c: [f32; 2], r: f32) -> Vec<[f32; 2]> {
        let mut out = Vec::new();
        let deg = &idx.deg;
        for (p, b) in self.paths.iter().zip(&idx.bbox) {
            if c[0] < b[0] - r || c[0] > b[2] + r || c[1] < b[1] - r || c[1] > b[3] + r {
                continue;
            }
            let pts = &p.points;
            // Nearest vertex of the path to c.
            let (near, dn) = pts
                .iter()
                .enumerate()
                .map(|(i, &q)| (i, dist(q, c)))
                .fold((0, f32::INFINITY), |b, x| if x.1 < b.1 { x } else { b });
            if dn > r {
                continue;
            }
            // Walk both directions from the nearest vertex.
            for dir in [1isize, -1] {
                let mut i = near as isize;
                let mut found = None;
                loop {
                    let j = i + dir;
                    if j < 0 || j >= pts.len() as isize {
                        break;
                    }
                    let (a, b) = (pts[i as usize], pts[j as usize]);
                    if dist(b, c) >= r {
                        found = Some(circle_cross(a, b, c, r));
                        break;
                    }
                    i = j;
                }
                match found {
                    Some(q) => out.push(q),
                    None => {
                        // The path ends inside: an exit only at a leaf end
                        // (a junction end continues into other paths, which
                        // contribute their own exits).
                        let end_idx = if dir > 0 { pts.len() - 1 } else { 0 };
                        let end_node = if dir > 0 { p.b } else { p.a };
                        let q = pts[end_idx];
                        if end_idx != near && deg[end_node] == 1 && dist(q, c) >= r * 0.5 {
                            out.push(q);
                        }
                    }
                }
            }
        }
        // Merge exits closer than r/2 (the same line seen from two paths).
        let mut merged: Vec<[f32; 2]> = Vec::new();
        for q in out {
            if merged.iter().all(|&m| dist(m, q) >= r * 0.5) {
                merged.push(q);
            }
        }
        merged.sort_by(|a, b| {
            let ta = (a[1] - c[1]).atan2(a[0] - c[0]);
            let tb = (b[1] - c[1]).atan2(b[0] - c[0]);
            ta.total_cmp(&tb)
        });
        merged
    }
}

/// Per-path data for fast exit queries.
#[derive(Debug, Clone, PartialEq)]
pub struct ExitIndex {
    deg: Vec<usize>,
    bbox: Vec<[f32; 4]>,
}

/// The point at arc length `s` along a polyline.
pub(crate) fn point_at(pts: &[[f32; 2]], s: f32) -> [f32; 2] {
    let mut left = s;
    for w in pts.windows(2) {
        let l = dist(w[0], w[1]);
        if left <= l && l > 0.0 {
            let t = left / l;
            return [
                w[0][0] + t * (w[1][0] - w[0][0]),
                w[0][1] + t * (w[1][1] - w[0][1]),
            ];
        }
        left -= l;
    }
    *pts.last().expect("paths have points")
}

/// Where segment `ab` (a inside, b outside) crosses the circle (c, r).
fn circle_cross(a: [f32; 2], b: [f32; 2], c: [f32; 2], r: f32) -> [f32; 2] {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let (fx, fy) = (a[0] - c[0], a[1] - c[1]);
    let qa = dx * dx + dy * dy;
    let qb = 2.0 * (fx * dx + fy * dy);
    let qc = fx * fx + fy * fy - r * r;
    let disc = (qb * qb - 4.0 * qa * qc).max(0.0);
    let t = if qa > 0.0 {
        ((-qb + disc.sqrt()) / (2.0 * qa)).clamp(0.0, 1.0)
    } else {
        0.0
    };
    [a[0] + t * dx, a[1] + t * dy]
}
