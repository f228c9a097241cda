//! Stage `reduce_weights` (paper §5.3): the coherence pyramid W^i. A pixel
//! is frozen (0) if any of its 2×2 children is, so freezing dominates;
//! otherwise it takes the most frequent child weight, ties going to the
//! larger weight (freedom to change wins a tie, so an edited region is not
//! shrunk by the coarser levels). Weights are quarters (0, 1 = 0.25, 4 = 1).

use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

/// W^{i} (`w × h`) from W^{i−1} (`cw × ch`); children past the edge are absent.
pub fn reduce_weights(child: &[u8], cw: usize, ch: usize, w: usize, h: usize) -> Vec<u8> {
    let mut out = vec![0u8; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
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
            *o = if frozen {
                0
            } else {
                // `max_by_key` keeps the last of equal maxima: the larger weight.
                (1..5u8).max_by_key(|&v| counts[v as usize]).unwrap_or(4)
            };
        }
    });
    out
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
}
