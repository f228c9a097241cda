//! The picture of `terrasynth water --preview`: the preview renderer's
//! hillshade and tint (no contours, which would read as shorelines), lakes
//! and sea in blue, rivers drawn wider and darker with their Strahler
//! order.

use super::Water;
use super::lakes::{LAKE, SEA};
use crate::heightfield::Heightfield;
use crate::render::{self, Contours, RenderError, RenderOptions, Sea};
use image::{Rgba, RgbaImage};

const LAKE_BLUE: Rgba<u8> = Rgba([70, 130, 215, 235]);
const SEA_BLUE: Rgba<u8> = Rgba([45, 95, 180, 235]);

/// River colour and width (preview pixels per cell of the preview scale)
/// by Strahler order: order 1 thin and light, each order darker and wider.
fn river_style(order: u8, px_per_cell: f64) -> (Rgba<u8>, f64) {
    let o = order.clamp(1, 8) as f64;
    let shade = |lo: f64, hi: f64| (lo + (hi - lo) * (o - 1.0) / 7.0) as u8;
    let width = (0.6 + 0.45 * o) * px_per_cell.clamp(0.5, 2.0);
    (
        Rgba([
            shade(90.0, 10.0),
            shade(150.0, 50.0),
            shade(235.0, 160.0),
            255,
        ]),
        width,
    )
}

impl Water {
    /// Renders `hf` (the heightfield this was computed from) with the water
    /// on it; `max_size` bounds the longer side in pixels.
    pub fn preview(&self, hf: &Heightfield, max_size: usize) -> Result<RgbaImage, RenderError> {
        let opts = RenderOptions {
            max_size,
            contours: Contours::Off,
            sea: Sea::Off,
            ..RenderOptions::default()
        };
        let mut p = render::render(hf, &opts)?;
        let scale = p.info.px_per_cell_x;
        let (w, h) = (self.width, self.height);
        let class = &self.bodies.class;
        let mut canvas = p.canvas();
        for (which, colour) in [(SEA, SEA_BLUE), (LAKE, LAKE_BLUE)] {
            let mask: Vec<bool> = class.iter().map(|&c| c == which).collect();
            if mask.contains(&true) {
                canvas.region(&mask, w, h, Some(colour), None);
            }
        }
        // Low orders first, so the main rivers lie on top.
        let mut segments: Vec<_> = self.rivers.segments.iter().collect();
        segments.sort_by_key(|s| s.order);
        for s in segments {
            let pts: Vec<(f64, f64)> = s
                .cells
                .iter()
                .map(|&i| ((i as usize % w) as f64 + 0.5, (i as usize / w) as f64 + 0.5))
                .collect();
            let (colour, width) = river_style(s.order, scale);
            canvas.polyline(&pts, width, colour);
        }
        Ok(p.image)
    }
}
