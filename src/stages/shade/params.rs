//! The kernel's parameter block ([`ShadeParams`], the same bytes as the
//! WGSL uniform) and buffers, and the bounds checked once before any pixel
//! is shaded, so that the per-pixel code can index without surprises.

use super::{FULL, LIGHT_ONE, MAX_ABS_HEIGHT, MAX_LIGHTS, NODATA, flags};
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;

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
        // In parallel (the first offender, so the message is the same).
        if let Some(i) = b
            .heights
            .par_iter()
            .position_first(|&h| h != NODATA && !(-MAX_ABS_HEIGHT..=MAX_ABS_HEIGHT).contains(&h))
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
