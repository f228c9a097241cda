//! Fixed-point synthesis coordinates (DESIGN §6 rule 1).
//!
//! A coordinate is an atlas position with [`FRAC_BITS`] fractional bits in a
//! non-negative i32 (atlases are < 65536 wide, so at most 24 bits are used).
//! The paper keeps real-valued coordinates so that features do not snap to
//! the coarse pyramid grid (§4, after Lefebvre & Hoppe); the fraction is
//! what carries sub-texel jitter from level to level, where each upsampling
//! doubles it into whole texels. Scoring reads the nearest texel
//! ([`round`]); reconstruction interpolates bilinearly at full precision.
//!
//! Rounding rules, identical in the WGSL mirror: [`round`] is half-up by an
//! arithmetic shift; divisions that can see negative operands use the
//! Euclidean (floor) form of [`div_floor`].

/// Fractional bits of a coordinate.
pub const FRAC_BITS: u32 = 8;
/// One texel in fixed point.
pub const ONE: i32 = 1 << FRAC_BITS;

/// A synthesis coordinate: x and y in fixed point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Coord {
    pub x: i32,
    pub y: i32,
}

impl Coord {
    pub const fn from_texel(x: i32, y: i32) -> Coord {
        Coord {
            x: x << FRAC_BITS,
            y: y << FRAC_BITS,
        }
    }
    /// Packs into one u64 (x low, y high), the stored form.
    #[inline(always)]
    pub fn pack(self) -> u64 {
        self.x as u32 as u64 | (self.y as u32 as u64) << 32
    }
    #[inline(always)]
    pub fn unpack(v: u64) -> Coord {
        Coord {
            x: v as u32 as i32,
            y: (v >> 32) as u32 as i32,
        }
    }
}

/// Nearest texel (half-up).
#[inline(always)]
pub fn round(c: i32) -> i32 {
    (c + (ONE >> 1)) >> FRAC_BITS
}

/// ⌊a / b⌋ for b > 0, with the same result in WGSL (whose `/` truncates).
///
/// Computed as an unsigned division of `a` or of `−a − 1` (the bitwise
/// complement, never negative), complemented back for negative `a`:
/// ⌊a/b⌋ = −⌈−a/b⌉ = −(⌊(−a − 1)/b⌋ + 1) there. The same value as
/// `a.div_euclid(b)`, but by a constant `b` it compiles to a multiply and
/// a shift without sign fix-ups (the correction divides per candidate).
#[inline(always)]
pub fn div_floor(a: i32, b: i32) -> i32 {
    debug_assert!(b > 0);
    let sign = a >> 31;
    (((a ^ sign) as u32 / b as u32) as i32) ^ sign
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_rules() {
        assert_eq!(round(ONE * 5 + ONE / 2 - 1), 5);
        assert_eq!(round(ONE * 5 + ONE / 2), 6);
        assert_eq!(div_floor(-7, 12), -1);
        assert_eq!(div_floor(7, 12), 0);
        assert_eq!(div_floor(-12, 12), -1);
        for a in [
            i32::MIN,
            i32::MIN + 1,
            -37,
            -36,
            -35,
            -1,
            0,
            1,
            35,
            36,
            i32::MAX,
        ] {
            for b in [1, 2, 12, 24, 36, 1 << 20, i32::MAX] {
                assert_eq!(div_floor(a, b), a.div_euclid(b), "{a} / {b}");
            }
        }
        let c = Coord {
            x: 123_456,
            y: 65_535 << FRAC_BITS,
        };
        assert_eq!(Coord::unpack(c.pack()), c);
    }
}
