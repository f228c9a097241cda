//! The masks people expect next to a heightfield, to texture and populate
//! it in an engine or a GIS: slope, flow accumulation, a terrain-type map
//! and an optional RGBA splat map. All are 8-bit images of the
//! heightfield's size, rows north to south like it.
//!
//! - **slope**: degrees from the steepest of the central differences
//!   (Horn's 3×3 would smooth more; central differences keep single-cell
//!   gullies), `value = round(degrees × 255 / 90)`;
//! - **flow accumulation**: `water`'s ([`crate::water::route`]): D8 on
//!   the depression-filled surface with flats resolved, so flow crosses
//!   pits and lakes instead of stopping in them; edge cells drain into the
//!   grid like any other.
//!   `value = round(255 × ln(cells) / ln(all cells))`, so a single cell is
//!   0 and a river draining the whole grid 255;
//! - **types**: [`crate::procedural::types::TypeClassification::classify`] (ridge,
//!   slope, valley floor, plateau, cliff), the local classes of the
//!   procedural styles' masks (the embedded database's masks are regional
//!   — sea, flat, hills, mountains — and come with its DEMs);
//! - **splat** (RGBA, weights summing to 255): R grass on gentle ground,
//!   G rock on slopes above 30° (fully at 45°), B snow on the top 15 % of
//!   the relief where not rock, A wet ground where flow accumulation is in
//!   its top quarter.
//!
//! For a game engine (`masks --for`), the masks are those of the heightmap
//! as `convert --for` writes it ([`crate::io::engine`]), and the splat map
//! takes the engine's form: Unreal paints weight-blended layers from one
//! 8-bit weightmap per layer at the heightmap's size ([`splat_layers`]);
//! Unity's splat (control) texture has one texel per terrain *cell*, a
//! power of two where the heightmap has 2ⁿ + 1 vertices ([`splat_cells`]).

use crate::heightfield::Heightfield;
use crate::water::{self, WaterError};
use rayon::prelude::*;

/// Slope in degrees, per cell.
pub fn slope_degrees(hf: &Heightfield) -> Vec<f32> {
    let (w, h, c) = (hf.width(), hf.height(), hf.cell_size() as f32);
    let mut out = vec![0.0f32; w * h];
    out.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let (xi, yi) = (x as isize, y as isize);
            // One-sided at the border (the span shrinks to one cell).
            let (x0, x1) = ((xi - 1).max(0), (xi + 1).min(w as isize - 1));
            let (y0, y1) = ((yi - 1).max(0), (yi + 1).min(h as isize - 1));
            let dx =
                (hf.get_clamped(x1, yi) - hf.get_clamped(x0, yi)) / (c * (x1 - x0).max(1) as f32);
            let dy =
                (hf.get_clamped(xi, y1) - hf.get_clamped(xi, y0)) / (c * (y1 - y0).max(1) as f32);
            let g = (dx * dx + dy * dy).sqrt();
            *o = if g.is_finite() {
                g.atan().to_degrees()
            } else {
                0.0
            };
        }
    });
    out
}

/// The masks of one heightfield, as 8-bit samples (RGBA for `splat`).
pub struct Masks {
    pub slope: Vec<u8>,
    pub flow: Vec<u8>,
    pub splat: Option<Vec<[u8; 4]>>,
}

/// Computes slope, flow and (when asked) splat masks; flow needs every
/// height (no nodata).
pub fn compute(hf: &Heightfield, splat: bool) -> Result<Masks, WaterError> {
    let slope = slope_degrees(hf);
    let acc = water::route(hf)?.accumulation;
    let log_all = ((hf.len() as f32).ln()).max(f32::MIN_POSITIVE);
    let flow_f: Vec<f32> = acc.iter().map(|&a| (a as f32).ln() / log_all).collect();
    let to_u8 = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    let splat = splat.then(|| {
        let s = hf.stats();
        let (lo, hi) = s.map_or((0.0, 0.0), |s| (s.min, s.max));
        let snow_line = hi - 0.15 * (hi - lo);
        slope
            .iter()
            .zip(&flow_f)
            .zip(hf.data())
            .map(|((&sl, &fl), &z)| {
                let rock = ((sl - 30.0) / 15.0).clamp(0.0, 1.0);
                let snow = if hi > lo && z >= snow_line {
                    1.0 - rock
                } else {
                    0.0
                };
                let wet = ((fl - 0.75) / 0.25).clamp(0.0, 1.0) * (1.0 - rock) * (1.0 - snow);
                let grass = (1.0 - rock - snow - wet).max(0.0);
                // Integer weights that sum to exactly 255.
                let r = (grass * 255.0).round() as u8;
                let g = (rock * 255.0).round().min(255.0 - r as f32) as u8;
                let b = (snow * 255.0).round().min(255.0 - r as f32 - g as f32) as u8;
                [r, g, b, 255 - r - g - b]
            })
            .collect()
    });
    Ok(Masks {
        slope: slope.iter().map(|&d| to_u8(d / 90.0)).collect(),
        flow: flow_f.iter().map(|&f| to_u8(f)).collect(),
        splat,
    })
}

