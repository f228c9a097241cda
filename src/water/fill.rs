//! Depression filling by priority-flood (Barnes, Lehman & Mulla 2014,
//! "Priority-Flood", Algorithm 2 with the plain queue for pit cells): the
//! flood starts from every border cell (and every sea cell), always grows
//! from the lowest cell of its edge, and raises each cell it reaches below
//! that level to it. Every cell ends at the lowest level at which water
//! could leave it: the spill level of its depression, exactly (a copy of a
//! height, no arithmetic), so a filled lake is level.
//!
//! The fill is flat, not ε-raised (Barnes' Priority-Flood+ε): in f32 an ε
//! step per cell climbs by an ulp per cell across a lake (~6 cm over 1 000
//! cells at 1 000 m), which would move the lake's surface off its spill
//! level. Flats are drained instead by [`super::flats`].
//!
//! The priority queue is a radix heap on the heights' order-preserving
//! bits: the flood pops levels in non-decreasing order (a monotone queue),
//! where a radix heap costs O(1) per push and an amortised bucket scan per
//! pop; it kept a 4096² fill well under the binary heap's time (see the
//! README's `water` figures). The result does not depend on the order in
//! which equal levels are popped.

use super::d8::CLOCKWISE;
use crate::procedural::grid::neighbour;
use std::collections::VecDeque;

/// Order-preserving key of a finite height: `a < b ⇔ key(a) < key(b)`.
fn key(z: f32) -> u32 {
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
struct RadixHeap {
    last: u32,
    buckets: [Vec<(u32, u32)>; 33],
}

impl RadixHeap {
    fn new() -> Self {
        RadixHeap {
            last: 0,
            buckets: std::array::from_fn(|_| Vec::new()),
        }
    }

    fn bucket(k: u32, last: u32) -> usize {
        (32 - (k ^ last).leading_zeros()) as usize
    }

    fn push(&mut self, k: u32, cell: u32) {
        debug_assert!(k >= self.last, "radix heap keys must not decrease");
        self.buckets[Self::bucket(k, self.last)].push((k, cell));
    }

    fn pop(&mut self) -> Option<(u32, u32)> {
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

/// The filled surface of `heights` (`width × height`, no NaN): every cell
/// raised to its spill level. `sea` cells (when given) are outlets like
/// the border; their level is `sea_level`, the water surface.
pub fn priority_flood(
    heights: &[f32],
    width: usize,
    height: usize,
    sea: Option<(&[bool], f32)>,
) -> Vec<f32> {
    let (w, h) = (width, height);
    let n = w * h;
    let mut z = heights.to_vec();
    let mut closed = vec![false; n];
    let mut open = RadixHeap::new();
    let mut seed = |i: usize, z: &mut [f32], closed: &mut [bool]| {
        if !closed[i] {
            closed[i] = true;
            open.push(key(z[i]), i as u32);
        }
    };
    if let Some((mask, level)) = sea {
        for (i, _) in mask.iter().enumerate().filter(|p| *p.1) {
            z[i] = level;
            seed(i, &mut z, &mut closed);
        }
    }
    for x in 0..w {
        seed(x, &mut z, &mut closed);
        seed((h - 1) * w + x, &mut z, &mut closed);
    }
    for y in 0..h {
        seed(y * w, &mut z, &mut closed);
        seed(y * w + w - 1, &mut z, &mut closed);
    }
    // Interior cells reach their neighbours by fixed offsets; only seeds
    // (border cells, and sea cells on it) need bounds checks.
    let offsets: Vec<isize> = CLOCKWISE
        .iter()
        .map(|&(dx, dy, _)| dy * w as isize + dx)
        .collect();
    let mut pit: VecDeque<u32> = VecDeque::new();
    loop {
        let c = match pit.pop_front() {
            Some(c) => c as usize,
            None => match open.pop() {
                Some((_, c)) => c as usize,
                None => break,
            },
        };
        let zc = z[c];
        let (x, y) = (c % w, c / w);
        let interior = x > 0 && y > 0 && x < w - 1 && y < h - 1;
        for (k, &(dx, dy, _)) in CLOCKWISE.iter().enumerate() {
            let nb = if interior {
                c.wrapping_add_signed(offsets[k])
            } else {
                match neighbour(x, y, dx, dy, w, h) {
                    Some(nb) => nb,
                    None => continue,
                }
            };
            if closed[nb] {
                continue;
            }
            closed[nb] = true;
            if z[nb] <= zc {
                z[nb] = zc;
                pit.push_back(nb as u32);
            } else {
                open.push(key(z[nb]), nb as u32);
            }
        }
    }
    z
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
