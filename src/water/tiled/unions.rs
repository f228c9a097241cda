//! Bodies that cross tiles — flats, lakes — as components: each tile
//! labels its own, and those reaching its ring ("open" ones) are joined
//! across tiles by a union-find, so a global aggregate (a flat's highest
//! climb, a lake's area and depth) sums every tile's share.

use super::ring::{Pad, ring_cells};

/// No component.
pub const NONE: u32 = u32::MAX;

/// Disjoint sets over `0..n`.
pub struct Unions {
    parent: Vec<u32>,
}

impl Unions {
    pub fn new(n: usize) -> Self {
        Unions {
            parent: (0..n as u32).collect(),
        }
    }

    pub fn find(&mut self, mut a: usize) -> usize {
        while self.parent[a] as usize != a {
            let g = self.parent[self.parent[a] as usize];
            self.parent[a] = g;
            a = g as usize;
        }
        a
    }

    pub fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        // The lower root wins: the result does not depend on the order.
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.parent[hi] = lo as u32;
        }
    }
}

/// A tile's components: 8-connected runs of core cells that are `member`s,
/// neighbours joined where `joined` (both arguments padded indices).
pub struct Components {
    /// Component of every core cell, [`NONE`] for non-members.
    pub id: Vec<u32>,
    pub count: usize,
    /// The open index of each component reaching the ring, [`NONE`] for
    /// the others; open indices number them in ring order.
    pub open: Vec<u32>,
    pub open_count: usize,
}

impl Components {
    pub fn label(
        pad: &Pad,
        member: impl Fn(usize) -> bool,
        joined: impl Fn(usize, usize) -> bool,
    ) -> Self {
        let (w, h) = (pad.core.w, pad.core.h);
        let offsets = pad.offsets();
        let mut id = vec![NONE; w * h];
        let mut count = 0u32;
        let mut stack = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let p = pad.at(x, y);
                if id[y * w + x] != NONE || !member(p) {
                    continue;
                }
                id[y * w + x] = count;
                stack.push(p);
                while let Some(c) = stack.pop() {
                    for o in offsets {
                        let k = c.wrapping_add_signed(o);
                        if let Some((kx, ky)) = pad.to_core(k)
                            && id[ky * w + kx] == NONE
                            && member(k)
                            && joined(c, k)
                        {
                            id[ky * w + kx] = count;
                            stack.push(k);
                        }
                    }
                }
                count += 1;
            }
        }
        let mut open = vec![NONE; count as usize];
        let mut open_count = 0;
        for (x, y) in ring_cells(w, h) {
            let c = id[y * w + x];
            if c != NONE && open[c as usize] == NONE {
                open[c as usize] = open_count;
                open_count += 1;
            }
        }
        Components {
            id,
            count: count as usize,
            open,
            open_count: open_count as usize,
        }
    }

    /// The open index of each ring cell's component, [`NONE`] where none.
    pub fn ring(&self, w: usize, h: usize) -> Vec<u32> {
        ring_cells(w, h)
            .into_iter()
            .map(|(x, y)| match self.id[y * w + x] {
                NONE => NONE,
                c => self.open[c as usize],
            })
            .collect()
    }
}
