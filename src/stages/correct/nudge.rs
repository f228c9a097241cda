//! The kernel side of a geometric constraint (paper eq. 8–9): the
//! blended [`Target`] of one pixel and the non-linear height nudge φ_d that
//! `correct` applies towards it, in 32-bit integers, identical in the
//! scalar and SIMD corrections and in WGSL. The CPU side — blending
//! overlapping constraints into targets — is `synth::control::blend`.

use crate::level::fixed::div_floor;

/// Largest tolerance handed to the kernel (keeps φ's products in 32 bits).
/// Past it the cone stops widening: with 5 cm units that is 1.6 km of
/// height, far outside any error φ's cubic would still act on.
pub const MAX_TOL: i32 = 32_767;
/// Largest |h_t − h_c| the kernel works with (keeps 3|x| in an i32).
pub const MAX_ERROR: i32 = 1 << 24;

/// A pixel's blended constraint, in database height units.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Target {
    /// Target height h_t (units; may leave 0..65535).
    pub height: i32,
    /// Tolerance t = s·d (units) in the low 16 bits, with the
    /// [`KEEP_DETAIL`] flag above them; −1 where no constraint reaches.
    pub tol: i32,
}

impl Target {
    /// No constraint here.
    pub const NONE: Target = Target { height: 0, tol: -1 };
}

/// φ_d(x) of eq. 9 with λ = ½, in integer height units (the kernel side;
/// identical in the scalar and SIMD corrections and in WGSL: 32-bit
/// arithmetic only) — except where the tolerance is 0, the pixels a curve
/// or a point's site passes through: there φ = x, the whole error.
///
/// Why: eq. 9 halves the error per pass so that a constraint shapes its
/// surroundings gradually, but a pixel held hard has no surroundings to
/// shape — it is the constraint. Halved, the last level's two passes left
/// a quarter of its error: ridges came out ~1.5 % of relief low and
/// valleys high (issue 14), the cliff's top edge 1.38 % low. In full, the
/// curve profile's mean error on the Pyrenees goes 1.32 → 0.80 % of
/// relief and the cliff's top edge 1.38 → 0.87 %.
///
/// With t the tolerance: `x/2 − sign(x)·t/3` outside ±t (slope λ, offset
/// c = 2λt/3), `x·(x/t)²/6` inside (= −b·x³ with b = −λ/(3t²)). Inside, the
/// ratio r = |x|/t is formed in 15 fractional bits (|x| ≤ t ≤ 2^15, so
/// |x|·2^15 < 2^31) and squared back to 15 bits; the product |x|·r² < 2^30.
/// Both branches round to nearest (ties away from zero, by symmetry).
#[inline(always)]
pub fn phi(x: i32, tol: i32) -> i32 {
    let x = x.clamp(-MAX_ERROR, MAX_ERROR);
    let a = x.unsigned_abs();
    let t = tol as u32;
    let mag = if t == 0 {
        a
    } else if a > t {
        (3 * a - 2 * t + 3) / 6
    } else if a == 0 {
        0
    } else {
        let r = (a << 15) / t;
        let r2 = (r * r) >> 15;
        (a * r2 + 3 * (1 << 15)) / (6 << 15)
    };
    if x < 0 { -(mag as i32) } else { mag as i32 }
}

/// V after nudging a chosen candidate of height `h_c` (units, V included)
/// towards `target`: `v + φ(h_t − h_c)`; unchanged where no constraint.
#[inline(always)]
pub fn nudge(v: i32, h_c: i32, target: Target) -> i32 {
    if target.tol < 0 {
        return v;
    }
    v + phi(target.height.saturating_sub(h_c), target.tolerance())
}

/// Bit of [`Target::tol`] set where every constraint that reaches the
/// pixel lets the winner keep its own detail ([`own_detail`]): curves do;
/// points and sculpt strokes, whose heights are asked exactly, do not. The
/// tolerance itself is the low 16 bits ([`MAX_TOL`] < 2^15).
pub const KEEP_DETAIL: i32 = 1 << 16;

/// Levels below this keep the winner's own detail under a nudge
/// ([`own_detail`]): levels 0 and 1, whose 5×5 texels span the 5–10 px
/// that read as the ground's texture.
pub const DETAIL_LEVELS: u32 = 2;

