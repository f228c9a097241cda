//! The type-set and coherence-weight pyramids of a window: `reduce_types`
//! and `reduce_weights` over *footprints*, rectangles aligned so that each
//! level's is exactly the children of the one above (clipped to the
//! world), from the top corrected level's cone region down. A pixel of
//! level i summarizes the 2^i × 2^i output pixels under it, so its value
//! over a footprint is the whole level's; each level's guide is then the
//! cone region cropped out of its footprint.

use crate::level::state::level_size;
use crate::stages::common::ALL_TYPES;
use crate::stages::reduce_types::reduce_types;
use crate::stages::reduce_weights::reduce_weights;
use crate::synth::cone::{Cone, Rect};
use crate::synth::control::UNCONSTRAINED;

/// Footprints of levels `0..=last` (index = level): the cone's region at
/// `last`, then the children of each footprint, clipped to the world.
pub(super) fn footprints(cone: &Cone, last: usize) -> Vec<Rect> {
    let (w, h) = cone.world();
    let mut fp = vec![cone.region(last)];
    for i in (0..last).rev() {
        let above = fp[0];
        let (lw, lh) = level_size(w, h, i);
        fp.insert(
            0,
            Rect {
                x0: 2 * above.x0,
                y0: 2 * above.y0,
                x1: (2 * above.x1).min(lw),
                y1: (2 * above.y1).min(lh),
            },
        );
    }
    fp
}

/// R^i over the footprints from painted level-0 type ids (over
/// `fp[0] ∩ world`, [`UNCONSTRAINED`] = none): as `Session`'s guides, a
/// painted pixel allows its type, any other (the padding of a world
/// narrower than its 2-pixel level 0 included) every type.
pub(super) fn type_sets(
    painted: &[u8],
    world: (usize, usize),
    fp: &[Rect],
    full: u32,
) -> Vec<Vec<u32>> {
    let f0 = fp[0];
    let inner = Rect {
        x1: f0.x1.min(world.0),
        y1: f0.y1.min(world.1),
        ..f0
    };
    let mut level: Vec<u32> = vec![ALL_TYPES; f0.pixels()];
    for y in inner.y0..inner.y1 {
        for x in inner.x0..inner.x1 {
            let t = painted[(y - inner.y0) * inner.width() + x - inner.x0];
            if t != UNCONSTRAINED {
                level[(y - f0.y0) * f0.width() + x - f0.x0] = 1 << t;
            }
        }
    }
    let mut out = vec![level];
    for i in 1..fp.len() {
        let (c, p) = (fp[i - 1], fp[i]);
        let next = reduce_types(
            &out[i - 1],
            c.width(),
            c.height(),
            p.width(),
            p.height(),
            full,
        );
        out.push(next);
    }
    out
}

/// W^i over the footprints from level-0 weights over `fp[0]`, pixels of
/// `pasted[i]` (over `fp[i]`) frozen at every level above 0.
pub(super) fn weight_sets(w0: Vec<u8>, fp: &[Rect], pasted: &[Vec<bool>]) -> Vec<Vec<u8>> {
    let mut out = vec![w0];
    for i in 1..fp.len() {
        let (c, p) = (fp[i - 1], fp[i]);
        let mut next = reduce_weights(&out[i - 1], c.width(), c.height(), p.width(), p.height());
        for (w, &frozen) in next.iter_mut().zip(&pasted[i]) {
            if frozen {
                *w = crate::stages::correct::W_FROZEN;
            }
        }
        out.push(next);
    }
    out
}
