//! Graph-cut seams (seed 001 App. A after Kwatra et al. 2003; seed 004
//! §4.3.1): over a patch window, each pixel takes the old output (A) or the
//! new patch (B) so that the sum of edge costs across the seam is minimal.
//! Solved as a minimum s–t cut by Dinic's max-flow on the 4-connected grid
//! with integer capacities (deterministic, exact).

/// What a window pixel may become.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Label {
    /// Either (an overlap pixel).
    Free,
    /// Must stay old (filled pixels on the window border).
    Old,
    /// Must be new (unfilled pixels; a feature patch's core).
    New,
}

/// Capacity standing for "infinite".
pub const INF: i64 = 1 << 50;

/// Max-flow on a small graph (Dinic).
struct Flow {
    head: Vec<u32>,
    next: Vec<u32>,
    to: Vec<u32>,
    cap: Vec<i64>,
}

const NIL: u32 = u32::MAX;

impl Flow {
    fn new(n: usize) -> Flow {
        Flow {
            head: vec![NIL; n],
            next: Vec::new(),
            to: Vec::new(),
            cap: Vec::new(),
        }
    }

    /// Adds `a → b` with capacity `c_ab` and `b → a` with `c_ba` (one pair of arcs).
    fn add(&mut self, a: usize, b: usize, c_ab: i64, c_ba: i64) {
        for (x, y, c) in [(a, b, c_ab), (b, a, c_ba)] {
            self.to.push(y as u32);
            self.cap.push(c);
            self.next.push(self.head[x]);
            self.head[x] = (self.to.len() - 1) as u32;
        }
    }

    fn max_flow(&mut self, s: usize, t: usize) -> i64 {
        let n = self.head.len();
        let mut total = 0i64;
        let mut level = vec![u32::MAX; n];
        let mut iter = vec![NIL; n];
        let mut queue = Vec::with_capacity(n);
        loop {
            level.fill(u32::MAX);
            level[s] = 0;
            queue.clear();
            queue.push(s as u32);
            let mut qi = 0;
            while qi < queue.len() {
                let a = queue[qi] as usize;
                qi += 1;
                let mut e = self.head[a];
                while e != NIL {
                    let b = self.to[e as usize] as usize;
                    if self.cap[e as usize] > 0 && level[b] == u32::MAX {
                        level[b] = level[a] + 1;
                        queue.push(b as u32);
                    }
                    e = self.next[e as usize];
                }
            }
            if level[t] == u32::MAX {
                return total;
            }
            iter.copy_from_slice(&self.head);
            loop {
                let f = self.augment(s, t, INF, &level, &mut iter);
                if f == 0 {
                    break;
                }
                total += f;
            }
        }
    }

    /// Iterative DFS along the level graph; pushes one blocking path.
    fn augment(&mut self, s: usize, t: usize, limit: i64, level: &[u32], iter: &mut [u32]) -> i64 {
        let mut stack: Vec<u32> = Vec::new(); // arcs taken
        let mut a = s;
        loop {
            if a == t {
                let f = stack
                    .iter()
                    .map(|&e| self.cap[e as usize])
                    .fold(limit, i64::min);
                for &e in &stack {
                    self.cap[e as usize] -= f;
                    self.cap[(e ^ 1) as usize] += f;
                }
                return f;
            }
            let mut advanced = false;
            while iter[a] != NIL {
                let e = iter[a] as usize;
                let b = self.to[e] as usize;
                if self.cap[e] > 0 && level[b] == level[a] + 1 {
                    stack.push(e as u32);
                    a = b;
                    advanced = true;
                    break;
                }
                iter[a] = self.next[e];
            }
            if !advanced {
                // Dead end: retreat.
                match stack.pop() {
                    None => return 0,
                    Some(e) => {
                        a = self.to[(e ^ 1) as usize] as usize;
                        iter[a] = self.next[iter[a] as usize];
                    }
                }
            }
        }
    }

    /// Nodes reachable from `s` in the residual graph.
    fn source_side(&self, s: usize) -> Vec<bool> {
        let mut seen = vec![false; self.head.len()];
        seen[s] = true;
        let mut stack = vec![s];
        while let Some(a) = stack.pop() {
            let mut e = self.head[a];
            while e != NIL {
                let b = self.to[e as usize] as usize;
                if self.cap[e as usize] > 0 && !seen[b] {
                    seen[b] = true;
                    stack.push(b);
                }
                e = self.next[e as usize];
            }
        }
        seen
    }
}