/// The winner's smooth height is the mean of the 3×3 texels this far
/// apart around it ([`own_detail`]): nine samples of its 5×5
/// neighbourhood, within every exemplar's
/// [`MARGIN`](crate::database::layout::MARGIN) of 2 around an interior
/// texel.
///
/// Why nine and not all 25: the reads are the nudge's whole cost, and
/// the 25-texel mean cost a long curve's edit ~4 % more CPU time where
/// nine cost ~1 % (an 8-edit session of long curves at 1024²), for the
/// same detail (1024², seeds 11–15: 83 / 82 % with 25, 84 / 83 % with 9).
pub const DETAIL_STEP: i32 = 2;

impl Target {
    /// The tolerance t, without the [`KEEP_DETAIL`] flag (−1: none).
    #[inline(always)]
    pub fn tolerance(self) -> i32 {
        if self.tol < 0 { self.tol } else { self.tol & 0xFFFF }
    }
}

/// What a nudge leaves of the winner's own texture at a pixel with
/// `target` at level `level`: the texel's height `h` minus the floor of
/// the mean of the nine texels [`DETAIL_STEP`] apart around it (`at(dx,
/// dy)`: the height of the texel at that offset, rows from dy = −2), at
/// levels below [`DETAIL_LEVELS`] where the target has [`KEEP_DETAIL`];
/// 0 elsewhere. The nudge then moves the texel's smooth height towards
/// the target rather than its height.
///
/// Why: nudged by its own height, a pixel of a constrained ridge or valley
/// was set to the profile (its whole error on the curve's own pixels,
/// within a few metres beside it), so the feature's core came out as a
/// smooth sausage: at 1024² 74 % of the detail (std of h minus its 5×5
/// mean) of the exemplars' for the types drawn from, and of the same place
/// unconstrained (issue 40, `benches/feature_detail.py`). The profile is a
/// shape at the scale of the reach; the texture belongs to the exemplar.
/// Why not for points: a site's own detail moved it off its asked height
/// (on the large exemplars' sites, 90th percentile 2.2 → 2.7 % of relief).
/// Why only the finest levels: above them the samples span 20 px and
/// more, the scale of the profile itself; with levels 0–3 the detail
/// measured the same.
#[inline(always)]
pub fn own_detail(level: u32, target: Target, h: i32, at: impl Fn(i32, i32) -> i32) -> i32 {
    if level >= DETAIL_LEVELS || target.tol < 0 || target.tol & KEEP_DETAIL == 0 {
        return 0;
    }
    let mut sum = 0;
    for dy in [-DETAIL_STEP, 0, DETAIL_STEP] {
        for dx in [-DETAIL_STEP, 0, DETAIL_STEP] {
            sum += at(dx, dy);
        }
    }
    h - div_floor(sum, 9)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 8–9 in floating point, as printed (but the whole error where
    /// t = 0).
    fn phi_f(x: f64, t: f64) -> f64 {
        let lambda = 0.5;
        if t == 0.0 {
            return x;
        }
        let b = -lambda / (3.0 * t * t);
        let c = b * t * t * t + lambda * t;
        if x < -t {
            lambda * x + c
        } else if x > t {
            lambda * x - c
        } else {
            -b * x * x * x
        }
    }

    #[test]
    fn integer_phi_follows_eq_9() {
        for t in [0, 1, 7, 100, 2_000, MAX_TOL] {
            for x in (-70_000..=70_000).step_by(37) {
                let want = phi_f(x as f64, t as f64);
                let got = phi(x, t);
                assert!(
                    (got as f64 - want).abs() <= 1.0,
                    "φ({x}, {t}) = {got}, eq. 9: {want}"
                );
                assert_eq!(phi(-x, t), -got, "odd symmetry");
            }
        }
        // Small errors are nudged slightly, large ones by about half.
        assert_eq!(phi(10, 1000), 0);
        assert_eq!(phi(10_000, 1000), 5000 - 333);
        assert_eq!(nudge(7, 123, Target::NONE), 7);
        assert_eq!(
            nudge(
                0,
                0,
                Target {
                    height: 1000,
                    tol: 0
                }
            ),
            1000,
            "held hard: the whole error"
        );
    }
}
