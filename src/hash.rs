//! Stateless integer hashing: every random choice in terrasynth (jitter,
//! seeding, PatchMatch samples) is a pure function of its coordinates, so
//! results never depend on iteration order or thread count, and a WGSL kernel
//! (`kernels/common.wgsl`) reproduces them bit for bit (DESIGN §6 rule 2).
//!
//! The mixer is the PCG-RXS-M-XS output permutation recommended for GPU use
//! by Jarzynski & Olano, "Hash Functions for GPU Rendering" (JCGT 2020): only
//! u32 wrapping multiply/add, xor and shifts by less than 32.

/// One PCG round: a bijective 32-bit mix.
#[inline(always)]
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Hash of four words, chained so that every input bit affects the result.
#[inline(always)]
pub fn hash4(a: u32, b: u32, c: u32, d: u32) -> u32 {
    pcg(a ^ pcg(b ^ pcg(c ^ pcg(d))))
}

/// Uniform integer in `0..n` (n > 0) from a hash, by multiply-shift (no
/// modulo bias worth the name at these sizes; no 64-bit arithmetic needed on
/// the GPU side: the high word of a 32×32 product is computed there in halves).
#[inline(always)]
pub fn below(h: u32, n: u32) -> u32 {
    ((h as u64 * n as u64) >> 32) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values_pin_the_function() {
        // Pinned so that a change to the mixer (which would silently change
        // every synthesis and break the GPU mirror) fails loudly.
        assert_eq!(pcg(0), 129_708_002);
        assert_eq!(pcg(1), 2_831_084_092);
        assert_eq!(hash4(1, 2, 3, 4), hash4(1, 2, 3, 4));
        assert_ne!(hash4(1, 2, 3, 4), hash4(2, 1, 3, 4));
    }

    #[test]
    fn below_is_in_range_and_roughly_uniform() {
        let n = 10u32;
        let mut counts = [0u32; 10];
        for i in 0..100_000u32 {
            let v = below(pcg(i), n);
            assert!(v < n);
            counts[v as usize] += 1;
        }
        for c in counts {
            assert!((9_000..11_000).contains(&c), "{counts:?}");
        }
    }
}
