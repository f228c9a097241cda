//! The CPU side of `shade`: everything a person chooses in metres, degrees
//! and colours is turned, once, into the integers the kernel consumes.
//! Floats are fine here (DESIGN.md §6 rule 5): the kernel only ever sees
//! their quantized results, so CPU and GPU shade the same inputs.
//!
//! Heights become `i32` millimetres: exact for every format we read (SRTM
//! and PNG16 sidecars resolve centimetres at best) and ±67 km of range
//! ([`shade::MAX_ABS_HEIGHT`]) covers the Earth with room to spare.

use super::contours::{self, Contours};
use super::tint::{self, pack};
use super::types::TypeOverlay;
use super::{Grid, Lighting, RenderError, RenderOptions, Sea, preview_size};
use crate::heightfield::Heightfield;
use crate::stages::shade::{self, ShadeBuffers, ShadeParams, flags};
use rayon::prelude::*;

/// Kernel height units per metre (millimetres).
pub const UNITS_PER_M: f64 = 1000.0;
/// Heights up to this far above sea level still count as sea: SRTM stores
/// the sea as exactly 0 m, and 16-bit PNG quantization plus resampling ring
/// it by a few centimetres; real land starts at 1 m.
pub const SEA_TOLERANCE_M: f64 = 0.25;
/// Colours of things that are not terrain.
pub const RANGE_COLOUR: [u8; 3] = [226, 36, 30];
pub const NODATA_COLOUR: [u8; 3] = [160, 160, 164];
pub const NODATA_HATCH: [u8; 3] = [186, 186, 190];
pub const GRID_COLOUR: [u8; 4] = [255, 255, 255, 90];
/// How far the tint is muted toward grey under a type overlay, unless
/// its [`super::TypeOverlay::mute`] says otherwise.
pub const TYPES_MUTE: f64 = 0.8;
/// Grid lines closer than this are refused (they would grey the image out).
pub const MIN_GRID_PX: f64 = 2.0;

/// Inputs ready for [`shade::shade`], and what was chosen on the way.
#[derive(Debug, Clone)]
pub struct Prepared {
    pub params: ShadeParams,
    pub heights: Vec<i32>,
    pub types: Vec<u32>,
    pub tint: Vec<u32>,
    pub type_colours: Vec<u32>,
    pub info: RenderInfo,
}

impl Prepared {
    pub fn buffers(&self) -> ShadeBuffers<'_> {
        ShadeBuffers {
            heights: &self.heights,
            types: &self.types,
            tint: &self.tint,
            type_colours: &self.type_colours,
        }
    }
}

/// What a render chose, for captions, legends and overlays.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderInfo {
    /// Preview size in pixels.
    pub width: usize,
    pub height: usize,
    /// Preview pixels per heightfield cell, per axis.
    pub px_per_cell_x: f64,
    pub px_per_cell_y: f64,
    /// Valid height range of the input, metres (`None`: all nodata).
    pub height_range_m: Option<(f64, f64)>,
    /// Contour interval in metres (`None`: no contours); every
    /// [`contours::INDEX_EVERY`]-th is an index contour.
    pub contour_interval_m: Option<f64>,
    /// Sea level in metres when water is shown.
    pub sea_level_m: Option<f64>,
    /// Heights the land palette runs over, metres.
    pub tint_range_m: (f64, f64),
}

