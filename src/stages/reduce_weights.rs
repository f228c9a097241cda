//! Stage `reduce_weights` (paper §5.3): the coherence pyramid W^i. A pixel
//! is frozen (0) if any of its 2×2 children is, so freezing dominates;
//! otherwise it takes the most frequent child weight, ties going to the
//! larger weight (freedom to change wins a tie, so an edited region is not
//! shrunk by the coarser levels). Weights are quarters (0, 1 = 0.25, 4 = 1).

use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

/// W^{i} (`w × h`) from W^{i−1} (`cw × ch`); children past the edge are absent.
///
/// An edit reduces every level's weights (a level-sized pass each), and
/// nearly every 2×2 block is uniform — the whole raster is one weight but
/// for the edited stroke — so a uniform block takes its weight without
/// counting (at 1024², the reduction was ~8 % of an edit's CPU time).
pub fn reduce_weights(child: &[u8], cw: usize, ch: usize, w: usize, h: usize) -> Vec<u8> {
    let mut out = vec![0u8; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let (top, bottom) = (2 * y, 2 * y + 1);
        // Pixels whose four children all exist.
        let full = match bottom < ch {
            true => (cw / 2).min(w),
            false => 0,
        };
        if full > 0 {
            let (r0, r1) = (
                &child[top * cw..][..2 * full],
                &child[bottom * cw..][..2 * full],
            );
            let blocks = r0.chunks_exact(2).zip(r1.chunks_exact(2));
            for (o, (a, b)) in row[..full].iter_mut().zip(blocks) {
                *o = match a[0] == a[1] && a[0] == b[0] && a[0] == b[1] {
                    true => a[0].min(4),
                    false => majority([a[0], a[1], b[0], b[1]].into_iter()),
                };
            }
        }
        for (x, o) in row.iter_mut().enumerate().skip(full) {
            let children = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .into_iter()
                .filter_map(|(dx, dy)| {
                    let (cx, cy) = (2 * x + dx, 2 * y + dy);
                    (cx < cw && cy < ch).then(|| child[cy * cw + cx])
                });
            *o = majority(children);
        }
    });
    out
}

/// One parent's weight from its children's (module docs): 0 if any is
/// frozen, else the most frequent (clamped to 4), ties to the larger.
#[inline]
fn majority(children: impl Iterator<Item = u8>) -> u8 {
    let mut counts = [0u8; 5];
    for v in children {
        if v == 0 {
            return 0;
        }
        counts[v.min(4) as usize] += 1;
    }
    // `max_by_key` keeps the last of equal maxima: the larger weight.
    (1..5u8).max_by_key(|&v| counts[v as usize]).unwrap_or(4)
}

/// `ReduceWeightsParams` of `kernels/reduce_weights.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct ReduceWeightsUniform {
    pub width: u32,
    pub height: u32,
    pub child_width: u32,
    pub child_height: u32,
}

impl ReduceWeightsUniform {
    /// The parameters of reducing a `child` raster (width, height) to
    /// `width × height`.
    pub fn new(width: usize, height: usize, child: (usize, usize)) -> Self {
        ReduceWeightsUniform {
            width: width as u32,
            height: height as u32,
            child_width: child.0 as u32,
            child_height: child.1 as u32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_dominates_then_majority_then_larger() {
        #[rustfmt::skip]
        let w0 = [
            1, 1, 4, 4, 1, 4, 4,
            1, 4, 4, 0, 4, 1, 1,
        ];
        assert_eq!(reduce_weights(&w0, 7, 2, 4, 1), vec![1, 0, 4, 4]);
    }

    /// The rule by its definition, pixel by pixel.
    fn reference(child: &[u8], cw: usize, ch: usize, w: usize, h: usize) -> Vec<u8> {
        let mut out = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut counts = [0u8; 5];
                let mut frozen = false;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (cx, cy) = (2 * x + dx, 2 * y + dy);
                    if cx < cw && cy < ch {
                        let v = child[cy * cw + cx].min(4);
                        frozen |= v == 0;
                        counts[v as usize] += 1;
                    }
                }
                out[y * w + x] = match frozen {
                    true => 0,
                    false => (1..5u8).max_by_key(|&v| counts[v as usize]).unwrap_or(4),
                };
            }
        }
        out
    }

    use proptest::prelude::*;

    proptest! {
        /// Uniform blocks (the fast path), mixed ones, odd sizes and
        /// weights above 4 all reduce as the definition says.
        #[test]
        fn reduces_like_the_definition(
            (cw, ch, child) in (1usize..19, 1usize..19).prop_flat_map(|(cw, ch)| {
                let cells = proptest::collection::vec(
                    prop_oneof![4 => Just(4u8), 1 => 0u8..7],
                    cw * ch,
                );
                (Just(cw), Just(ch), cells)
            })
        ) {
            let (w, h) = (cw.div_ceil(2), ch.div_ceil(2));
            prop_assert_eq!(
                reduce_weights(&child, cw, ch, w, h),
                reference(&child, cw, ch, w, h)
            );
        }
    }
}
