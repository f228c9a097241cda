//! The geometry of a tiled world: tiles' cores, their rings (perimeter
//! cells) and the one-cell halo each tile reads from its neighbours' rings.
//!
//! Every cell just outside a tile's core lies on a neighbouring tile's
//! ring, so whatever the tiles publish about their rings is all a tile
//! needs to know of the world around it.

/// A world cut into `tile × tile` cores, row by row (the last row and
/// column shorter).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    pub world: (usize, usize),
    pub tile: usize,
}

/// A tile's core: its first world cell and size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Core {
    pub x0: usize,
    pub y0: usize,
    pub w: usize,
    pub h: usize,
}

impl Layout {
    /// Columns and rows.
    pub fn size(&self) -> (usize, usize) {
        (
            self.world.0.div_ceil(self.tile),
            self.world.1.div_ceil(self.tile),
        )
    }

    pub fn count(&self) -> usize {
        let (c, r) = self.size();
        c * r
    }

    /// The core of tile `t` (row-major tile index).
    pub fn core(&self, t: usize) -> Core {
        let cols = self.size().0;
        let (x0, y0) = ((t % cols) * self.tile, (t / cols) * self.tile);
        Core {
            x0,
            y0,
            w: self.tile.min(self.world.0 - x0),
            h: self.tile.min(self.world.1 - y0),
        }
    }

    /// The tile holding world cell (x, y).
    pub fn tile_of(&self, x: usize, y: usize) -> usize {
        (y / self.tile) * self.size().0 + x / self.tile
    }
}

/// Ring cells of a `w × h` core.
pub fn ring_len(w: usize, h: usize) -> usize {
    match (w, h) {
        (_, 1) => w,
        (1, _) => h,
        _ => 2 * (w + h) - 4,
    }
}

/// The ring index of core cell (x, y), clockwise from the top-left corner
/// (top row, right column, bottom row, left column); `None` inside.
pub fn ring_index(x: usize, y: usize, w: usize, h: usize) -> Option<usize> {
    if y == 0 {
        Some(x)
    } else if x == w - 1 {
        Some(w + y - 1)
    } else if y == h - 1 {
        Some(w + h - 1 + (w - 2 - x))
    } else if x == 0 {
        Some(2 * w + h - 2 + (h - 2 - y))
    } else {
        None
    }
}

/// The ring's cells (core coordinates) in ring-index order.
pub fn ring_cells(w: usize, h: usize) -> Vec<(usize, usize)> {
    let mut v = vec![(0, 0); ring_len(w, h)];
    let edge = (0..w).flat_map(|x| [(x, 0), (x, h - 1)]);
    for (x, y) in edge.chain((0..h).flat_map(|y| [(0, y), (w - 1, y)])) {
        let r = ring_index(x, y, w, h).expect("an edge cell is on the ring");
        v[r] = (x, y);
    }
    v
}

/// One value per ring cell of every tile.
#[derive(Debug, Clone, PartialEq)]
pub struct Rings<T> {
    base: Vec<usize>,
    pub values: Vec<T>,
}

impl<T: Copy> Rings<T> {
    pub fn new(layout: &Layout, fill: T) -> Self {
        let mut base = Vec::with_capacity(layout.count() + 1);
        let mut n = 0;
        for t in 0..layout.count() {
            base.push(n);
            let c = layout.core(t);
            n += ring_len(c.w, c.h);
        }
        base.push(n);
        Rings {
            base,
            values: vec![fill; n],
        }
    }

    /// Global index of ring cell `r` of tile `t`.
    pub fn node(&self, t: usize, r: usize) -> usize {
        self.base[t] + r
    }

    pub fn tile(&self, t: usize) -> &[T] {
        &self.values[self.base[t]..self.base[t + 1]]
    }

    pub fn tile_mut(&mut self, t: usize) -> &mut [T] {
        &mut self.values[self.base[t]..self.base[t + 1]]
    }

    /// The global index of world cell (x, y), which must lie on a ring.
    pub fn node_at(&self, layout: &Layout, x: usize, y: usize) -> usize {
        let t = layout.tile_of(x, y);
        let c = layout.core(t);
        let r = ring_index(x - c.x0, y - c.y0, c.w, c.h).expect("a cell on its tile's ring");
        self.base[t] + r
    }
}

/// A core with a one-cell halo, row-major `(w + 2) × (h + 2)`.
#[derive(Debug, Clone, Copy)]
pub struct Pad {
    pub core: Core,
}

impl Pad {
    pub fn pw(&self) -> usize {
        self.core.w + 2
    }

    pub fn cells(&self) -> usize {
        self.pw() * (self.core.h + 2)
    }

    /// The padded index of core cell (x, y).
    pub fn at(&self, x: usize, y: usize) -> usize {
        (y + 1) * self.pw() + x + 1
    }

    /// Neighbour offsets in [`super::super::d8::CLOCKWISE`] order.
    pub fn offsets(&self) -> [isize; 8] {
        let pw = self.pw() as isize;
        super::super::d8::CLOCKWISE.map(|(dx, dy, _)| dy * pw + dx)
    }

    /// Padded index → core cell (x, y), `None` on the halo.
    pub fn to_core(&self, p: usize) -> Option<(usize, usize)> {
        let (x, y) = (p % self.pw(), p / self.pw());
        (x >= 1 && y >= 1 && x <= self.core.w && y <= self.core.h).then(|| (x - 1, y - 1))
    }

    /// Every halo cell inside the world: (padded index, world x, world y).
    pub fn halo(&self, layout: &Layout) -> Vec<(usize, usize, usize)> {
        let c = self.core;
        let (ww, wh) = layout.world;
        let mut v = Vec::with_capacity(2 * (c.w + c.h) + 4);
        for py in 0..c.h + 2 {
            for px in 0..c.w + 2 {
                if (1..=c.w).contains(&px) && (1..=c.h).contains(&py) {
                    continue;
                }
                let (gx, gy) = ((c.x0 + px).checked_sub(1), (c.y0 + py).checked_sub(1));
                if let (Some(gx), Some(gy)) = (gx, gy)
                    && gx < ww
                    && gy < wh
                {
                    v.push((py * self.pw() + px, gx, gy));
                }
            }
        }
        v
    }

    /// `core` padded, the halo read from `rings` (`outside` beyond the
    /// world).
    pub fn padded<T: Copy>(
        &self,
        layout: &Layout,
        core: &[T],
        rings: &Rings<T>,
        outside: T,
    ) -> Vec<T> {
        let c = self.core;
        let mut v = vec![outside; self.cells()];
        for y in 0..c.h {
            let p = self.at(0, y);
            v[p..p + c.w].copy_from_slice(&core[y * c.w..(y + 1) * c.w]);
        }
        for (p, gx, gy) in self.halo(layout) {
            v[p] = rings.values[rings.node_at(layout, gx, gy)];
        }
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rings_number_each_edge_cell_once() {
        for (w, h) in [(1, 1), (5, 1), (1, 4), (2, 2), (5, 3), (7, 7)] {
            let cells = ring_cells(w, h);
            assert_eq!(cells.len(), ring_len(w, h), "{w}x{h}");
            for (r, &(x, y)) in cells.iter().enumerate() {
                assert_eq!(ring_index(x, y, w, h), Some(r), "{w}x{h} ({x}, {y})");
            }
            let mut sorted = cells.clone();
            sorted.sort();
            sorted.dedup();
            assert_eq!(sorted.len(), cells.len(), "{w}x{h}: a cell twice");
        }
        assert_eq!(ring_index(2, 1, 5, 3), None);
    }
}