/// Resizes, quantizes and parameterizes: all the float work of a render.
pub fn prepare(hf: &Heightfield, o: &RenderOptions) -> Result<Prepared, RenderError> {
    check_options(o)?;
    if let Some(t) = &o.types {
        check_types(hf, t)?;
    }
    let (w, h) = (hf.width(), hf.height());
    // The minimum is a wish and yields to the maximum.
    let (ow, oh) = preview_size::fit(w, h, o.min_size.min(o.max_size), o.max_size);
    // In parallel, and without a copy where the preview has the terrain's
    // size: after a synthesis this ran on one core while the other idled.
    let heights: Vec<i32> = preview_size::heights(hf.data(), w, h, ow, oh)
        .par_iter()
        .map(|&v| quantize(v as f64))
        .collect();
    let (sx, sy) = (ow as f64 / w as f64, oh as f64 / h as f64);
    let cell_x = hf.cell_size() / sx;
    let cell_y = hf.cell_size() / sy;
    let range = hf.extent().range.map(|(lo, hi)| (lo as f64, hi as f64));

    let mut p = ShadeParams::zeroed_with_size(ow as u32, oh as u32);
    set_lights(&mut p, &o.lighting);
    (
        p.slope_x_mul,
        p.slope_x_pre,
        p.slope_x_post,
        p.slope_x_clamp,
    ) = slope_scale(o.exaggeration, cell_x)?;
    (
        p.slope_y_mul,
        p.slope_y_pre,
        p.slope_y_post,
        p.slope_y_clamp,
    ) = slope_scale(o.exaggeration, cell_y)?;
    p.shade_floor = (o.lighting.shadow * 256.0).round() as u32;
    // Flat ground must come out at exactly 256 (the tint unchanged): the
    // gain maps the kernel's own flat hillshade onto 256 − floor.
    let flat = shade::hillshade(&p, 0, 0).max(1) as f64;
    p.shade_gain = (((256 - p.shade_floor) as f64 * 65536.0 / flat).round() as u32).min(1 << 19);
    p.shade_max = ((1.0 + o.lighting.highlight) * 256.0).round() as u32;
    p.nodata_colour = pack(NODATA_COLOUR, 255);
    p.nodata_hatch = pack(NODATA_HATCH, 255);

    // Sea: water below sea level (+ tolerance), the land palette above it.
    let (lo, hi) = range.unwrap_or((0.0, 0.0));
    let sea_level = match o.sea {
        Sea::Off => None,
        Sea::Level(s) => Some(s),
        Sea::Auto => (lo < 0.0 && hi > 0.0).then_some(0.0),
    };
    let land_lo = match sea_level {
        Some(s) => {
            p.flags |= flags::SEA;
            p.water_level = quantize(s + SEA_TOLERANCE_M);
            let depth = (s + SEA_TOLERANCE_M - lo).max(tint::MIN_WATER_DEPTH_M);
            // A power-of-two depth step (a shift in the kernel) reaching
            // the deep colour at `depth` or up to twice it.
            let step = ((depth * UNITS_PER_M / 256.0).ceil() as u32).max(1);
            p.water_shift = step.next_power_of_two().trailing_zeros();
            p.water_shallow = pack(tint::WATER_SHALLOW, 255);
            p.water_deep = pack(tint::WATER_DEEP, 255);
            p.coast_colour = pack3(contours::COAST_COLOUR);
            p.coast_half_width = px256(contours::COAST_HALF_WIDTH_PX);
            s + SEA_TOLERANCE_M
        }
        None => lo,
    };

    // Tint.
    let (tlo, thi) = o
        .tint_range
        .unwrap_or((land_lo, land_lo + (hi - land_lo).max(tint::MIN_SPAN_M)));
    p.tint_lo = quantize(tlo);
    let span = (quantize(thi) - p.tint_lo).max(1) as u32;
    let palette = match &o.types {
        Some(t) => o.palette.muted(t.mute),
        None => o.palette.clone(),
    };
    let (shift, lut) = tint::table(&palette, span);
    p.tint_shift = shift;
    p.tint_len = lut.len() as u32;

    // Out-of-range red.
    if let Some((rlo, rhi)) = o.range {
        p.flags |= flags::RANGE;
        p.range_lo = quantize(rlo);
        p.range_hi = quantize(rhi);
        p.range_colour = pack(RANGE_COLOUR, 255);
    }

    // Contours.
    let interval = match o.contours {
        Contours::Off => None,
        Contours::Auto => contours::nice_interval(hi - lo).filter(|&i| i * UNITS_PER_M >= 1.0),
        Contours::Every(m) => Some(m),
    };
    if let Some(i) = interval {
        p.flags |= flags::CONTOURS;
        p.contour_interval = (i * UNITS_PER_M).round() as u32;
        p.contour_base = quantize(sea_level.unwrap_or(0.0));
        p.contour_index_every = contours::INDEX_EVERY;
        p.contour_colour = pack3(contours::CONTOUR_COLOUR);
        p.index_colour = pack3(contours::INDEX_COLOUR);
        p.contour_half_width = px256(contours::CONTOUR_HALF_WIDTH_PX);
        p.index_half_width = px256(contours::INDEX_HALF_WIDTH_PX);
        p.contour_min_spacing = px256(contours::MIN_SPACING_PX);
    }

    // Grid.
    let grid_px = match o.grid {
        Grid::Off => None,
        Grid::Cells(n) => Some((n * sx, n * sy)),
        Grid::Metres(m) => Some((m / cell_x, m / cell_y)),
    };
    if let Some((gx, gy)) = grid_px {
        if gx.min(gy) < MIN_GRID_PX {
            return Err(RenderError::Option {
                option: "grid",
                value: grid_text(o.grid),
                allowed: format!(
                    "lines at least {MIN_GRID_PX} px apart; at this preview size they would be {:.2} px apart",
                    gx.min(gy)
                ),
            });
        }
        p.flags |= flags::GRID;
        p.grid_step_x = px256(gx.min(1e6));
        p.grid_step_y = px256(gy.min(1e6));
        p.grid_colour = pack3(GRID_COLOUR);
    }

    // Types.
    let (types, type_colours) = match &o.types {
        Some(t) => {
            p.flags |= flags::TYPES;
            let m = &t.mask;
            let idx = preview_size::nearest(&m.indices, m.width, m.height, ow, oh);
            let packed = idx
                .chunks(4)
                .map(|c| {
                    let mut b = [shade::NO_TYPE as u8; 4];
                    b[..c.len()].copy_from_slice(c);
                    u32::from_le_bytes(b)
                })
                .collect();
            (
                packed,
                t.colours.iter().map(|&c| u32::from_le_bytes(c)).collect(),
            )
        }
        None => (Vec::new(), Vec::new()),
    };

    let info = RenderInfo {
        width: ow,
        height: oh,
        px_per_cell_x: sx,
        px_per_cell_y: sy,
        height_range_m: range,
        contour_interval_m: (p.flags & flags::CONTOURS != 0)
            .then(|| p.contour_interval as f64 / UNITS_PER_M),
        sea_level_m: sea_level,
        tint_range_m: (tlo, thi),
    };
    Ok(Prepared {
        params: p,
        heights,
        types,
        tint: lut,
        type_colours,
        info,
    })
}

