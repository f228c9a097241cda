//! The `shade` stage: one RGBA8 preview pixel from quantized heights.
//!
//! This is the CPU mirror of the `kernels/shade.wgsl` compute kernel and
//! must produce the same bytes (DESIGN.md §6). Everything per pixel is
//! therefore **integer arithmetic on 32-bit values only**: no floats, no
//! 64-bit integers (WGSL has none), no shift by 32 or more. The CPU prepares
//! the inputs once ([`super::prepare`]); this file only consumes them.
//!
//! # Inputs
//! - heights: `i32` per pixel in one unit throughout (the renderer uses
//!   millimetres; the kernel does not care which unit, every parameter is
//!   expressed in it). [`NODATA`] marks a missing sample. Valid heights must
//!   lie in `±MAX_ABS_HEIGHT` (±2²⁶), so that a difference of two heights
//!   fits in 28 bits and a Horn gradient sum in 30 bits.
//! - types: one 8-bit type index per pixel, packed four per `u32`, the pixel
//!   `i` in bits `8·(i mod 4)..` of word `i / 4`; [`NO_TYPE`] (255) = none.
//! - tint: the hypsometric look-up table, packed RGBA (`r | g<<8 | b<<16 | a<<24`).
//! - type colours: 256 packed RGBA colours, alpha = overlay opacity.
//!
//! # Rounding rules (the same on both sides)
//! - `a / b` on non-negative values truncates (= floor).
//! - [`floor_div`]/[`floor_mod`] round toward −∞ for signed values.
//! - [`shr_sym`] shifts the magnitude and restores the sign (rounds toward
//!   zero), so positive and negative slopes are treated alike;
//!   [`shr_round`] adds half before shifting the magnitude (round half away
//!   from zero).
//! - Colour blends: `(a·(256−t) + b·t + 128) >> 8` with `t` in 0..=256.
//!
//! # Pipeline of one pixel
//! 1. Read the 3×3 neighbourhood (edges replicate, nodata neighbours take the
//!    centre's value); remember its min and max.
//! 2. Horn's gradient (the 3×3 Sobel weights GDAL uses), scaled to a slope in
//!    [`SLOPE_ONE`] fixed point with the true cell size and exaggeration.
//! 3. Multi-directional hillshade: up to four Lambert lights, mixed by fixed
//!    weights or by the USGS aspect weighting (Mark 1992, GDAL
//!    `-multidirectional`).
//! 4. Base colour: out-of-range red, water below sea level, or the
//!    hypsometric tint; then the type overlay; then shading.
//! 5. Anti-aliased contour lines (width from the pixel's distance to the
//!    level in pixels, `|h − L| / |∇h|`), index contours, the coastline, grid.

use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

/// Height value of a missing sample.
pub const NODATA: i32 = i32::MIN;
/// Valid heights lie in `-MAX_ABS_HEIGHT..=MAX_ABS_HEIGHT` (±67 km in mm).
pub const MAX_ABS_HEIGHT: i32 = 1 << 26;
/// Fixed-point slope unit: a slope (rise over run) of 1 is `SLOPE_ONE`.
pub const SLOPE_ONE: i32 = 1 << 12;
/// Slopes are clamped to ±64 (89.1°); steeper makes no visible difference.
pub const MAX_SLOPE: i32 = 1 << 18;
/// Light vectors are unit vectors scaled by this.
pub const LIGHT_ONE: i32 = 1 << 12;
/// The most lights a [`ShadeParams`] can hold.
pub const MAX_LIGHTS: usize = 4;
/// Type index meaning "no type here".
pub const NO_TYPE: u32 = 255;
/// Full coverage / opacity in the 0..=256 blend scale.
pub const FULL: u32 = 256;

