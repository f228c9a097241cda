//! The altitude guide of the coarse start: where a world stands high and
//! where low at the scale of massifs, drawn anew for every seed.
//!
//! A smooth random field — integer value noise, [`OCTAVES`] octaves from a
//! lattice of 2^[`BASE_BITS`] output pixels, each octave half the
//! amplitude and lattice of the one before — is read through its own
//! distribution as a rank u ∈ [0, 1): the piece at a place takes its
//! source among the exemplars' places whose surroundings stand at quantile
//! u of their altitudes ([`super::pool::Pool`]). The field sets the layout
//! of highs and lows, the exemplars set everything else, and the output's
//! altitudes follow the exemplars' distribution whatever the layout: the
//! rank is local ([`Guide::rank`]), so every region of a few hundred
//! pixels holds the exemplars' whole range of altitudes.
//!
//! Why a field and not the exemplars' own layout: the start laid verbatim
//! exemplar blocks, so every output was the exemplar's own massifs
//! rearranged (issue 46: half of its 64-px windows matched the exemplar at
//! NCC ≥ 0.95, a world 3× the exemplar's side repeated its highest summit 8
//! times). Why not pieces drawn freely: an unguided mosaic of small pieces
//! has no structure above the piece size — highs and lows scattered as
//! blobs and pits, which correction then levels (relief 38–60 % with
//! 16-px blocks on the shared DEMs). Why no fit of each piece to its
//! neighbours (image quilting): choosing the best-fitting of several
//! candidates prefers pieces that fit anything — moderate altitudes,
//! smooth ground — and took a quarter of the relief before correction even
//! began (yosemite, 8 candidates: start relief 54 % of the exemplar's);
//! correction joins unfitted pieces at least as well.
//!
//! Every value is a hash of the seed and an absolute position (DESIGN §6):
//! a window of a world computes the same guide there.

use crate::hash::hash4;

/// Lattice of the coarsest octave, log₂ of output pixels: 256 px, a few
/// massifs across an output the size of the shared DEMs. Measured on the
/// 8 shared DEMs (seeds 11–13): 512 px kept 65–83 % of their relief where
/// 256 px kept 71–88 % (an output holds too few highs and lows of the
/// larger field, and correction levels lone pieces), 128 px left no
/// massifs larger than a few pieces.
pub const BASE_BITS: u32 = 8;

/// Octaves of the field (lattices of 256, 128 and 64 px).
pub const OCTAVES: u32 = 3;

/// The rank of the field at a place is taken among its values at a grid
/// of places around it: `(2·RANK_STEPS + 1)²` places, [`RANK_SPACING`]
/// output pixels apart (±224 px).
///
/// Why a local rank and not the field's global distribution: an output
/// the size of a shared DEM holds only a few lattice cells of the coarsest
/// octave, so the share of it the field put at low ranks was a lottery
/// (riviera, 39 % sea: a seed-11 output got 10 % at its start and a lake
/// after correction, median slope 211 % of the exemplar's; with local ranks
/// every ~450-px region holds the whole range of altitudes, in the
/// exemplars' proportions, and slope came to 133 %, relief 71 → 84 %).
const RANK_STEPS: i32 = 7;
const RANK_SPACING: i32 = 32;

/// Salt of the field's hashes.
const SALT: u32 = 0x6A1D_0000;

/// Local ranks sampled (at hashed places of seed 0) for their distribution.
const CDF_SAMPLES: u32 = 2048;

/// The distribution of the field's local ranks, to read them as uniform
/// quantiles.
///
/// Why: the field is smooth at the scale of the rank's window, so a place
/// is rarely below (or above) all of the places around it — measured, the
/// lowest and highest deciles of local ranks held half the share of the
/// middle ones, and coasts came out with two thirds of their sea (catalan
/// 14.6 % at the start, exemplar 21.7 %).
pub struct Guide {
    /// [`CDF_SAMPLES`] local ranks, sorted.
    sorted: Vec<u32>,
}

impl Guide {
    pub fn new() -> Guide {
        let mut sorted: Vec<u32> = (0..CDF_SAMPLES)
            .map(|k| {
                let x = (hash4(0, SALT | 1, k, 0) >> 8) as i32;
                let y = (hash4(0, SALT | 2, k, 0) >> 8) as i32;
                local_rank(0, x, y)
            })
            .collect();
        sorted.sort_unstable();
        Guide { sorted }
    }

