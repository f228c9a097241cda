//! The pipeline of one pixel ([`shade_pixel`], steps 1 to 5 of the module
//! docs) and the parallel loop over the image ([`shade`]); the light and
//! the lines it draws live in their own files.

use super::arith::{alpha256, apply_shade, blend, shr_round, shr_sym};
use super::hillshade;
use super::lines::{Gradient, contour, line_coverage, nearest_level, on_grid, straddles};
use super::{FULL, MAX_SLOPE, NO_TYPE, NODATA, ParamsError, ShadeBuffers, ShadeParams, flags};
use crate::level::fixed::div_floor;
use rayon::prelude::*;

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
        nearest_level(p, div_floor(sum, 16)).filter(|l| straddles(lo, hi, l.level))
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