/// The splat map's layers, in channel order (R, G, B, A).
pub const SPLAT_LAYERS: [&str; 4] = ["grass", "rock", "snow", "wet"];

/// The splat map as one 8-bit weightmap per layer ([`SPLAT_LAYERS`]
/// order), for engines that import layers separately (Unreal).
pub fn splat_layers(splat: &[[u8; 4]]) -> [Vec<u8>; 4] {
    std::array::from_fn(|c| splat.iter().map(|p| p[c]).collect())
}

/// The splat map of a `w × h` grid of vertices as the `(w − 1) × (h − 1)`
/// cells between them: each cell the mean of its four corners, R, G and B
/// rounded down and A taking the rest, so every cell still sums to 255.
pub fn splat_cells(splat: &[[u8; 4]], w: usize, h: usize) -> Vec<[u8; 4]> {
    let (cw, ch) = (w.saturating_sub(1), h.saturating_sub(1));
    (0..cw * ch)
        .map(|k| {
            let (x, y) = (k % cw, k / cw);
            let corners = [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)];
            let mean = |c: usize| {
                let s: u32 = corners
                    .iter()
                    .map(|&(i, j)| u32::from(splat[j * w + i][c]))
                    .sum();
                (s / 4) as u8
            };
            let (r, g, b) = (mean(0), mean(1), mean(2));
            [r, g, b, 255 - r - g - b]
        })
        .collect()
}

/// An 8-bit PNG of `channels` samples per pixel (1 grey, 3 RGB, 4 RGBA).
pub fn encode_png8(width: usize, height: usize, channels: usize, data: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width as u32, height as u32);
    enc.set_color(match channels {
        4 => png::ColorType::Rgba,
        3 => png::ColorType::Rgb,
        _ => png::ColorType::Grayscale,
    });
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc
        .write_header()
        .expect("writing a PNG header to memory cannot fail");
    writer
        .write_image_data(data)
        .expect("the buffer has width × height × channels bytes");
    drop(writer);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slope_of_a_plane_and_flow_down_a_valley() {
        // A 45° ramp: rise of one cell per cell.
        let ramp = Heightfield::from_fn(8, 8, 2.0, |x, _| 2.0 * x as f32).unwrap();
        for d in slope_degrees(&ramp) {
            assert!((d - 45.0).abs() < 1e-4, "{d}");
        }
        // A V valley draining south: column 4 collects everything.
        let v = Heightfield::from_fn(9, 10, 1.0, |x, y| {
            (x as f32 - 4.0).abs() * 2.0 + (9 - y) as f32 * 0.1
        })
        .unwrap();
        let acc = water::route(&v).unwrap().accumulation;
        assert_eq!(acc[9 * 9 + 4], 90, "the outlet drains the whole grid");
        assert_eq!(acc[0], 1, "a corner receives nothing");
        let m = compute(&v, true).unwrap();
        assert_eq!(m.flow[9 * 9 + 4], 255);
        assert_eq!(m.flow[0], 0);
        for p in m.splat.unwrap() {
            assert_eq!(p.iter().map(|&c| c as u32).sum::<u32>(), 255);
        }
    }

    #[test]
    fn splat_layers_and_cells_keep_every_weight() {
        let s = vec![
            [255, 0, 0, 0],
            [0, 255, 0, 0],
            [0, 0, 128, 127],
            [85, 85, 85, 0],
        ];
        let l = splat_layers(&s);
        assert_eq!(l[1], [0, 255, 0, 85]);
        assert_eq!(l[3], [0, 0, 127, 0]);
        // One cell between four vertices: their means, A the remainder.
        let c = splat_cells(&s, 2, 2);
        assert_eq!(c, [[85, 85, 53, 32]]);
        // A uniform splat is its own cell map.
        let u = vec![[10, 20, 30, 195]; 12];
        assert_eq!(splat_cells(&u, 4, 3), vec![[10, 20, 30, 195]; 6]);
    }
}
