//! Height constraints of a scene: point constraints, curve constraints
//! with their widgets, and junction heights (paper §3).

use super::*;
use crate::synth::control::curve::{MAX_REACH_PX, MAX_SLOPE_DEG, Widget};

/// `"points"`: the point constraints; their ids join `ids`.
pub(super) fn points(
    r: &Reader,
    m: &Map<String, Value>,
    (fw, fh): (f64, f64),
    ids: &mut Vec<String>,
) -> R<Vec<PointSpec>> {
    let mut points = Vec::new();
    if let Some(v) = m.get("points") {
        for (i, p) in r
            .array(v, "points", 0, "point constraints")?
            .iter()
            .enumerate()
        {
            let path = format!("points[{i}]");
            let o = r.object(
                p,
                &path,
                &[
                    "id",
                    "at",
                    "height_m",
                    "slope_deg",
                    "slope_direction_deg",
                    "radius_px",
                ],
            )?;
            let id = r.id(o, &path, path.clone(), ids)?;
            let at = r.xy(
                r.required(o, &path, "at", "[x, y] in pixels")?,
                &join(&path, "at"),
                (fw, fh),
            )?;
            let height_m = r.height(
                r.required(o, &path, "height_m", "a height in metres")?,
                &join(&path, "height_m"),
            )?;
            let slope_deg = match o.get("slope_deg") {
                Some(v) => r.number(
                    v,
                    &join(&path, "slope_deg"),
                    0.0,
                    80.0,
                    false,
                    "0..=80 degrees",
                )?,
                None => 0.0,
            };
            let slope_direction_deg = match o.get("slope_direction_deg") {
                Some(v) => r.number(
                    v,
                    &join(&path, "slope_direction_deg"),
                    -360.0,
                    360.0,
                    false,
                    "-360..=360 degrees",
                )?,
                None => 0.0,
            };
            let radius_px = r.number(
                r.required(o, &path, "radius_px", "a radius in pixels")?,
                &join(&path, "radius_px"),
                0.0,
                MAX_REACH_PX,
                true,
                "0 < radius <= 4096 pixels",
            )?;
            points.push(PointSpec {
                id,
                at,
                height_m,
                slope_deg,
                slope_direction_deg,
                radius_px,
            });
        }
    }
    Ok(points)
}

/// `"curves"`: the curve constraints and their widgets; their ids join `ids`.
pub(super) fn curves(
    r: &Reader,
    m: &Map<String, Value>,
    (fw, fh): (f64, f64),
    ids: &mut Vec<String>,
) -> R<Vec<CurveItem>> {
    let mut curves = Vec::new();
    if let Some(v) = m.get("curves") {
        for (i, c) in r
            .array(v, "curves", 0, "curve constraints")?
            .iter()
            .enumerate()
        {
            let path = format!("curves[{i}]");
            let o = r.object(c, &path, &["id", "points", "smoothing", "widgets"])?;
            let id = r.id(o, &path, path.clone(), ids)?;
            let pp = join(&path, "points");
            let pts = r.array(
                r.required(o, &path, "points", "an array of >= 2 [x, y] points")?,
                &pp,
                2,
                "[x, y] points",
            )?;
            let points = pts
                .iter()
                .enumerate()
                .map(|(k, p)| r.xy(p, &format!("{pp}[{k}]"), (fw, fh)))
                .collect::<R<Vec<_>>>()?;
            let smoothing = match o.get("smoothing") {
                Some(v) => r.integer(v, &join(&path, "smoothing"), 8)? as u32,
                None => 2,
            };
            let wp = join(&path, "widgets");
            let ws = r.array(
                r.required(o, &path, "widgets", "an array of >= 1 widgets")?,
                &wp,
                1,
                "widgets",
            )?;
            let mut widgets = Vec::with_capacity(ws.len());
            for (k, w) in ws.iter().enumerate() {
                let path = format!("{wp}[{k}]");
                let o = r.object(w, &path, &["at", "height_m", "slope_deg", "reach_px"])?;
                let at = r.number(
                    r.required(o, &path, "at", "a fraction of the arc length")?,
                    &join(&path, "at"),
                    0.0,
                    1.0,
                    false,
                    "0..=1 (fraction of the curve's arc length)",
                )?;
                let height_m = r.height(
                    r.required(o, &path, "height_m", "a height in metres")?,
                    &join(&path, "height_m"),
                )?;
                let slope_deg = r.pair(
                    r.required(o, &path, "slope_deg", "[left, right] slopes in degrees")?,
                    &join(&path, "slope_deg"),
                    -MAX_SLOPE_DEG,
                    MAX_SLOPE_DEG,
                    false,
                    "-85..=85 degrees",
                )?;
                let reach_px = r.pair(
                    r.required(o, &path, "reach_px", "[left, right] reaches in pixels")?,
                    &join(&path, "reach_px"),
                    0.0,
                    MAX_REACH_PX,
                    true,
                    "0 < reach <= 4096 pixels",
                )?;
                widgets.push(Widget {
                    at,
                    height_m,
                    slope_deg,
                    reach_px,
                });
            }
            if points.windows(2).all(|w| w[0] == w[1]) {
                return Err(r.invalid(
                    &pp,
                    o.get("points").expect("checked"),
                    "points that are not all the same (a curve needs length)",
                ));
            }
            curves.push(CurveItem {
                id,
                spec: CurveSpec {
                    points,
                    widgets,
                    smoothing,
                },
            });
        }
    }
    Ok(curves)
}

/// `"junctions"`: heights set on automatic curve junctions.
pub(super) fn junctions(
    r: &Reader,
    m: &Map<String, Value>,
    (fw, fh): (f64, f64),
) -> R<Vec<JunctionHeight>> {
    let mut junctions = Vec::new();
    if let Some(v) = m.get("junctions") {
        for (i, j) in r
            .array(v, "junctions", 0, "junction heights")?
            .iter()
            .enumerate()
        {
            let path = format!("junctions[{i}]");
            let o = r.object(j, &path, &["at", "height_m"])?;
            let at = r.xy(
                r.required(o, &path, "at", "[x, y] in pixels")?,
                &join(&path, "at"),
                (fw, fh),
            )?;
            let height_m = r.height(
                r.required(o, &path, "height_m", "a height in metres")?,
                &join(&path, "height_m"),
            )?;
            junctions.push(JunctionHeight { at, height_m });
        }
    }
    Ok(junctions)
}
