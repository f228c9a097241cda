//! Scene overlays on the preview (issue: "overlays on the preview: points,
//! curves, widgets, painted types, frozen regions"), so a person can check
//! a design against its controls at a glance.
//!
//! - painted types: the shade stage's type tint (lighter than its default
//!   so the relief stays readable) with each region outlined;
//! - frozen regions: a translucent white wash with a white outline;
//! - points: a ring at the radius of effect and a dot at the site;
//! - curves: the curve in black on a white halo, the smoothed reach
//!   envelope as a thin line, widgets as diamonds, junctions as squares;
//! - pastes: the pasted lasso, dashed-free outline, at its destination.

use super::{PasteSource, Scene, SceneEdits, SceneError};
use crate::heightfield::Heightfield;
use crate::io::maps::type_mask::{NO_TYPE, TypeMask};
use crate::render::{self, Marker, RenderOptions, TypeOverlay};
use image::{Rgba, RgbaImage};

const BLACK: Rgba<u8> = Rgba([20, 20, 20, 255]);
const HALO: Rgba<u8> = Rgba([255, 255, 255, 200]);
const ENVELOPE: Rgba<u8> = Rgba([20, 20, 20, 140]);
const WIDGET: Rgba<u8> = Rgba([255, 214, 10, 255]);
const JUNCTION: Rgba<u8> = Rgba([230, 60, 230, 255]);
const POINT: Rgba<u8> = Rgba([0, 200, 255, 255]);
const PASTE: Rgba<u8> = Rgba([255, 120, 0, 255]);

/// Opacity of painted types in the overlay (the renderer's default, 150,
/// hides the relief's shading).
pub const TYPE_OPACITY: u8 = 90;

/// Renders `hf` with the scene's controls drawn on top (`overlay` false:
/// the plain preview). `edits` must have converted `scene` (it holds the
/// built curves: smoothed shape, envelope, junctions).
pub fn preview(
    hf: &Heightfield,
    scene: &Scene,
    edits: &SceneEdits,
    type_names: &[String],
    overlay: bool,
) -> Result<RgbaImage, SceneError> {
    let render_err = |e: render::RenderError| SceneError::new(&scene.file, "$", e.into());
    let mut opts = RenderOptions::default();
    let types = if overlay {
        scene.type_raster(type_names)?
    } else {
        None
    };
    if let Some(t) = &types {
        let mut mask = TypeMask::new(scene.width, scene.height, t.clone())
            .expect("the raster has the scene's size, which parsing checked");
        mask.names = type_names
            .iter()
            .enumerate()
            .map(|(i, n)| (i as u8, n.clone()))
            .collect();
        let mut o = TypeOverlay::new(mask);
        for c in o.colours.iter_mut().take(NO_TYPE as usize) {
            c[3] = TYPE_OPACITY;
        }
        opts.types = Some(o);
    }
    let mut p = render::render(hf, &opts).map_err(render_err)?;
    if !overlay {
        return Ok(p.image);
    }
    let (w, h) = (scene.width, scene.height);
    let scale = p.info.px_per_cell_x.max(0.5);
    let mut cv = p.canvas();
    if let Some(t) = &types {
        for id in 0..NO_TYPE {
            let region: Vec<bool> = t.iter().map(|&v| v == id).collect();
            if region.iter().any(|&b| b) {
                let [r, g, b] = render::types::type_colour(id);
                cv.region(&region, w, h, None, Some(Rgba([r, g, b, 255])));
            }
        }
    }
    if let Some(f) = scene.freeze_raster()? {
        cv.region(
            &f,
            w,
            h,
            Some(Rgba([255, 255, 255, 70])),
            Some(Rgba([255, 255, 255, 255])),
        );
    }
    for paste in &scene.pastes {
        let c = super::polygon_centroid(&paste.lasso);
        let shift = paste.to - c;
        let pts: Vec<(f64, f64)> = paste
            .lasso
            .iter()
            .map(|q| (q.x + shift.x.round(), q.y + shift.y.round()))
            .collect();
        cv.polygon(&pts, None, Some((PASTE, 2.0)));
        if paste.source == PasteSource::Terrain {
            let src: Vec<(f64, f64)> = paste.lasso.iter().map(|q| (q.x, q.y)).collect();
            cv.polygon(&src, None, Some((Rgba([255, 120, 0, 120]), 1.0)));
        }
    }
    for (_, c) in edits.curves() {
        for lp in c.envelope() {
            let mut pts: Vec<(f64, f64)> = lp.iter().map(|q| (q.x, q.y)).collect();
            pts.push(pts[0]);
            cv.polyline(&pts, 1.0, ENVELOPE);
        }
        let pts: Vec<(f64, f64)> = c.points().iter().map(|q| (q.x, q.y)).collect();
        cv.polyline(&pts, 4.0, HALO);
        cv.polyline(&pts, 2.0, BLACK);
    }
    for (item, (_, c)) in scene.curves.iter().zip(edits.curves()) {
        for wd in &item.spec.widgets {
            let q = c.point_at(wd.at * c.length());
            cv.marker((q.x, q.y), Marker::Diamond, 11.0, BLACK);
            cv.marker((q.x, q.y), Marker::Diamond, 8.0, WIDGET);
        }
    }
    for j in edits.junctions() {
        cv.marker((j.at.x, j.at.y), Marker::Square, 11.0, JUNCTION);
    }
    for pt in &scene.points {
        let r = pt.radius_px;
        let ring: Vec<(f64, f64)> = (0..=64)
            .map(|k| {
                let a = k as f64 / 64.0 * std::f64::consts::TAU;
                (pt.at.x + r * a.cos(), pt.at.y + r * a.sin())
            })
            .collect();
        cv.polyline(&ring, 1.5, POINT);
        cv.point((pt.at.x, pt.at.y), 3.0 * scale.clamp(1.0, 2.0), BLACK);
        cv.point((pt.at.x, pt.at.y), 2.0 * scale.clamp(1.0, 2.0), POINT);
    }
    Ok(p.image)
}
