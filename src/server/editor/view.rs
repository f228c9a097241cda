//! What the page shows of a frame: the preview image (the `shade` stage:
//! hillshade, tint, contours, out-of-range red, painted types) and
//! the geometry the server computes for the controls (smoothed curves,
//! their envelopes of effect, widget positions, junctions), which the page
//! draws as handles over the image.
//!
//! The tint, contour interval and red range are fixed by the database's
//! height range, not taken from each frame, so an edit that raises one peak
//! does not recolour the whole map (a designer reads changes by colour).

use crate::backend::engine::Engine;
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::io::maps::type_mask::TypeMask;
use crate::render::{self, Contours, Grid, RenderOptions, Sea, TypeOverlay};
use crate::scene::SceneEdits;
use image::RgbaImage;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

/// Which layers the preview shows (the page's view toggles; the grid is
/// drawn by the page, crisp at any zoom).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct View {
    pub contours: bool,
    /// Painted types as colours over the relief.
    pub types: bool,
    /// Red where heights leave the exemplars' range (paper §3).
    pub range: bool,
}

impl Default for View {
    fn default() -> Self {
        View {
            contours: true,
            types: true,
            range: true,
        }
    }
}

/// Previews are at the terrain's resolution up to this side (the page
/// scales them); larger terrains are box-filtered down to it.
pub const PREVIEW_MAX: usize = 2048;

/// Render settings that stay the same for every frame of a database.
#[derive(Debug, Clone)]
pub struct Style {
    /// The exemplars' height range, metres.
    pub range: (f64, f64),
    pub contour_m: Option<f64>,
    pub type_names: Vec<String>,
}

impl Style {
    pub fn new(db: &Database) -> Style {
        let ex = &db.meta().exemplars;
        let lo = ex.iter().map(|e| e.min_m).fold(f64::INFINITY, f64::min);
        let hi = ex.iter().map(|e| e.max_m).fold(f64::NEG_INFINITY, f64::max);
        let range = if lo.is_finite() && hi.is_finite() && hi > lo {
            (lo, hi)
        } else {
            (0.0, 1.0)
        };
        Style {
            range,
            contour_m: render::contours::nice_interval(range.1 - range.0),
            type_names: db.type_names().to_vec(),
        }
    }

    /// Every setting but the type overlay depends only on the database
    /// and the view (nothing on the frame's own heights), and the `shade`
    /// stage reads a 3×3 neighbourhood: so a window rendered with a
    /// one-pixel margin has the full render's pixels inside (tested).
    fn options(&self, view: View) -> RenderOptions {
        RenderOptions {
            min_size: 1,
            max_size: PREVIEW_MAX,
            contours: match (view.contours, self.contour_m) {
                (true, Some(m)) => Contours::Every(m),
                _ => Contours::Off,
            },
            grid: Grid::Off,
            range: view.range.then_some(self.range),
            tint_range: Some(self.range),
            sea: if self.range.0 < 0.0 {
                Sea::Level(0.0)
            } else {
                Sea::Off
            },
            ..RenderOptions::default()
        }
    }

    fn overlay(&self, w: usize, h: usize, types: Vec<u8>) -> Result<TypeOverlay, String> {
        let mut mask = TypeMask::new(w, h, types).map_err(|e| e.to_string())?;
        mask.names = self
            .type_names
            .iter()
            .enumerate()
            .map(|(i, n)| (i as u8, n.clone()))
            .collect();
        let mut o = TypeOverlay::new(mask);
        // The tint stays where nothing is painted (issue 43: one stroke
        // greyed the whole map).
        o.mute = 0.0;
        for c in o
            .colours
            .iter_mut()
            .take(crate::io::maps::type_mask::NO_TYPE as usize)
        {
            c[3] = crate::scene::overlay::TYPE_OPACITY;
        }
        Ok(o)
    }

    /// Renders a whole preview, shaded on `engine`. `types` is the scene's
    /// painted type raster (database indices, 255 = none).
    pub fn render(
        &self,
        engine: &Engine,
        hf: &Heightfield,
        types: Option<&[u8]>,
        view: View,
    ) -> Result<RgbaImage, String> {
        let mut opts = self.options(view);
        if let (true, Some(t)) = (view.types, types) {
            opts.types = Some(self.overlay(hf.width(), hf.height(), t.to_vec())?);
        }
        Ok(render::render_on(engine, hf, &opts)
            .map_err(|e| e.to_string())?
            .image)
    }

    /// Re-renders `rect` (`[x0, y0, x1, y1)`, terrain pixels) of `image`, a
    /// preview of `hf` at its own resolution. False (nothing done) when the
    /// preview is scaled; then only [`Style::render`] is exact.
    pub fn render_window(
        &self,
        engine: &Engine,
        hf: &Heightfield,
        types: Option<&[u8]>,
        view: View,
        image: &mut RgbaImage,
        rect: [usize; 4],
    ) -> Result<bool, String> {
        let (w, h) = (hf.width(), hf.height());
        if (image.width() as usize, image.height() as usize) != (w, h) || w.max(h) > PREVIEW_MAX {
            return Ok(false);
        }
        let [x0, y0, x1, y1] = [rect[0], rect[1], rect[2].min(w), rect[3].min(h)];
        if x0 >= x1 || y0 >= y1 {
            return Ok(true);
        }
        // One pixel of margin where the window is not at the edge.
        let (cx0, cy0) = (x0.saturating_sub(1), y0.saturating_sub(1));
        let (cx1, cy1) = ((x1 + 1).min(w), (y1 + 1).min(h));
        let (cw, ch) = (cx1 - cx0, cy1 - cy0);
        let crop = hf.crop(cx0, cy0, cw, ch).map_err(|e| e.to_string())?;
        let mut opts = self.options(view);
        if let (true, Some(t)) = (view.types, types) {
            let sub: Vec<u8> = (cy0..cy1)
                .flat_map(|y| t[y * w + cx0..y * w + cx1].iter().copied())
                .collect();
            opts.types = Some(self.overlay(cw, ch, sub)?);
        }
        let part = render::render_on(engine, &crop, &opts)
            .map_err(|e| e.to_string())?
            .image;
        for y in y0..y1 {
            for x in x0..x1 {
                let px = *part.get_pixel((x - cx0) as u32, (y - cy0) as u32);
                image.put_pixel(x as u32, y as u32, px);
            }
        }
        Ok(true)
    }
}