/// Metres → kernel units, rounded, clamped to the kernel's height bound;
/// NaN → [`shade::NODATA`].
pub fn quantize(m: f64) -> i32 {
    if m.is_nan() {
        return shade::NODATA;
    }
    let lim = shade::MAX_ABS_HEIGHT as f64;
    (m * UNITS_PER_M).round().clamp(-lim, lim) as i32
}

fn grid_text(g: Grid) -> String {
    match g {
        Grid::Off => "off".into(),
        Grid::Cells(n) => format!("every {n} cells"),
        Grid::Metres(m) => format!("every {m} m"),
    }
}

/// Pixels → 1/256 pixel.
fn px256(px: f64) -> u32 {
    (px * 256.0).round() as u32
}

fn pack3(c: [u8; 4]) -> u32 {
    u32::from_le_bytes(c)
}

fn set_lights(p: &mut ShadeParams, l: &Lighting) {
    let one = shade::LIGHT_ONE as f64;
    for (slot, light) in p.lights.iter_mut().zip(&l.lights) {
        let (az, alt) = (
            light.azimuth_deg.to_radians(),
            light.altitude_deg.to_radians(),
        );
        // Towards the light: x east, y south, z up.
        *slot = [
            (alt.cos() * az.sin() * one).round() as i32,
            (-alt.cos() * az.cos() * one).round() as i32,
            (alt.sin() * one).round() as i32,
            (light.weight * 256.0).round() as i32,
        ];
    }
    p.light_count = l.lights.len().min(shade::MAX_LIGHTS) as u32;
    if l.aspect_weighted {
        p.flags |= flags::ASPECT_WEIGHTS;
    }
}

/// Horn sums (8 × mm per pixel) → slope in [`shade::SLOPE_ONE`] units along
/// one axis of `cell_m` metres: factor `f = exaggeration · 4096 / (8 · cell · 1000)`,
/// applied as `(s >> pre) · mul >> post` with `mul` in `[2^11, 2^12]`
/// (0.05 % precision) whenever `f < 2^11`. Returns `(mul, pre, post, clamp)`.
fn slope_scale(exaggeration: f64, cell_m: f64) -> Result<(i32, u32, u32, i32), RenderError> {
    let f = exaggeration * shade::SLOPE_ONE as f64 / (8.0 * cell_m * UNITS_PER_M);
    if !(f.is_finite() && f > 0.0 && f <= (1 << 24) as f64) {
        return Err(RenderError::Option {
            option: "exaggeration",
            value: format!("{exaggeration} at {cell_m} m cells"),
            allowed: "a vertical scale between 1e-9 and 16.7 million slope units per mm".into(),
        });
    }
    let total = (11.0 - f.log2()).ceil().max(0.0) as u32;
    let post = total.min(11);
    let pre = (total - post).min(30);
    let mul = (f * 2f64.powi((pre + post) as i32)).round().max(1.0) as i32;
    let sat = ((shade::MAX_SLOPE as i64) << post) / mul as i64 + 2;
    let clamp = sat.min((1i64 << 30) / mul as i64) as i32;
    Ok((mul, pre, post, clamp))
}

