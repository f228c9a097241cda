//! Stage `reconstruct`: heights from E⁰ at S⁰ (bilinear) plus V⁰.
//!
//! The kernel output is an i32 height in database units with 8 fractional
//! bits (bit-exact on CPU and GPU); conversion to metres is a CPU-side
//! `offset + scale · value / 256` (DESIGN §6 rule 5).
//!
//! Bilinear weights have [`FRAC_BITS`] bits; the weighted sum of four u16
//! heights is at most 65535 · 2^16 < 2^32 (a u32), then shifted down by 8
//! (truncating) to keep 8 fractional bits.

use crate::synth::atlas::AtlasLevel;
use crate::synth::fixed::{FRAC_BITS, ONE};
use crate::synth::state::State;
use rayon::prelude::*;

/// Fractional bits of reconstructed heights.
pub const HEIGHT_FRAC_BITS: u32 = 8;

/// Heights of level 0, row-major, in units × 2^8.
pub fn reconstruct(atlas: &AtlasLevel<'_>, heights: &[u16], st: &State) -> Vec<i32> {
    let w = st.width;
    let mut out = vec![0i32; st.width * st.height];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let i = y * w + x;
            let s = st.s(i);
            let (x0, y0) = (s.x >> FRAC_BITS, s.y >> FRAC_BITS);
            let (fx, fy) = ((s.x & (ONE - 1)) as u32, (s.y & (ONE - 1)) as u32);
            let e = |dx: i32, dy: i32| heights[atlas.index(x0 + dx, y0 + dy)] as u32;
            let top = e(0, 0) * (ONE as u32 - fx) + e(1, 0) * fx;
            let bottom = e(0, 1) * (ONE as u32 - fx) + e(1, 1) * fx;
            let v = (top * (ONE as u32 - fy) + bottom * fy) >> (2 * FRAC_BITS - HEIGHT_FRAC_BITS);
            *o = v as i32 + (st.v(i) << HEIGHT_FRAC_BITS);
        }
    });
    out
}
