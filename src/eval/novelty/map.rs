//! The copy map: where a synthesis is its exemplar, at a glance.

use super::Novelty;
use crate::heightfield::Heightfield;
use crate::render::font::{GLYPH_HEIGHT, draw_text};
use crate::render::{RenderError, RenderOptions, render};
use image::{Rgba, RgbaImage};

/// Copied windows: filled and outlined red.
const COPY: Rgba<u8> = Rgba([220, 30, 30, 255]);
const COPY_FILL: Rgba<u8> = Rgba([220, 30, 30, 80]);
/// Scored windows that are not copies: a faint white outline.
const NEW: Rgba<u8> = Rgba([255, 255, 255, 110]);

/// The synthesis's preview (hillshade, tint, contours) with every scored
/// window of `n` drawn on it — copies filled red, the others outlined in
/// white, flat windows left bare — under a caption with the share.
pub fn copy_map(synth: &Heightfield, n: &Novelty, title: &str) -> Result<RgbaImage, RenderError> {
    let opts = RenderOptions {
        max_size: 1536,
        ..Default::default()
    };
    let mut preview = render(synth, &opts)?;
    let side = n.params.window as f64;
    {
        let mut canvas = preview.canvas();
        for w in &n.windows {
            let (x0, y0) = (w.x as f64, w.y as f64);
            let square = [
                (x0, y0),
                (x0 + side, y0),
                (x0 + side, y0 + side),
                (x0, y0 + side),
            ];
            if n.is_copy(w) {
                canvas.polygon(&square, Some(COPY_FILL), Some((COPY, 2.0)));
            } else {
                canvas.polygon(&square, None, Some((NEW, 1.0)));
            }
        }
    }
    let figures = format!(
        "copies {:.0}% of {} windows (NCC >= {}), median NCC {:.3}",
        n.share * 100.0,
        n.scored,
        n.params.threshold,
        n.median_ncc
    );
    const SCALE: u32 = 2;
    let line = GLYPH_HEIGHT * SCALE + 6;
    let band = 2 * line + 6;
    let img = &preview.image;
    let mut out = RgbaImage::from_pixel(img.width(), img.height() + band, Rgba([255; 4]));
    for (k, text) in [title, figures.as_str()].into_iter().enumerate() {
        let y = 6 + (k as u32 * line) as i64;
        draw_text(&mut out, 6, y, text, SCALE, Rgba([0, 0, 0, 255]));
    }
    image::imageops::overlay(&mut out, img, 0, i64::from(band));
    Ok(out)
}
