//! Pictures of several terrains side by side, for comparing a synthesis
//! with its exemplar at a glance: the same renderer, lighting and contour
//! interval rules, and one hypsometric tint range over all of them, so that
//! a colour means the same height in every panel.

use super::font::{GLYPH_HEIGHT, draw_text};
use super::{RenderError, RenderOptions, render};
use crate::heightfield::Heightfield;
use image::{Rgba, RgbaImage};

/// Gap between panels and around the labels, pixels.
const GAP: u32 = 8;
/// Label text scale (font pixels to image pixels).
const LABEL_SCALE: u32 = 2;

/// Renders each `(label, terrain)` with `opts` (its tint range replaced by
/// the union of the terrains' height ranges unless set), left to right on a
/// white background, each under its label.
pub fn side_by_side(
    panels: &[(&str, &Heightfield)],
    opts: &RenderOptions,
) -> Result<RgbaImage, RenderError> {
    let range =
        panels
            .iter()
            .filter_map(|(_, hf)| hf.stats())
            .fold(None, |acc: Option<(f64, f64)>, s| {
                let (lo, hi) = (s.min as f64, s.max as f64);
                Some(acc.map_or((lo, hi), |(a, b)| (a.min(lo), b.max(hi))))
            });
    let opts = RenderOptions {
        tint_range: opts.tint_range.or(range),
        ..opts.clone()
    };
    let images = panels
        .iter()
        .map(|(_, hf)| render(hf, &opts).map(|p| p.image))
        .collect::<Result<Vec<_>, _>>()?;
    let label_h = GLYPH_HEIGHT * LABEL_SCALE + 2 * GAP;
    let width = images.iter().map(|i| i.width() + GAP).sum::<u32>() + GAP;
    let height = images.iter().map(|i| i.height()).max().unwrap_or(0) + label_h + GAP;
    let mut out = RgbaImage::from_pixel(width, height, Rgba([255, 255, 255, 255]));
    let mut x = GAP;
    for ((label, _), img) in panels.iter().zip(&images) {
        draw_text(
            &mut out,
            x as i64,
            GAP as i64,
            label,
            LABEL_SCALE,
            Rgba([0, 0, 0, 255]),
        );
        image::imageops::overlay(&mut out, img, x as i64, label_h as i64);
        x += img.width() + GAP;
    }
    Ok(out)
}
