//! Stage `reduce_types` (paper §5.2): the target-set pyramid R^i. Each
//! pixel's set is the union of its 2×2 children's sets at level i − 1,
//! leaving out children whose set is full (unconstrained) — otherwise a
//! narrow painted band would be washed out by its unconstrained
//! surroundings at coarse levels. Four full children give a full set.
//!
//! Sets are u32 bit masks of type ids; [`ALL_TYPES`] and `full` (every
//! type of the database) both count as full.

use crate::stages::common::ALL_TYPES;
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

/// R^{i} (`w × h`) from R^{i−1} (`cw × ch`); children past the child
/// level's edge (odd sizes) are absent.
pub fn reduce_types(
    child: &[u32],
    cw: usize,
    ch: usize,
    w: usize,
    h: usize,
    full: u32,
) -> Vec<u32> {
    let mut out = vec![ALL_TYPES; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let mut union = 0u32;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (cx, cy) = (2 * x + dx, 2 * y + dy);
                if cx < cw && cy < ch {
                    let r = child[cy * cw + cx];
                    if r != ALL_TYPES && r & full != full {
                        union |= r;
                    }
                }
            }
            if union != 0 {
                *o = union;
            }
        }
    });
    out
}

/// `ReduceTypesParams` of `kernels/reduce_types.wgsl` (padded to 32 bytes,
/// a whole number of 16-byte uniform rows).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct ReduceTypesUniform {
    pub width: u32,
    pub height: u32,
    pub child_width: u32,
    pub child_height: u32,
    /// Every type of the database (`reduce_types`' `full`).
    pub full: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

impl ReduceTypesUniform {
    /// The parameters of reducing a `child` raster (width, height) to
    /// `width × height`.
    pub fn new(width: usize, height: usize, child: (usize, usize), full: u32) -> Self {
        ReduceTypesUniform {
            width: width as u32,
            height: height as u32,
            child_width: child.0 as u32,
            child_height: child.1 as u32,
            full,
            ..Default::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn union_ignores_full_sets() {
        let full = 0b111;
        #[rustfmt::skip]
        let r0 = [
            ALL_TYPES, 0b001, full, full, 0b100,
            ALL_TYPES, 0b010, full, full, ALL_TYPES,
        ];
        let r1 = reduce_types(&r0, 5, 2, 3, 1, full);
        assert_eq!(r1, vec![0b011, ALL_TYPES, 0b100]);
    }
}