/// Feature switches in [`ShadeParams::flags`].
pub mod flags {
    /// Draw contour lines.
    pub const CONTOURS: u32 = 1;
    /// Draw the grid.
    pub const GRID: u32 = 1 << 1;
    /// Paint heights outside `range_lo..=range_hi` with `range_colour`.
    pub const RANGE: u32 = 1 << 2;
    /// Heights `<= water_level` are water, with a coastline at the boundary;
    /// the contour at `contour_base` (sea level) is left to the coastline.
    pub const SEA: u32 = 1 << 3;
    /// Blend the type colours over the base colour.
    pub const TYPES: u32 = 1 << 4;
    /// Weight the lights by the USGS aspect rule instead of fixed weights.
    pub const ASPECT_WEIGHTS: u32 = 1 << 5;
    /// Every flag the kernel knows.
    pub const ALL: u32 = (1 << 6) - 1;
}

/// Everything the kernel needs besides the buffers. `#[repr(C)]`, only
/// 32-bit integer fields, 16-byte aligned blocks, so the same bytes can be a
/// WGSL uniform buffer. Colours are packed RGBA (`r | g<<8 | b<<16 | a<<24`),
/// where alpha is the opacity of the thing drawn.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct ShadeParams {
    /// Per light: direction towards the light `(x east, y south, z up)` as a
    /// unit vector times [`LIGHT_ONE`], then its fixed weight (0..=256).
    pub lights: [[i32; 4]; MAX_LIGHTS],
    pub width: u32,
    pub height: u32,
    /// [`flags`] bits.
    pub flags: u32,
    /// Lights in use, 1..=4.
    pub light_count: u32,

    /// Horn x sum → slope: `clamp(shr_sym(s, pre), ±clamp) · mul`, then
    /// `shr_round(·, post)`. `clamp · mul ≤ 2³⁰`, `post ≤ 12`, `pre ≤ 30`.
    pub slope_x_mul: i32,
    pub slope_x_pre: u32,
    pub slope_x_post: u32,
    pub slope_x_clamp: i32,
    /// The same for the y (southward) sum.
    pub slope_y_mul: i32,
    pub slope_y_pre: u32,
    pub slope_y_post: u32,
    pub slope_y_clamp: i32,

    /// Shading factor (×256) of a fully dark pixel: the factor is
    /// `shade_floor + (hs · shade_gain + 2^15) >> 16`, where the CPU picks
    /// the gain so that flat ground gets exactly 256 (`≤ 2^19`).
    pub shade_floor: u32,
    pub shade_gain: u32,
    /// Largest shading factor (256..=512); above 256 the colour moves to white.
    pub shade_max: u32,
    pub nodata_colour: u32,

    /// Tint table: entry `min((max(h, tint_lo) − tint_lo) >> tint_shift, tint_len − 1)`.
    pub tint_lo: i32,
    pub tint_shift: u32,
    pub tint_len: u32,
    pub nodata_hatch: u32,

    /// Water is `h <= water_level` (sea level plus a tolerance for flat-sea
    /// noise); its depth tint is `min(256, (water_level − h) >> water_shift)`.
    pub water_level: i32,
    pub water_shift: u32,
    pub water_shallow: u32,
    pub water_deep: u32,

    pub range_lo: i32,
    pub range_hi: i32,
    pub range_colour: u32,
    pub coast_colour: u32,

    /// Contour levels are `contour_base + k · contour_interval` (interval ≥ 1,
    /// ≤ 2²⁷); every `contour_index_every`-th (0 = none) is an index contour.
    pub contour_base: i32,
    pub contour_interval: u32,
    pub contour_index_every: u32,
    pub contour_colour: u32,
    /// Half widths in 1/256 pixel.
    pub contour_half_width: u32,
    pub index_half_width: u32,
    pub coast_half_width: u32,
    pub index_colour: u32,
    /// Minor contours fade out where they are closer than this many 1/256
    /// pixels (fully gone at half of it), so steep slopes do not turn solid.
    pub contour_min_spacing: u32,
    /// Grid line spacing in 1/256 pixel (≥ 256), per axis.
    pub grid_step_x: u32,
    pub grid_step_y: u32,
    pub grid_colour: u32,
}

