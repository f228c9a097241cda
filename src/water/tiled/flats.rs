//! Flat resolution across tiles: the rules of [`super::super::flats`]
//! (Barnes, Lehman & Mulla 2014, as pysheds implements them) on one tile
//! whose halo is read from its neighbours' rings.
//!
//! The paper's two breadth-first sweeps are shortest step counts from
//! their sources (low edges; flat cells beside higher ground) through the
//! flats, so across tiles they are found by passing distances: a tile
//! spreads them from its own sources and from its halo's published
//! distances, publishes its ring's, and the tiles whose halo changed run
//! again until nothing changes (`super::settle`). Distances only fall and
//! each is the length of a real path, so the fixed point is the whole
//! world's. A flat's inversion of the second sweep needs its largest value
//! over the whole flat: the open flats' maxima are joined across tiles
//! ([`super::unions`]).

use super::super::flats::{DRAINS, FLAT, HIGHER, classify};
use super::ring::{Layout, Pad, Rings};
use super::unions::{Components, NONE};

/// One tile's filled surface, padded, with its cells classified.
pub struct Surface {
    pub pad: Pad,
    /// Filled levels (the sea at sea level); +∞ beyond the world.
    pub f: Vec<f32>,
    pub sea: Vec<bool>,
    /// [`FLAT`], [`DRAINS`], [`HIGHER`] bits; 0 beyond the world.
    pub class: Vec<u8>,
}

impl Surface {
    /// The classes of the core cells, from the padded levels.
    pub fn classify_core(pad: &Pad, layout: &Layout, f: &[f32], sea: &[bool]) -> Vec<u8> {
        let c = pad.core;
        let (ww, wh) = layout.world;
        let offsets = pad.offsets();
        let mut class = vec![0u8; c.w * c.h];
        for y in 0..c.h {
            for x in 0..c.w {
                let (gx, gy, p) = (c.x0 + x, c.y0 + y, pad.at(x, y));
                class[y * c.w + x] = if gx == 0 || gy == 0 || gx == ww - 1 || gy == wh - 1 || sea[p]
                {
                    DRAINS
                } else {
                    classify(f[p], offsets.map(|o| f[p.wrapping_add_signed(o)]))
                };
            }
        }
        class
    }

    /// A tile's surface: its core's levels and sea, the halo's and the
    /// halo's classes from the rings.
    pub fn new(
        layout: &Layout,
        pad: Pad,
        (f, sea): (&[f32], &[bool]),
        rings: (&Rings<f32>, &Rings<bool>, &Rings<u8>),
    ) -> Surface {
        let f = pad.padded(layout, f, rings.0, f32::INFINITY);
        let sea = pad.padded(layout, sea, rings.1, false);
        let core = Surface::classify_core(&pad, layout, &f, &sea);
        let class = pad.padded(layout, &core, rings.2, 0);
        Surface { pad, f, sea, class }
    }

    fn flat(&self, p: usize) -> bool {
        self.class[p] & FLAT != 0
    }

    /// Steps from `seeds` (padded index, distance) into the core's flats:
    /// a flat cell is one step from a flat neighbour, or from a non-flat
    /// one of its level (a low edge). 0 where none reaches (padded).
    fn spread(&self, mut seeds: Vec<(u32, usize)>) -> Vec<u32> {
        let mut dist = vec![0u32; self.pad.cells()];
        // Breadth-first by rings of equal distance, the seeds joining at
        // their own distance.
        seeds.sort_unstable();
        let offsets = self.pad.offsets();
        let (mut ring, mut next) = (Vec::new(), Vec::new());
        let mut s = 0;
        let mut d = seeds.first().map_or(0, |x| x.0);
        while s < seeds.len() || !ring.is_empty() {
            if ring.is_empty() {
                d = d.max(seeds[s].0);
            }
            while s < seeds.len() && seeds[s].0 == d {
                let p = seeds[s].1;
                if dist[p] == 0 || d < dist[p] {
                    dist[p] = d;
                    ring.push(p);
                }
                s += 1;
            }
            for &p in &ring {
                for o in offsets {
                    let k = p.wrapping_add_signed(o);
                    if self.pad.to_core(k).is_none()
                        || !self.flat(k)
                        || (!self.flat(p) && self.f[k] != self.f[p])
                    {
                        continue;
                    }
                    if dist[k] == 0 || d + 1 < dist[k] {
                        dist[k] = d + 1;
                        next.push(k);
                    }
                }
            }
            std::mem::swap(&mut ring, &mut next);
            next.clear();
            d += 1;
        }
        dist
    }

    /// The two sweeps (padded): towards lower terrain and away from higher,
    /// seeded by the core's sources and the halo's published distances.
    pub fn sweeps(
        &self,
        layout: &Layout,
        tl: &Rings<u32>,
        hi: &Rings<u32>,
    ) -> (Vec<u32>, Vec<u32>) {
        let pad = &self.pad;
        let offsets = pad.offsets();
        let (mut low, mut high) = (Vec::new(), Vec::new());
        for y in 0..pad.core.h {
            for x in 0..pad.core.w {
                let p = pad.at(x, y);
                if self.class[p] & DRAINS != 0
                    && offsets.iter().any(|&o| {
                        let k = p.wrapping_add_signed(o);
                        self.flat(k) && self.f[k] == self.f[p]
                    })
                {
                    low.push((1, p));
                }
                if self.flat(p) && self.class[p] & HIGHER != 0 {
                    high.push((1, p));
                }
            }
        }
        for (p, gx, gy) in pad.halo(layout) {
            let node = tl.node_at(layout, gx, gy);
            if tl.values[node] > 0 {
                low.push((tl.values[node], p));
            }
            if hi.values[node] > 0 {
                high.push((hi.values[node], p));
            }
        }
        (self.spread(low), self.spread(high))
    }

    /// The core's flats as components.
    pub fn flats(&self) -> Components {
        Components::label(&self.pad, |p| self.flat(p), |_, _| true)
    }
}

/// The drainage gradient of a flat-resolution cell: twice its step from
/// lower terrain, plus, on a flat reached from higher ground, its flat's
/// largest such step minus its own.
pub fn gradient(tl: u32, flat: bool, hi: u32, top: u32) -> u32 {
    2 * tl + if flat && hi > 0 { top - hi } else { 0 }
}

/// The largest away-from-higher step of each of a tile's flats.
pub fn tops(flats: &Components, hi: &[u32], pad: &Pad) -> Vec<u32> {
    let mut top = vec![0u32; flats.count];
    for y in 0..pad.core.h {
        for x in 0..pad.core.w {
            let c = flats.id[y * pad.core.w + x];
            if c != NONE {
                top[c as usize] = top[c as usize].max(hi[pad.at(x, y)]);
            }
        }
    }
    top
}
