//! The integer arithmetic of the rounding rules in the module docs, each
//! with a WGSL twin: sign-symmetric shifts, floor division, `isqrt`, and
//! colour blends in the 0..=256 scale.

use super::FULL;

/// Multiplies a colour by `factor`/256; above 256 moves it toward white by
/// `(factor − 256)`/256 instead, so highlights do not shift the hue.
pub(super) fn apply_shade(c: u32, factor: u32) -> u32 {
    if factor <= FULL {
        let ch = |s: u32| ((c >> s & 0xff) * factor + 128) >> 8;
        ch(0) | ch(8) << 8 | ch(16) << 16
    } else {
        blend(c, 0x00ff_ffff, factor - FULL)
    }
}

/// `a` → `b` by `t`/256 per RGB channel; the result's alpha byte is 0.
#[inline]
pub fn blend(a: u32, b: u32, t: u32) -> u32 {
    let ch = |s: u32| ((a >> s & 0xff) * (FULL - t) + (b >> s & 0xff) * t + 128) >> 8;
    ch(0) | ch(8) << 8 | ch(16) << 16
}

/// A packed colour's alpha as 0..=256 (255 → 256, so opaque is exact).
#[inline]
pub(super) fn alpha256(c: u32) -> u32 {
    let a = c >> 24;
    a + (a >> 7)
}

/// Shifts the magnitude right by `k` (< 32) and restores the sign: rounds
/// toward zero, symmetric for ±.
#[inline]
pub fn shr_sym(v: i32, k: u32) -> i32 {
    let m = (v.unsigned_abs() >> k) as i32;
    if v < 0 { -m } else { m }
}

/// Shifts the magnitude right by `k` (< 32) rounding half away from zero.
/// Needs `|v| + 2^(k−1) < 2^31`.
#[inline]
pub fn shr_round(v: i32, k: u32) -> i32 {
    if k == 0 {
        return v;
    }
    let m = ((v.unsigned_abs() + (1 << (k - 1))) >> k) as i32;
    if v < 0 { -m } else { m }
}

/// `floor(sqrt(n))`. The WGSL twin works bit by bit (16 fixed steps,
/// with selects); here the hardware's square root gives the same value in
/// a few instructions instead of a 16-step dependency chain per pixel:
/// the correctly rounded f64 root of a u32 is never rounded up to the next
/// integer (below (k + 1)² the root is under k + 1 − 1/(2k + 2), a gap of
/// more than 2⁻¹⁸, where f64's spacing near 2¹⁶ is 2⁻³⁶), and the cast
/// truncates.
#[inline]
pub fn isqrt(n: u32) -> u32 {
    (n as f64).sqrt() as u32
}