/// The buffers the kernel reads.
#[derive(Clone, Copy, Debug)]
pub struct ShadeBuffers<'a> {
    pub heights: &'a [i32],
    /// Packed type indices; may be empty when [`flags::TYPES`] is off.
    pub types: &'a [u32],
    pub tint: &'a [u32],
    /// 256 colours; may be empty when [`flags::TYPES`] is off.
    pub type_colours: &'a [u32],
}

/// Why a parameter block cannot be run. Checked once before the loop so the
/// per-pixel code can index without surprises.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid shade parameters: {0}")]
pub struct ParamsError(pub String);

impl ShadeParams {
    /// Checks every bound the kernel relies on, and the buffer lengths.
    pub fn validate(&self, b: &ShadeBuffers) -> Result<(), ParamsError> {
        let err = |m: String| Err(ParamsError(m));
        let n = self.width as u64 * self.height as u64;
        if self.width == 0
            || self.height == 0
            || self.width > 1 << 20
            || self.height > 1 << 20
            || n > 1 << 30
        {
            return err(format!(
                "size {}x{} out of range: each side 1..=2^20, at most 2^30 pixels",
                self.width, self.height
            ));
        }
        if b.heights.len() as u64 != n {
            return err(format!("{} heights for {n} pixels", b.heights.len()));
        }
        if let Some(i) = b
            .heights
            .iter()
            .position(|&h| h != NODATA && !(-MAX_ABS_HEIGHT..=MAX_ABS_HEIGHT).contains(&h))
        {
            return err(format!(
                "height {} at pixel {i} outside ±{MAX_ABS_HEIGHT}",
                b.heights[i]
            ));
        }
        for (name, v) in [
            ("tint_lo", self.tint_lo),
            ("water_level", self.water_level),
            ("contour_base", self.contour_base),
        ] {
            if !(-MAX_ABS_HEIGHT..=MAX_ABS_HEIGHT).contains(&v) {
                return err(format!("{name} {v} outside ±{MAX_ABS_HEIGHT}"));
            }
        }
        if self.flags & !flags::ALL != 0 {
            return err(format!("unknown flag bits {:#x}", self.flags & !flags::ALL));
        }
        if !(1..=MAX_LIGHTS as u32).contains(&self.light_count) {
            return err(format!("light_count {} must be 1..=4", self.light_count));
        }
        for l in &self.lights[..self.light_count as usize] {
            if l[..3].iter().any(|c| c.abs() > LIGHT_ONE) || !(0..=256).contains(&l[3]) {
                return err(format!(
                    "light {l:?}: components must be within ±{LIGHT_ONE}, weight 0..=256"
                ));
            }
        }
        if self.lights[..self.light_count as usize]
            .iter()
            .all(|l| l[3] == 0)
        {
            return err("every light has weight 0".into());
        }
        for (mul, pre, post, clamp) in [
            (
                self.slope_x_mul,
                self.slope_x_pre,
                self.slope_x_post,
                self.slope_x_clamp,
            ),
            (
                self.slope_y_mul,
                self.slope_y_pre,
                self.slope_y_post,
                self.slope_y_clamp,
            ),
        ] {
            if mul < 0
                || pre > 30
                || post > 12
                || clamp < 0
                || (clamp as i64) * (mul as i64) > 1 << 30
            {
                return err(format!(
                    "slope scale mul {mul} pre {pre} post {post} clamp {clamp}: need mul, clamp >= 0, pre <= 30, post <= 12, clamp*mul <= 2^30"
                ));
            }
        }
        if self.shade_gain > 1 << 19 {
            return err(format!("shade_gain {} must be <= 2^19", self.shade_gain));
        }
        if self.shade_floor > FULL || !(FULL..=2 * FULL).contains(&self.shade_max) {
            return err(format!(
                "shade_floor {} must be <= 256 and shade_max {} in 256..=512",
                self.shade_floor, self.shade_max
            ));
        }
        if self.tint_shift > 31 || self.tint_len == 0 || b.tint.len() != self.tint_len as usize {
            return err(format!(
                "tint table: shift {} must be <= 31, length {} >= 1 and match the buffer ({})",
                self.tint_shift,
                self.tint_len,
                b.tint.len()
            ));
        }
        if self.water_shift > 31 {
            return err(format!("water_shift {} must be <= 31", self.water_shift));
        }
        if self.flags & flags::CONTOURS != 0
            && (self.contour_interval == 0 || self.contour_interval > 1 << 27)
        {
            return err(format!(
                "contour interval {} must be 1..=2^27",
                self.contour_interval
            ));
        }
        let half_widths = [
            self.contour_half_width,
            self.index_half_width,
            self.coast_half_width,
        ];
        if half_widths.iter().any(|&w| w > 16 * FULL) || self.contour_min_spacing > 1 << 13 {
            return err("line half widths must be <= 16 px, min spacing <= 32 px".into());
        }
        if self.flags & flags::GRID != 0 && (self.grid_step_x < FULL || self.grid_step_y < FULL) {
            return err(format!(
                "grid step {}x{} (1/256 px) must be >= 256",
                self.grid_step_x, self.grid_step_y
            ));
        }
        if self.flags & flags::TYPES != 0
            && (b.types.len() as u64 != n.div_ceil(4) || b.type_colours.len() != 256)
        {
            return err(format!(
                "type buffers: {} words for {n} pixels (need {}), {} colours (need 256)",
                b.types.len(),
                n.div_ceil(4),
                b.type_colours.len()
            ));
        }
        Ok(())
    }
}