/// A solved seam: which pixels take the new patch, and the cut's cost.
#[derive(Debug, Clone, PartialEq)]
pub struct Seam {
    pub cost: i64,
    pub take_new: Vec<bool>,
}

/// Minimum cut over a `w × h` window with labels and the cost of cutting
/// between horizontal neighbours `(x, y)–(x+1, y)` (`cost_h[y·w + x]`) and
/// vertical ones `(x, y)–(x, y+1)` (`cost_v[y·w + x]`), all ≥ 0.
///
/// Only the free pixels become graph nodes: constrained pixels are merged
/// into their terminal (an edge to one becomes a terminal edge, an edge
/// between an old and a new pixel is always cut and just adds its cost).
/// Patch windows are mostly constrained, so this shrinks the graph several
/// times over.
pub fn min_cut(w: usize, h: usize, labels: &[Label], cost_h: &[i64], cost_v: &[i64]) -> Seam {
    let n = w * h;
    let mut node = vec![u32::MAX; n];
    let mut count = 0usize;
    for i in 0..n {
        if labels[i] == Label::Free {
            node[i] = count as u32;
            count += 1;
        }
    }
    let (s, t) = (count, count + 1);
    let mut g = Flow::new(count + 2);
    let mut fixed_cost = 0i64;
    let mut link = |g: &mut Flow, i: usize, j: usize, c: i64| {
        if c == 0 {
            return;
        }
        match (labels[i], labels[j]) {
            (Label::Free, Label::Free) => g.add(node[i] as usize, node[j] as usize, c, c),
            (Label::Free, Label::Old) => g.add(s, node[i] as usize, c, 0),
            (Label::Old, Label::Free) => g.add(s, node[j] as usize, c, 0),
            (Label::Free, Label::New) => g.add(node[i] as usize, t, c, 0),
            (Label::New, Label::Free) => g.add(node[j] as usize, t, c, 0),
            (Label::Old, Label::New) | (Label::New, Label::Old) => fixed_cost += c,
            _ => {}
        }
    };
    for i in 0..n {
        let (x, y) = (i % w, i / w);
        if x + 1 < w {
            link(&mut g, i, i + 1, cost_h[i]);
        }
        if y + 1 < h {
            link(&mut g, i, i + w, cost_v[i]);
        }
    }
    let cost = g.max_flow(s, t) + fixed_cost;
    let side = g.source_side(s);
    Seam {
        cost,
        take_new: (0..n)
            .map(|i| match labels[i] {
                Label::Old => false,
                Label::New => true,
                Label::Free => !side[node[i] as usize],
            })
            .collect(),
    }
}

/// Kwatra's gradient-normalised matching cost between neighbours s and t
/// along direction d (seed 004 §4.3.1, glyphs lost, read as in Kwatra et al.
/// 2003 eq. 5): `M = (|a(s) − b(s)| + |a(t) − b(t)|) / (|G_a^d(s)| +
/// |G_a^d(t)| + |G_b^d(s)| + |G_b^d(t)| + ε)`, scaled by 256 to an integer.
/// Heights are integer decimetres, gradients central differences in dm per
/// pixel, `ε = 10` (1 m): seams prefer to run where both patches agree and
/// through rough ground, where a mismatch is hidden.
pub fn kwatra(dsa: i64, dta: i64, gsum: i64) -> i64 {
    ((dsa.abs() + dta.abs()) * 256) / (gsum + 10)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chain_is_cut_at_its_cheapest_link() {
        // 5 pixels in a row, Old | F F F | New, link costs 7 3 9 4.
        let labels = [
            Label::Old,
            Label::Free,
            Label::Free,
            Label::Free,
            Label::New,
        ];
        let cost_h = [7, 3, 9, 4, 0];
        let s = min_cut(5, 1, &labels, &cost_h, &[0; 5]);
        assert_eq!(s.cost, 3);
        assert_eq!(s.take_new, [false, false, true, true, true]);
    }
}
