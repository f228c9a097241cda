//! The `shade` stage: one RGBA8 preview pixel from quantized heights.
//!
//! This is the CPU mirror of the `kernels/shade.wgsl` compute kernel and
//! must produce the same bytes (DESIGN.md §6). Everything per pixel is
//! therefore **integer arithmetic on 32-bit values only**: no floats, no
//! 64-bit integers (WGSL has none), no shift by 32 or more. The CPU prepares
//! the inputs once (`render::prepare`); this module only consumes them.
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
//! - Signed divisions round toward −∞: [`div_floor`](crate::level::fixed::div_floor)
//!   and `rem_euclid` (`div_floor`/`rem_floor` of `kernels/common.wgsl`).
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

mod arith;
mod light;
mod lines;
mod params;
mod pixel;
#[cfg(test)]
mod tests;

pub use arith::{blend, isqrt, shr_round, shr_sym};
pub use light::hillshade;
pub use params::{ParamsError, ShadeBuffers, ShadeParams};
pub use pixel::{shade, shade_pixel};

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