/// Shades every pixel into `out` (row-major, packed RGBA), in parallel over
/// rows. The result does not depend on the thread count: each pixel is a pure
/// function of the inputs.
pub fn shade(p: &ShadeParams, b: &ShadeBuffers, out: &mut [u32]) -> Result<(), ParamsError> {
    p.validate(b)?;
    let w = p.width as usize;
    if out.len() != w * p.height as usize {
        return Err(ParamsError(format!(
            "output has {} pixels, expected {}",
            out.len(),
            w * p.height as usize
        )));
    }
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            *px = shade_pixel(p, b, x as u32, y as u32);
        }
    });
    Ok(())
}

/// One pixel. `p` must have passed [`ShadeParams::validate`] against `b`
/// (otherwise this may panic on an index, never return garbage silently).
pub fn shade_pixel(p: &ShadeParams, b: &ShadeBuffers, x: u32, y: u32) -> u32 {
    let w = p.width;
    let i = (y * w + x) as usize;
    let h = b.heights[i];
    if h == NODATA {
        // Diagonal hatching, 4 px stripes, so nodata never reads as terrain.
        return if ((x + y) >> 2) & 1 == 0 {
            p.nodata_colour
        } else {
            p.nodata_hatch
        };
    }

    // 1. Neighbourhood: rows above (n), centre (c), below (s); columns w, c, e.
    let xw = if x > 0 { x - 1 } else { 0 };
    let xe = if x + 1 < w { x + 1 } else { x };
    let yn = if y > 0 { y - 1 } else { 0 };
    let ys = if y + 1 < p.height { y + 1 } else { y };
    let mut lo = h;
    let mut hi = h;
    let mut at = |xx: u32, yy: u32| -> i32 {
        let v = b.heights[(yy * w + xx) as usize];
        let v = if v == NODATA { h } else { v };
        lo = lo.min(v);
        hi = hi.max(v);
        v
    };
    let nw = at(xw, yn);
    let n = at(x, yn);
    let ne = at(xe, yn);
    let we = at(xw, y);
    let ea = at(xe, y);
    let sw = at(xw, ys);
    let s = at(x, ys);
    let se = at(xe, ys);

    // 2. Horn sums: 8 × the gradient in height units per pixel. On the
    // image border the replicated column spans one pixel instead of two, so
    // the one-sided sum is doubled (edges shade like the interior).
    // Each side is ≤ 4 · 2^26, so |sum| ≤ 2^29, and ≤ 2^30 doubled.
    let mut gx = (ne + 2 * ea + se) - (nw + 2 * we + sw);
    let mut gy = (sw + 2 * s + se) - (nw + 2 * n + ne);
    if xe - xw == 1 {
        gx *= 2;
    }
    if ys - yn == 1 {
        gy *= 2;
    }
    let sx = slope(
        gx,
        p.slope_x_mul,
        p.slope_x_pre,
        p.slope_x_post,
        p.slope_x_clamp,
    );
    let sy = slope(
        gy,
        p.slope_y_mul,
        p.slope_y_pre,
        p.slope_y_post,
        p.slope_y_clamp,
    );

    // 3. Light.
    let hs = hillshade(p, sx, sy);
    // hs ≤ 4096, gain ≤ 2^19: the product and the rounding half fit in u32.
    let factor = (p.shade_floor + ((hs * p.shade_gain + (1 << 15)) >> 16)).min(p.shade_max);

    // 4. Colour.
    let water = p.flags & flags::SEA != 0 && h <= p.water_level;
    let out_of_range = p.flags & flags::RANGE != 0 && (h < p.range_lo || h > p.range_hi);
    let mut colour = if out_of_range {
        p.range_colour
    } else if water {
        let t = ((p.water_level - h) as u32 >> p.water_shift).min(FULL);
        blend(p.water_shallow, p.water_deep, t)
    } else {
        let d = (h.max(p.tint_lo) - p.tint_lo) as u32; // < 2^28
        b.tint[(d >> p.tint_shift).min(p.tint_len - 1) as usize]
    };
    if p.flags & flags::TYPES != 0 {
        let t = (b.types[i >> 2] >> ((i as u32 & 3) * 8)) & 0xff;
        if t != NO_TYPE {
            let c = b.type_colours[t as usize];
            colour = blend(colour, c, alpha256(c));
        }
    }
    colour = apply_shade(colour, factor);

    // 5. Lines. Which levels pass through the 3×3 neighbourhood is cheap to
    // find; the gradient magnitude (a square root) is only needed there.
    let contour_level = if p.flags & flags::CONTOURS != 0 {
        // Contours follow the 1-2-1 smoothed height (the same 3×3 weights
        // as the gradient), so sensor noise on flat ground does not draw
        // a froth of tiny loops. |sum| ≤ 16 · 2^26 = 2^30.
        let sum = 4 * h + 2 * (n + s + we + ea) + (nw + ne + sw + se);
        nearest_level(p, floor_div(sum, 16)).filter(|l| straddles(lo, hi, l.level))
    } else {
        None
    };
    // The coastline is the level just above sea level.
    let coast = p.flags & flags::SEA != 0 && straddles(lo, hi, p.water_level + 1);
    if contour_level.is_some() || coast {
        let g = Gradient::new(gx, gy);
        if let Some(l) = contour_level {
            colour = contour(p, &g, &l, colour);
        }
        if coast {
            let cov = line_coverage(&g, h.abs_diff(p.water_level + 1), p.coast_half_width);
            colour = blend(
                colour,
                p.coast_colour,
                (cov * alpha256(p.coast_colour)) >> 8,
            );
        }
    }
    if p.flags & flags::GRID != 0 && (on_grid(x, p.grid_step_x) || on_grid(y, p.grid_step_y)) {
        colour = blend(colour, p.grid_colour, alpha256(p.grid_colour));
    }
    colour | 0xff00_0000
}