    /// The quantile u of the field of seed `seed` at output pixel (x, y),
    /// in 1/2^16 (0 ..= 65535): its local rank, read through their
    /// distribution.
    pub fn rank(&self, seed: u32, x: i32, y: i32) -> u32 {
        let r = local_rank(seed, x, y);
        let (lo, hi) = (
            self.sorted.partition_point(|&s| s < r) as u64,
            self.sorted.partition_point(|&s| s <= r) as u64,
        );
        // Ties (equal local ranks) take the middle of their interval.
        (((lo + hi) << 15) / u64::from(CDF_SAMPLES)) as u32
    }
}

impl Default for Guide {
    fn default() -> Guide {
        Guide::new()
    }
}

/// The rank of the field of seed `seed` at output pixel (x, y) among its
/// values around it, in 1/2^16.
fn local_rank(seed: u32, x: i32, y: i32) -> u32 {
    let v = field(seed, x, y);
    let mut below = 0u64;
    for dy in -RANK_STEPS..=RANK_STEPS {
        for dx in -RANK_STEPS..=RANK_STEPS {
            let o = field(seed, x + dx * RANK_SPACING, y + dy * RANK_SPACING);
            below += u64::from(o < v);
        }
    }
    let n = ((2 * RANK_STEPS + 1) * (2 * RANK_STEPS + 1)) as u64;
    // The middle of the rank's interval: (below + ½) / n.
    (((2 * below + 1) << 16) / (2 * n)) as u32
}

/// The field at output pixel (x, y): [`OCTAVES`] octaves of value noise.
fn field(seed: u32, x: i32, y: i32) -> i32 {
    (0..OCTAVES)
        .map(|o| value_noise(seed, SALT | (o + 8), x, y, BASE_BITS - o) >> o)
        .sum()
}

/// Value noise in `[−2^15, 2^15)` at (x, y): hashed values on a lattice of
/// 2^g pixels, interpolated bilinearly in integers.
fn value_noise(seed: u32, salt: u32, x: i32, y: i32, g: u32) -> i32 {
    let (cx, cy, fx, fy) = (x >> g, y >> g, x & ((1 << g) - 1), y & ((1 << g) - 1));
    let v = |dx: i32, dy: i32| {
        let h = hash4(seed, salt, (cx + dx) as u32, (cy + dy) as u32);
        i64::from((h >> 16) as i32 - (1 << 15))
    };
    let (fx, fy, n) = (i64::from(fx), i64::from(fy), 1i64 << g);
    let top = v(0, 0) * (n - fx) + v(1, 0) * fx;
    let bottom = v(0, 1) * (n - fx) + v(1, 1) * fx;
    ((top * (n - fy) + bottom * fy) >> (2 * g)) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_are_uniform_over_a_large_world_and_smooth() {
        let g = Guide::new();
        let mut hist = [0u32; 10];
        let (mut steps, mut n) = (0u64, 0u64);
        for y in (0..8192).step_by(32) {
            for x in (0..8192).step_by(32) {
                let r = g.rank(7, x, y);
                assert!(r < 65536);
                hist[((r * 10) >> 16) as usize] += 1;
                steps += u64::from(r.abs_diff(g.rank(7, x + 32, y)));
                n += 1;
            }
        }
        let mean = n as f64 / 10.0;
        for (k, &c) in hist.iter().enumerate() {
            assert!(
                (c as f64 - mean).abs() < 0.15 * mean,
                "decile {k}: {c} of {n}"
            );
        }
        // Neighbours 32 px apart differ by a tenth of the range (measured
        // 0.11): the field is smooth at the scale of pieces (white noise:
        // a third).
        let mean_step = steps as f64 / n as f64 / 65536.0;
        assert!(mean_step < 0.15, "mean step {mean_step}");
        // Another seed, another field.
        let same = (0..64)
            .filter(|&k| g.rank(7, k * 97, 5) == g.rank(8, k * 97, 5))
            .count();
        assert!(same < 8, "{same}");
    }
}
