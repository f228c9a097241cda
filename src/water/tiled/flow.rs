//! Flow accumulation and Strahler order across tiles (Barnes 2016's
//! parallel flow accumulation, by passing): a tile accumulates its own
//! cells plus what its halo's cells send into it — their published
//! accumulation and, where they are channels, their order — and publishes
//! its ring's. Tiles whose halo changed run again until nothing changes
//! (`super::settle`). The flow network is acyclic, so the values at a cell
//! are right once everything upstream of it is, and the fixed point is the
//! whole world's accumulation and orders.

use super::super::d8::{CLOCKWISE, OUTLET, accumulate_into};
use super::super::rivers::{join, strahler};
use super::ring::{Layout, Pad, Rings};

/// A cell's D8 direction code: the [`CLOCKWISE`] index of its receiver, or
/// this for none.
pub const NO_RECEIVER: u8 = 8;
/// Bit set in a direction code on sea cells.
pub const SEA_BIT: u8 = 0x10;

/// One tile's accumulation (in cells) and Strahler order (0 off channels).
pub struct Flow {
    pub acc: Vec<u64>,
    pub order: Vec<u8>,
}

/// The world cell a direction code points to, if any.
fn target(x: usize, y: usize, code: u8) -> Option<(isize, isize)> {
    let d = (code & !SEA_BIT) as usize;
    (d != NO_RECEIVER as usize).then(|| {
        let (dx, dy, _) = CLOCKWISE[d];
        (x as isize + dx, y as isize + dy)
    })
}

/// Routes a tile: `dirs` its direction codes, the rings the halo's codes,
/// accumulations and orders; channels drain at least `threshold` cells.
pub fn route(
    layout: &Layout,
    pad: &Pad,
    dirs: &[u8],
    (ring_dir, ring_acc, ring_order): (&Rings<u8>, &Rings<u64>, &Rings<u8>),
    threshold: u64,
) -> Flow {
    let c = pad.core;
    let (w, h) = (c.w, c.h);
    let n = w * h;
    let inside = |(x, y): (isize, isize)| {
        let (lx, ly) = (x - c.x0 as isize, y - c.y0 as isize);
        ((0..w as isize).contains(&lx) && (0..h as isize).contains(&ly))
            .then(|| ly as usize * w + lx as usize)
    };
    let receivers: Vec<u32> = (0..n)
        .map(|i| {
            target(c.x0 + i % w, c.y0 + i / w, dirs[i])
                .and_then(inside)
                .map_or(OUTLET, |k| k as u32)
        })
        .collect();
    let mut acc = vec![1u64; n];
    let (mut top, mut ties) = (vec![0u8; n], vec![0u8; n]);
    for (_, gx, gy) in pad.halo(layout) {
        let node = ring_dir.node_at(layout, gx, gy);
        let code = ring_dir.values[node];
        if let Some(k) = target(gx, gy, code).and_then(inside) {
            let a = ring_acc.values[node];
            acc[k] += a;
            if a >= threshold && code & SEA_BIT == 0 {
                join(&mut top[k], &mut ties[k], ring_order.values[node]);
            }
        }
    }
    accumulate_into(&receivers, &mut acc);
    let channel = |i: usize| acc[i] >= threshold && dirs[i] & SEA_BIT == 0;
    let cells: Vec<usize> = (0..n).filter(|&i| channel(i)).collect();
    let downstream = |i: usize| {
        let r = receivers[i];
        (r != OUTLET && channel(r as usize)).then_some(r as usize)
    };
    let order = strahler(&cells, downstream, top, ties);
    Flow { acc, order }
}