/// The PNG of `rect` of an image.
pub fn encode_rect(image: &RgbaImage, rect: [usize; 4]) -> Result<Vec<u8>, String> {
    let [x0, y0, x1, y1] = rect;
    let sub = image::imageops::crop_imm(
        image,
        x0 as u32,
        y0 as u32,
        (x1 - x0) as u32,
        (y1 - y0) as u32,
    )
    .to_image();
    render::encode_png(&sub).map_err(|e| e.to_string())
}

/// One decimal place is plenty for pixels on screen and keeps replies small.
fn r1(v: f64) -> f64 {
    (v * 10.0).round() / 10.0
}

/// A polyline for the page, thinned to about one point per `step` pixels.
fn polyline(pts: &[glam::DVec2], step: usize) -> Value {
    let n = pts.len();
    let out: Vec<[f64; 2]> = pts
        .iter()
        .enumerate()
        .filter(|(i, _)| i % step == 0 || *i + 1 == n)
        .map(|(_, p)| [r1(p.x), r1(p.y)])
        .collect();
    json!(out)
}

/// The controls' geometry as the server built it: per curve (by id) its
/// smoothed line, envelope of effect and widget positions with the unit
/// left normal there; the junctions with their height and curves.
pub fn overlay(edits: &SceneEdits, scene: &crate::scene::Scene) -> Value {
    let curves: Vec<Value> = edits
        .curves()
        .iter()
        .zip(&scene.curves)
        .map(|((id, c), item)| {
            let len = c.length();
            let widgets: Vec<Value> = item
                .spec
                .widgets
                .iter()
                .map(|w| {
                    let s = w.at * len;
                    let p = c.point_at(s);
                    let d = c.point_at((s + 1.0).min(len)) - c.point_at((s - 1.0).max(0.0));
                    // Left of a walker on the map (y down): (x, y) → (y, −x).
                    let n = glam::DVec2::new(d.y, -d.x).normalize_or_zero();
                    json!({"at": [r1(p.x), r1(p.y)], "left": [r1(n.x * 1e3) / 1e3, r1(n.y * 1e3) / 1e3]})
                })
                .collect();
            json!({
                "id": id,
                "length_px": r1(len),
                "line": polyline(c.points(), 2),
                "envelope": c.envelope().iter().map(|l| polyline(l, 2)).collect::<Vec<_>>(),
                "widgets": widgets,
            })
        })
        .collect();
    let junctions: Vec<Value> = edits
        .junctions()
        .iter()
        .map(|j| {
            let ids: Vec<&str> = j
                .members
                .iter()
                .filter_map(|(k, _)| scene.curves.get(*k).map(|c| c.id.as_str()))
                .collect();
            json!({"at": [r1(j.at.x), r1(j.at.y)], "height_m": r1(j.height_m), "curves": ids})
        })
        .collect();
    json!({"curves": curves, "junctions": junctions})
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A window re-rendered into a preview gives the bytes of rendering the
    /// whole terrain again.
    #[test]
    fn a_window_renders_like_the_whole() {
        let (w, h) = (97, 64);
        let hf = Heightfield::from_fn(w, h, 30.0, |x, y| {
            (400.0 + 300.0 * ((x as f64 * 0.21).sin() * (y as f64 * 0.13).cos()) + 3.0 * x as f64)
                as f32
        })
        .unwrap();
        let style = Style {
            range: (100.0, 900.0),
            contour_m: Some(50.0),
            type_names: vec!["a".into(), "b".into()],
        };
        let types: Vec<u8> = (0..w * h)
            .map(|k| {
                if k % w > 60 {
                    1
                } else if k % 7 == 0 {
                    0
                } else {
                    255
                }
            })
            .collect();
        let view = View::default();
        let mut bumped = hf.clone();
        for y in 10..30 {
            for x in 20..50 {
                bumped.set(x, y, bumped.get(x, y) + 40.0 + x as f32);
            }
        }
        let cpu = Engine::default();
        let whole = style.render(&cpu, &bumped, Some(&types), view).unwrap();
        let mut patched = style.render(&cpu, &hf, Some(&types), view).unwrap();
        assert_ne!(whole, patched);
        // The changed heights grown by the shade stage's one-pixel reach,
        // then a window at the edge.
        for rect in [[19, 9, 51, 31], [0, 0, w, 5]] {
            let ok = style
                .render_window(&cpu, &bumped, Some(&types), view, &mut patched, rect)
                .unwrap();
            assert!(
                ok && whole == patched,
                "window {rect:?} differs from a full render"
            );
        }
    }
}
