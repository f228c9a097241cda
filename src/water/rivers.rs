//! Rivers: the channel network is every cell draining at least a
//! threshold area (and not sea); rivers are its cells on land — a lake is
//! the water body there, not a river through it. Each channel cell gets its
//! Strahler order (1 at a source; where two or more tributaries of the
//! highest order meet, one more), computed across lakes too, so a river
//! leaving a lake keeps the order of what flowed in.
//!
//! As lines, the rivers are cut into segments between confluences: a
//! segment starts at a source, at a confluence or where a river leaves a
//! lake, follows D8, and ends at the next confluence (its first cell is the
//! next segment's first), at a lake or the sea (whose first cell it
//! includes, so the line touches the water), or at a border outlet. Every
//! river therefore reaches a lake, the sea or the border, by construction
//! of the filled surface (every cell drains); `tests/water/network.rs` checks it.

use super::d8::OUTLET;
use super::lakes::{LAKE, LAND, SEA};
use serde::Serialize;

/// How a river segment ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum End {
    /// At a confluence: its last cell starts another segment.
    Confluence,
    /// In a lake (its last cell is the lake's).
    Lake,
    /// In the sea (its last cell is the sea's).
    Sea,
    /// At a border cell where the flow leaves the grid.
    Border,
}

/// One river segment.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Cell indices (row-major), upstream first.
    pub cells: Vec<u32>,
    /// Strahler order.
    pub order: u8,
    /// Upstream area of its last river cell, in cells.
    pub upstream_cells: u32,
    pub end: End,
}

impl Segment {
    /// Length in cells along D8 steps (diagonals √2).
    pub fn length_cells(&self, width: usize) -> f64 {
        self.cells
            .windows(2)
            .map(|p| {
                let (a, b) = (p[0] as usize, p[1] as usize);
                if a % width != b % width && a / width != b / width {
                    std::f64::consts::SQRT_2
                } else {
                    1.0
                }
            })
            .sum()
    }
}

/// The river network.
#[derive(Debug, Clone)]
pub struct Rivers {
    /// Strahler order of every river cell, 0 elsewhere.
    pub order: Vec<u8>,
    pub segments: Vec<Segment>,
}

/// Counts a donor of Strahler order `o` into a cell's highest donor order
/// `top` and how many donors have it, `ties`.
pub(super) fn join(top: &mut u8, ties: &mut u8, o: u8) {
    if o > *top {
        (*top, *ties) = (o, 1);
    } else if o == *top {
        *ties = ties.saturating_add(1);
    }
}

/// Strahler order of the channel `cells` (0 elsewhere), in topological
/// order: a cell is done once every channel donor is. `top` and `ties`
/// ([`join`]) start with what flows in from elsewhere (zero: nothing).
pub(super) fn strahler(
    cells: &[usize],
    downstream: impl Fn(usize) -> Option<usize>,
    mut top: Vec<u8>,
    mut ties: Vec<u8>,
) -> Vec<u8> {
    let n = top.len();
    let mut pending = vec![0u8; n];
    for &c in cells {
        if let Some(r) = downstream(c) {
            pending[r] += 1;
        }
    }
    let mut order = vec![0u8; n];
    for &start in cells {
        if pending[start] != 0 {
            continue;
        }
        let mut c = start;
        loop {
            order[c] = match (top[c], ties[c]) {
                (0, _) => 1,
                (t, k) if k >= 2 => t.saturating_add(1),
                (t, _) => t,
            };
            let Some(r) = downstream(c) else { break };
            join(&mut top[r], &mut ties[r], order[c]);
            pending[r] -= 1;
            if pending[r] != 0 {
                break;
            }
            pending[r] = u8::MAX;
            c = r;
        }
    }
    order
}

/// Traces the rivers: channel cells drain at least `threshold` cells.
pub fn trace(receivers: &[u32], acc: &[u32], class: &[u8], threshold: u32) -> Rivers {
    let n = receivers.len();
    let channel = |i: usize| acc[i] >= threshold && class[i] != SEA;
    let downstream = |i: usize| {
        let r = receivers[i];
        (r != OUTLET && channel(r as usize)).then_some(r as usize)
    };
    let cells: Vec<usize> = (0..n).filter(|&i| channel(i)).collect();
    let mut order = strahler(&cells, downstream, vec![0; n], vec![0; n]);
    // Rivers: channel cells on land; their river donors decide the heads.
    let river = |i: usize| channel(i) && class[i] == LAND;
    let mut donors = vec![0u8; n];
    for &c in cells.iter().filter(|&&c| river(c)) {
        if let Some(r) = downstream(c).filter(|&r| river(r)) {
            donors[r] += 1;
        }
    }
    let mut segments = Vec::new();
    for &head in cells.iter().filter(|&&c| river(c) && donors[c] != 1) {
        let mut path = vec![head as u32];
        let mut c = head;
        let end = loop {
            let r = receivers[c];
            if r == OUTLET {
                break End::Border;
            }
            let r = r as usize;
            match class[r] {
                LAKE => {
                    path.push(r as u32);
                    break End::Lake;
                }
                SEA => {
                    path.push(r as u32);
                    break End::Sea;
                }
                _ => {}
            }
            path.push(r as u32);
            if donors[r] != 1 {
                // A confluence on a border outlet starts no segment of its
                // own (it would be one cell): the rivers end there.
                if receivers[r] == OUTLET {
                    c = r;
                    break End::Border;
                }
                break End::Confluence;
            }
            c = r;
        };
        if path.len() < 2 {
            // A confluence or source that is itself a border outlet: the
            // segments into it end there; no line of its own.
            continue;
        }
        segments.push(Segment {
            cells: path,
            order: order[head],
            upstream_cells: acc[c],
            end,
        });
    }
    for (o, &cl) in order.iter_mut().zip(class) {
        if cl != LAND {
            *o = 0;
        }
    }
    Rivers { order, segments }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn strahler_rises_where_equal_orders_meet() {
        // Cells 0..=6 in a row of 7 (plus nothing else): 0 → 2, 1 → 2,
        // 2 → 4, 3 → 4, 4 → 5, 5 → 6, 6 the outlet. Threshold 1: all
        // channel. 2 is order 2 (two order-1 sources), 4 stays 2 (an
        // order-2 and an order-1).
        let r = [2, 2, 4, 4, 5, 6, OUTLET];
        let acc = super::super::d8::accumulate(&r);
        let class = [LAND; 7];
        let rv = trace(&r, &acc, &class, 1);
        assert_eq!(rv.order, vec![1, 1, 2, 1, 2, 2, 2]);
        // Segments: 0→2, 1→2, 3→4, 2→4, 4→5→6 (border).
        let ends: Vec<(Vec<u32>, End)> = rv
            .segments
            .iter()
            .map(|s| (s.cells.clone(), s.end))
            .collect();
        assert_eq!(
            ends,
            vec![
                (vec![0, 2], End::Confluence),
                (vec![1, 2], End::Confluence),
                (vec![2, 4], End::Confluence),
                (vec![3, 4], End::Confluence),
                (vec![4, 5, 6], End::Border),
            ]
        );
        assert_eq!(rv.segments[4].upstream_cells, 7);
    }
}