fn check_options(o: &RenderOptions) -> Result<(), RenderError> {
    let bad = |option: &'static str, value: String, allowed: &str| {
        Err(RenderError::Option {
            option,
            value,
            allowed: allowed.into(),
        })
    };
    if !(1..=super::MAX_PREVIEW_SIDE).contains(&o.max_size) {
        return bad("max_size", o.max_size.to_string(), "1..=16384 pixels");
    }
    if !(o.exaggeration.is_finite() && o.exaggeration > 0.0 && o.exaggeration <= 1000.0) {
        return bad(
            "exaggeration",
            o.exaggeration.to_string(),
            "a factor in (0, 1000]",
        );
    }
    if let Contours::Every(m) = o.contours
        && !(m.is_finite() && m * UNITS_PER_M >= 1.0 && m * UNITS_PER_M <= (1u64 << 27) as f64)
    {
        return bad(
            "contour interval",
            format!("{m} m"),
            "0.001 ..= 134217 metres",
        );
    }
    let finite_pair =
        |r: Option<(f64, f64)>| r.is_none_or(|(a, b)| a.is_finite() && b.is_finite() && a <= b);
    if !finite_pair(o.range) {
        return bad(
            "range",
            format!("{:?}", o.range),
            "finite MIN:MAX with MIN <= MAX",
        );
    }
    if !finite_pair(o.tint_range) || o.tint_range.is_some_and(|(a, b)| a == b) {
        return bad(
            "tint range",
            format!("{:?}", o.tint_range),
            "finite LO:HI with LO < HI",
        );
    }
    if let Sea::Level(s) = o.sea
        && !(s.is_finite() && s.abs() < 60_000.0)
    {
        return bad(
            "sea level",
            format!("{s} m"),
            "a finite level within ±60 km",
        );
    }
    match o.grid {
        Grid::Cells(v) | Grid::Metres(v) if !(v.is_finite() && v > 0.0) => {
            return bad("grid", grid_text(o.grid), "a positive spacing");
        }
        _ => {}
    }
    let l = &o.lighting;
    let light_ok = |x: &super::Light| {
        x.azimuth_deg.is_finite()
            && (0.0..=90.0).contains(&x.altitude_deg)
            && (0.0..=1.0).contains(&x.weight)
    };
    if l.lights.is_empty()
        || l.lights.len() > shade::MAX_LIGHTS
        || !l.lights.iter().all(light_ok)
        || l.lights.iter().all(|x| x.weight * 256.0 < 0.5)
    {
        return bad(
            "lights",
            format!("{:?}", l.lights),
            "1 to 4 lights, altitude 0..=90°, weight 0..=1, not all zero",
        );
    }
    if !((0.0..=1.0).contains(&l.shadow) && (0.0..=1.0).contains(&l.highlight)) {
        return bad(
            "shadow/highlight",
            format!("{} / {}", l.shadow, l.highlight),
            "each in 0..=1",
        );
    }
    Ok(())
}

fn check_types(hf: &Heightfield, t: &TypeOverlay) -> Result<(), RenderError> {
    if (t.mask.width, t.mask.height) != (hf.width(), hf.height()) {
        return Err(RenderError::TypesSize {
            mask_width: t.mask.width,
            mask_height: t.mask.height,
            width: hf.width(),
            height: hf.height(),
        });
    }
    Ok(())
}

impl ShadeParams {
    /// Everything zero (all features off) except the size.
    fn zeroed_with_size(width: u32, height: u32) -> ShadeParams {
        ShadeParams {
            width,
            height,
            ..bytemuck::Zeroable::zeroed()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_scale_is_precise_and_bounded() {
        for &(ex, cell) in &[
            (1.0, 92.6),
            (1.0, 0.01),
            (10.0, 1.0),
            (1.0, 5000.0),
            (0.001, 1e5),
        ] {
            let (mul, pre, post, clamp) = slope_scale(ex, cell).unwrap();
            let f = ex * 4096.0 / (8.0 * cell * 1000.0);
            let eff = mul as f64 / 2f64.powi((pre + post) as i32);
            assert!((eff / f - 1.0).abs() < 1e-3, "{ex} {cell}: {eff} vs {f}");
            assert!(post <= 11 && pre <= 30);
            assert!(clamp as i64 * mul as i64 <= 1 << 30);
            // The clamp never cuts a slope below the kernel's own limit.
            let top = ((clamp as i64) * mul as i64) >> post;
            assert!(
                top >= shade::MAX_SLOPE as i64
                    || clamp as i64 * mul as i64 >= (1 << 30) - mul as i64
            );
        }
        assert!(slope_scale(1.0, 1e-9).is_err());
    }

    #[test]
    fn quantize_rounds_and_clamps() {
        assert_eq!(quantize(1.2345), 1235);
        assert_eq!(quantize(-0.0004), 0);
        assert_eq!(quantize(1e9), shade::MAX_ABS_HEIGHT);
        assert_eq!(quantize(f64::NAN), shade::NODATA);
    }
}
