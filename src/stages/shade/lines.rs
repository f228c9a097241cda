//! Step 5 of the pipeline: anti-aliased lines (contours, index contours,
//! the coastline) placed by the pixel's distance to a level in pixels,
//! `|h − L| / |∇h|`, and the grid.

use super::arith::{alpha256, blend, isqrt, shr_sym};
use super::{FULL, ShadeParams, flags};
use crate::level::fixed::div_floor;

/// Height gradient magnitude, kept as `(g, k)`: `g · 2^k ≈ |(gx, gy)|` with
/// `g < 2^16`, where `(gx, gy)` are Horn sums (8 × units per pixel).
pub(super) struct Gradient {
    g: u32,
    k: u32,
}

impl Gradient {
    pub(super) fn new(gx: i32, gy: i32) -> Gradient {
        let m = gx.unsigned_abs().max(gy.unsigned_abs());
        let bits = 32 - m.leading_zeros();
        let k = bits.saturating_sub(15);
        let (x, y) = (shr_sym(gx, k), shr_sym(gy, k));
        Gradient {
            g: isqrt((x * x) as u32 + (y * y) as u32),
            k,
        }
    }

    /// A height difference in units → pixels × 256, when that is below
    /// `limit` (≤ 2^13); `None` otherwise, without dividing. A flat pixel
    /// is infinitely far from every level.
    fn px256_below(&self, units: u32, limit: u32) -> Option<u32> {
        let u = units >> self.k;
        // u < 2^20 keeps u·2^11 in u32; limit · g < 2^13 · 2^16.
        if self.g == 0 || u >= 1 << 20 || u << 11 >= limit * self.g {
            return None;
        }
        Some((u << 11) / self.g)
    }
}

/// A level a line may be drawn along, with its distance from the pixel.
pub(super) struct Level {
    pub(super) level: i32,
    /// |h − level| in height units (≤ 2^27 by the bounds).
    dist: u32,
    index: bool,
}

/// The contour level nearest to `h` (ties go to the lower one), or `None`
/// where sea level's contour is left to the coastline. One floor division.
pub(super) fn nearest_level(p: &ShadeParams, h: i32) -> Option<Level> {
    let interval = p.contour_interval as i32;
    let q = div_floor(h - p.contour_base, interval); // |q·I| ≤ 2^27 + 2^27
    let below = p.contour_base + q * interval;
    let r = h - below; // 0 ≤ r < I
    let (level, k) = if r <= interval - r {
        (below, q)
    } else {
        (below + interval, q + 1)
    };
    if p.flags & flags::SEA != 0 && level == p.contour_base {
        return None;
    }
    Some(Level {
        level,
        dist: h.abs_diff(level),
        index: p.contour_index_every != 0 && k.rem_euclid(p.contour_index_every as i32) == 0,
    })
}

/// Whether a level separates the 3×3 neighbourhood: a level divides heights
/// below it from heights at or above it (`lo < level <= hi`), so flat ground
/// lying exactly on a level draws nothing.
pub(super) fn straddles(lo: i32, hi: i32, level: i32) -> bool {
    lo < level && level <= hi
}

/// Anti-aliased coverage (0..=256) of a line `dist` height units away:
/// the distance in pixels is `dist / |∇h|`, and a box-filtered line is
/// full inside its half width and falls off linearly over one pixel.
pub(super) fn line_coverage(g: &Gradient, dist: u32, half_width: u32) -> u32 {
    let reach = half_width + 128; // ≤ 2^13
    match g.px256_below(dist, reach) {
        Some(d) => (reach - d).min(FULL),
        None => 0,
    }
}

pub(super) fn contour(p: &ShadeParams, g: &Gradient, l: &Level, colour: u32) -> u32 {
    let (half_width, line) = if l.index {
        (p.index_half_width, p.index_colour)
    } else {
        (p.contour_half_width, p.contour_colour)
    };
    let mut cov = line_coverage(g, l.dist, half_width);
    if cov == 0 {
        return colour;
    }
    if !l.index && p.contour_min_spacing > 0 {
        // Spacing between neighbouring levels, in 1/256 px: fade the minor
        // lines from full at `min_spacing` to nothing at half of it.
        let half = p.contour_min_spacing / 2;
        let spacing = g
            .px256_below(p.contour_interval, p.contour_min_spacing)
            .unwrap_or(p.contour_min_spacing);
        let fade = (spacing.saturating_sub(half) * FULL / half.max(1)).min(FULL);
        cov = (cov * fade) >> 8;
    }
    blend(colour, line, (cov * alpha256(line)) >> 8)
}

/// Whether pixel `x` (covering `[x, x+1)`) contains a grid line at a
/// positive multiple of `step` / 256 pixels. `x < 2^20`, so `256x` fits.
pub(super) fn on_grid(x: u32, step: u32) -> bool {
    x > 0 && (x * FULL + FULL - 1) / step != (x * FULL - 1) / step
}
