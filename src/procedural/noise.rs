//! Gradient (Perlin) lattice noise from a stateless integer hash (seed 002 §5.2).
//!
//! Each lattice point's gradient is chosen by hashing (seed, x, y): there is
//! no permutation table and no RNG state, so any sample can be evaluated on
//! its own, in any order, on any thread, and a GPU kernel can reproduce the
//! choice with the same 32-bit integer operations (DESIGN §6 rule 2).
//! Interpolation uses Perlin's quintic fade 6t⁵ − 15t⁴ + 10t³ (C2-continuous,
//! a polynomial, hence bit-reproducible).

/// PCG-RXS-M-XS 32-bit hash (Jarzynski & Olano 2020, "Hash Functions for GPU
/// Rendering"): good avalanche for lattice coordinates, integer ops only.
#[inline]
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// Hash of a lattice point for a seed (nested PCG, one round per input).
#[inline]
pub fn hash2(seed: u32, x: i32, y: i32) -> u32 {
    lattice_hash(pcg(seed), x, y)
}

/// [`hash2`] with the seed's own round already applied (hoisted out of loops).
#[inline]
fn lattice_hash(seed_hash: u32, x: i32, y: i32) -> u32 {
    pcg((x as u32) ^ pcg((y as u32) ^ seed_hash))
}

/// A hash mapped to [0, 1) with 24 bits of resolution.
#[inline]
pub fn unit(h: u32) -> f64 {
    (h >> 8) as f64 * (1.0 / 16_777_216.0)
}

/// Sixteen unit gradients, 22.5° apart. More directions than Perlin's 8 or 12
/// keep the lattice axes from showing through in long ridges.
const H: f64 = std::f64::consts::FRAC_1_SQRT_2;
const GRADIENTS: [(f64, f64); 16] = [
    (1.0, 0.0),
    (0.923_879_532_511_286_7, 0.382_683_432_365_089_8),
    (H, H),
    (0.382_683_432_365_089_8, 0.923_879_532_511_286_7),
    (0.0, 1.0),
    (-0.382_683_432_365_089_8, 0.923_879_532_511_286_7),
    (-H, H),
    (-0.923_879_532_511_286_7, 0.382_683_432_365_089_8),
    (-1.0, 0.0),
    (-0.923_879_532_511_286_7, -0.382_683_432_365_089_8),
    (-H, -H),
    (-0.382_683_432_365_089_8, -0.923_879_532_511_286_7),
    (0.0, -1.0),
    (0.382_683_432_365_089_8, -0.923_879_532_511_286_7),
    (H, -H),
    (0.923_879_532_511_286_7, -0.382_683_432_365_089_8),
];

/// With unit gradients, 2-D gradient noise lies in ±√½ (attained at a cell
/// centre when all four gradients point at it); this scale maps it onto ±1.
const SCALE: f64 = std::f64::consts::SQRT_2;

#[inline]
fn fade(t: f64) -> f64 {
    t * t * t * (t * (t * 6.0 - 15.0) + 10.0)
}

#[inline]
fn corner(seed_hash: u32, ix: i32, iy: i32, dx: f64, dy: f64) -> f64 {
    let (gx, gy) = GRADIENTS[(lattice_hash(seed_hash, ix, iy) >> 28) as usize];
    gx * dx + gy * dy
}

/// Gradient noise at (x, y) in lattice units: in [−1, 1], zero at every
/// lattice point, band-limited around frequency ½. Lattice coordinates wrap
/// every 2³² cells, far beyond any heightfield.
pub fn gradient_noise(seed: u32, x: f64, y: f64) -> f64 {
    let (xf, yf) = (x.floor(), y.floor());
    let (ix, iy) = (xf as i64 as i32, yf as i64 as i32);
    let (fx, fy) = (x - xf, y - yf);
    let seed = pcg(seed);
    let n00 = corner(seed, ix, iy, fx, fy);
    let n10 = corner(seed, ix.wrapping_add(1), iy, fx - 1.0, fy);
    let n01 = corner(seed, ix, iy.wrapping_add(1), fx, fy - 1.0);
    let n11 = corner(
        seed,
        ix.wrapping_add(1),
        iy.wrapping_add(1),
        fx - 1.0,
        fy - 1.0,
    );
    let (u, v) = (fade(fx), fade(fy));
    let bottom = n00 + (n10 - n00) * u;
    let top = n01 + (n11 - n01) * u;
    (bottom + (top - bottom) * v) * SCALE
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradients_are_unit_vectors() {
        for (x, y) in GRADIENTS {
            assert!((x * x + y * y - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn hash_spreads_gradient_choices_evenly() {
        let mut counts = [0u32; 16];
        for y in 0..128 {
            for x in 0..128 {
                counts[(hash2(7, x, y) >> 28) as usize] += 1;
            }
        }
        // 16384 draws over 16 bins: 1024 expected, σ ≈ 31.
        for c in counts {
            assert!((880..1170).contains(&c), "{counts:?}");
        }
    }
}