/// Horn sum → fixed-point slope (see [`ShadeParams::slope_x_mul`]).
#[inline]
fn slope(s: i32, mul: i32, pre: u32, post: u32, clamp: i32) -> i32 {
    let t = shr_sym(s, pre).clamp(-clamp, clamp);
    shr_round(t * mul, post).clamp(-MAX_SLOPE, MAX_SLOPE)
}

/// Combined hillshade, 0..=4096, of the surface with slopes `(sx, sy)`
/// ([`SLOPE_ONE`] fixed point, y southward). Public so the CPU side can ask
/// for the value of flat ground with exactly the kernel's arithmetic.
pub fn hillshade(p: &ShadeParams, sx: i32, sy: i32) -> u32 {
    // Surface normal (−sx, −sy, 1), rescaled so its largest component lies in
    // [2^14, 2^15): the squared length then fits in u32 (< 3·2^30) and the
    // dot products in i32 (< 3·2^27).
    let (mut nx, mut ny, mut nz) = (-sx, -sy, SLOPE_ONE);
    let m = nx.unsigned_abs().max(ny.unsigned_abs()).max(nz as u32);
    let bits = 32 - m.leading_zeros(); // m >= 2^12, so bits >= 13
    if bits > 15 {
        let k = bits - 15;
        nx = shr_sym(nx, k);
        ny = shr_sym(ny, k);
        nz = shr_sym(nz, k);
    } else {
        let k = 15 - bits;
        nx <<= k;
        ny <<= k;
        nz <<= k;
    }
    // len in [2^14, 2^15.8); its reciprocal 2^30 / len in (2^14.2, 2^16].
    let len = isqrt((nx * nx) as u32 + (ny * ny) as u32 + (nz * nz) as u32);
    let recip = (1u32 << 30) / len;

    // Aspect direction (downslope, the normal's horizontal part) scaled to a
    // largest component in [2^7, 2^8), for the USGS weights.
    let aspect = p.flags & flags::ASPECT_WEIGHTS != 0 && (nx != 0 || ny != 0);
    let (mut dx, mut dy) = (nx, ny);
    if aspect {
        let m = dx.unsigned_abs().max(dy.unsigned_abs());
        let bits = 32 - m.leading_zeros();
        if bits > 8 {
            dx = shr_sym(dx, bits - 8);
            dy = shr_sym(dy, bits - 8);
        } else {
            dx <<= 8 - bits;
            dy <<= 8 - bits;
        }
    }

    // Lambert term dot / len, 0..=4096: dot < (len + 1) · 4096 < 2^27.8, so
    // (dot >> 12) · recip < 2^15.8 · 2^16 fits u32.
    let lambert = |l: &[i32; 4]| -> u32 {
        let dot = nx * l[0] + ny * l[1] + nz * l[2];
        ((dot.max(0) as u32 >> 12) * recip) >> 18
    };
    let mut sum = 0u32; // < 4 · 2^15 · 2^12 = 2^29
    let mut wsum = 0u32;
    for l in &p.lights[..p.light_count as usize] {
        let lambert = lambert(l);
        let w = if aspect {
            // sin²(aspect − azimuth) = cross(d, a)² / (|d|²|a|²), with the
            // light's horizontal direction a at ≤ 2^7: |cross| < 2^15.5.
            let cross = dx * shr_sym(l[1], 5) - dy * shr_sym(l[0], 5);
            ((((cross * cross) as u32) >> 16) * l[3] as u32) >> 8 // < 2^15
        } else {
            l[3] as u32
        };
        sum += w * lambert;
        wsum += w;
    }
    if wsum == 0 {
        // Aspect weights all vanished (a light from straight above, or the
        // slope exactly along every light): fall back to the fixed weights.
        sum = 0;
        for l in &p.lights[..p.light_count as usize] {
            sum += l[3] as u32 * lambert(l);
            wsum += l[3] as u32;
        }
    }
    sum / wsum
}

