//! What several stages share: the Rust side of the stage rules in
//! `kernels/common.wgsl` (and of the constants the kernels repeat), so that
//! no stage imports another's internals. The fixed-point coordinate rules
//! (rounding, floor division) live below the stages, in
//! [`crate::level::fixed`].

use crate::database::appearance::{MODE1_BIAS, unpack_texel};

/// Height (units, before V) the correction attributes to texel (qx, qy):
/// its appearance mode 1, the Gaussian-weighted mean height around it.
#[inline(always)]
pub fn texel_height(texel: u64) -> i32 {
    unpack_texel(texel)[0] as i32 - MODE1_BIAS
}

/// Candidate offsets Δ, in evaluation (and tie-break) order.
pub const DELTAS: [(i32, i32); 9] = [
    (0, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// Target set of an unconstrained pixel.
pub const ALL_TYPES: u32 = u32::MAX;

/// Fractional bits of reconstructed heights.
pub const HEIGHT_FRAC_BITS: u32 = 8;

/// What a pixel gives its neighbours' predictions: the atlas index of its
/// rounded texel t(n), its exemplar's row stride and its offset V(n).
/// S(n) is interior (two texels from every exemplar edge), so the texel one
/// step away is in its exemplar, at `k − dx − dy·stride`.
#[derive(Debug, Clone, Copy)]
pub struct Texel {
    pub k: i32,
    pub stride: i32,
    pub v: i32,
}
