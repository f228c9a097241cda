//! A picture of a coordinates map (paper Fig. 3): red = x and green = y
//! within the source exemplar, blue = which exemplar, each stretched over
//! 0..=255. Smooth gradients are patches copied whole; confetti is pixels
//! drawn from everywhere. Unmapped pixels are black.

use crate::io::maps::coords_map::{CoordsMap, NO_EXEMPLAR};
use image::{Rgba, RgbaImage};

/// The picture of `map`, given each exemplar's (width, height) in
/// database order.
pub fn coords_preview(map: &CoordsMap, exemplars: &[(u32, u32)]) -> RgbaImage {
    let n = exemplars.len().max(2) as u32 - 1;
    RgbaImage::from_fn(map.width as u32, map.height as u32, |x, y| {
        let s = map.sources[y as usize * map.width + x as usize];
        match exemplars.get(s.exemplar as usize) {
            Some(&(w, h)) if s.exemplar != NO_EXEMPLAR => Rgba([
                (s.x as u32 * 255 / w.max(1)).min(255) as u8,
                (s.y as u32 * 255 / h.max(1)).min(255) as u8,
                (s.exemplar as u32 * 255 / n) as u8,
                255,
            ]),
            _ => Rgba([0, 0, 0, 255]),
        }
    })
}