/// Height gradient magnitude, kept as `(g, k)`: `g · 2^k ≈ |(gx, gy)|` with
/// `g < 2^16`, where `(gx, gy)` are Horn sums (8 × units per pixel).
struct Gradient {
    g: u32,
    k: u32,
}

impl Gradient {
    fn new(gx: i32, gy: i32) -> Gradient {
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
struct Level {
    level: i32,
    /// |h − level| in height units (≤ 2^27 by the bounds).
    dist: u32,
    index: bool,
}

/// The contour level nearest to `h` (ties go to the lower one), or `None`
/// where sea level's contour is left to the coastline. One floor division.
fn nearest_level(p: &ShadeParams, h: i32) -> Option<Level> {
    let interval = p.contour_interval as i32;
    let q = floor_div(h - p.contour_base, interval); // |q·I| ≤ 2^27 + 2^27
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
        index: p.contour_index_every != 0 && floor_mod(k, p.contour_index_every as i32) == 0,
    })
}

/// Whether a level separates the 3×3 neighbourhood: a level divides heights
/// below it from heights at or above it (`lo < level <= hi`), so flat ground
/// lying exactly on a level draws nothing.
fn straddles(lo: i32, hi: i32, level: i32) -> bool {
    lo < level && level <= hi
}

/// Anti-aliased coverage (0..=256) of a line `dist` height units away:
/// the distance in pixels is `dist / |∇h|`, and a box-filtered line is
/// full inside its half width and falls off linearly over one pixel.
fn line_coverage(g: &Gradient, dist: u32, half_width: u32) -> u32 {
    let reach = half_width + 128; // ≤ 2^13
    match g.px256_below(dist, reach) {
        Some(d) => (reach - d).min(FULL),
        None => 0,
    }
}

fn contour(p: &ShadeParams, g: &Gradient, l: &Level, colour: u32) -> u32 {
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
fn on_grid(x: u32, step: u32) -> bool {
    x > 0 && (x * FULL + FULL - 1) / step != (x * FULL - 1) / step
}

/// Multiplies a colour by `factor`/256; above 256 moves it toward white by
/// `(factor − 256)`/256 instead, so highlights do not shift the hue.
fn apply_shade(c: u32, factor: u32) -> u32 {
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
fn alpha256(c: u32) -> u32 {
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

/// Floor division for `d > 0` (rounds toward −∞), from truncating division.
#[inline]
pub fn floor_div(a: i32, d: i32) -> i32 {
    let q = a / d;
    if a % d < 0 { q - 1 } else { q }
}

/// The remainder of [`floor_div`], in `0..d`.
#[inline]
pub fn floor_mod(a: i32, d: i32) -> i32 {
    let r = a % d;
    if r < 0 { r + d } else { r }
}

/// `floor(sqrt(n))`, bit by bit: 16 fixed steps of the classic method,
/// written with selects instead of branches (the data decide each step, so
/// a branch would mispredict half the time; WGSL's `select` does the same).
#[inline]
pub fn isqrt(n: u32) -> u32 {
    let mut rem = n;
    let mut root = 0u32;
    let mut bit = 1u32 << 30;
    while bit != 0 {
        let t = root + bit;
        let take = rem >= t;
        rem = if take { rem - t } else { rem };
        root = (root >> 1) + if take { bit } else { 0 };
        bit >>= 2;
    }
    root
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn isqrt_is_floor_sqrt() {
        for n in (0..70_000u32).chain([u32::MAX, u32::MAX - 1, 1 << 30, (1 << 30) - 1]) {
            let r = isqrt(n) as u64;
            assert!(r * r <= n as u64 && (r + 1) * (r + 1) > n as u64, "{n}");
        }
    }

    #[test]
    fn rounding_helpers() {
        assert_eq!((floor_div(-7, 5), floor_mod(-7, 5)), (-2, 3));
        assert_eq!((floor_div(7, 5), floor_mod(7, 5)), (1, 2));
        assert_eq!((floor_div(-5, 5), floor_mod(-5, 5)), (-1, 0));
        assert_eq!((shr_sym(-5, 1), shr_sym(5, 1)), (-2, 2));
        assert_eq!(
            (shr_round(-6, 2), shr_round(6, 2), shr_round(5, 2)),
            (-2, 2, 1)
        );
        assert!(on_grid(4, 4 * 256) && !on_grid(3, 4 * 256) && !on_grid(0, 256));
        assert!(on_grid(1, 256) && on_grid(2, 256));
    }

    #[test]
    fn blend_ends_are_exact() {
        let (a, b) = (0x0012_3456, 0x00ab_cdef);
        assert_eq!(blend(a, b, 0), a);
        assert_eq!(blend(a, b, FULL), b);
        assert_eq!(apply_shade(a, FULL), a);
        assert_eq!(apply_shade(a, 2 * FULL), 0x00ff_ffff);
    }
}
