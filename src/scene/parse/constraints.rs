//! Height constraints of a scene: point constraints, curve constraints
//! with their widgets, and junction heights (paper §3).

use super::*;
use crate::synth::control::curve::{MAX_REACH_PX, MAX_SLOPE_DEG, Widget};

/// `"points"`: the point constraints; their ids join `ids`.
pub(super) fn points(d: &Doc, ids: &mut Vec<String>) -> R<Vec<PointSpec>> {
    let r = d.r;
    d.items(
        "points",
        "point constraints",
        &[
            "id",
            "at",
            "height_m",
            "slope_deg",
            "slope_direction_deg",
            "radius_px",
        ],
        |path, o| {
            let id = r.id(o, path, path.to_string(), ids)?;
            let (at, height_m) = d.height_at(o, path)?;
            let slope_deg = r.number_or(
                o,
                path,
                "slope_deg",
                Range::closed(0.0, 80.0, "0..=80 degrees"),
                0.0,
            )?;
            let slope_direction_deg = r.number_or(
                o,
                path,
                "slope_direction_deg",
                Range::closed(-360.0, 360.0, "-360..=360 degrees"),
                0.0,
            )?;
            let (v, vp) = r.field(o, path, "radius_px", "a radius in pixels")?;
            let radius_px = r.number(
                v,
                &vp,
                Range::above(0.0, MAX_REACH_PX, "0 < radius <= 4096 pixels"),
            )?;
            Ok(PointSpec {
                id,
                at,
                height_m,
                slope_deg,
                slope_direction_deg,
                radius_px,
            })
        },
    )
}

/// `"curves"`: the curve constraints and their widgets; their ids join `ids`.
pub(super) fn curves(d: &Doc, ids: &mut Vec<String>) -> R<Vec<CurveItem>> {
    let r = d.r;
    d.items(
        "curves",
        "curve constraints",
        &["id", "points", "smoothing", "widgets"],
        |path, o| {
            let id = r.id(o, path, path.to_string(), ids)?;
            let points = r.points(
                o,
                path,
                "points",
                2,
                "an array of >= 2 [x, y] points",
                d.size,
            )?;
            let smoothing = match o.get("smoothing") {
                Some(v) => r.integer(v, &join(path, "smoothing"), 8)? as u32,
                None => 2,
            };
            let (v, vp) = r.field(o, path, "widgets", "an array of >= 1 widgets")?;
            let widgets = r.items(
                Some(v),
                &vp,
                1,
                "widgets",
                &["at", "height_m", "slope_deg", "reach_px"],
                |path, o| {
                    let (v, vp) = r.field(o, path, "at", "a fraction of the arc length")?;
                    let at = r.number(
                        v,
                        &vp,
                        Range::closed(0.0, 1.0, "0..=1 (fraction of the curve's arc length)"),
                    )?;
                    let (v, vp) = r.field(o, path, "height_m", "a height in metres")?;
                    let height_m = r.height(v, &vp)?;
                    let (v, vp) =
                        r.field(o, path, "slope_deg", "[left, right] slopes in degrees")?;
                    let slope_deg = r.pair(
                        v,
                        &vp,
                        Range::closed(-MAX_SLOPE_DEG, MAX_SLOPE_DEG, "-85..=85 degrees"),
                    )?;
                    let (v, vp) =
                        r.field(o, path, "reach_px", "[left, right] reaches in pixels")?;
                    let reach_px = r.pair(
                        v,
                        &vp,
                        Range::above(0.0, MAX_REACH_PX, "0 < reach <= 4096 pixels"),
                    )?;
                    Ok(Widget {
                        at,
                        height_m,
                        slope_deg,
                        reach_px,
                    })
                },
            )?;
            if points.windows(2).all(|w| w[0] == w[1]) {
                return Err(r.invalid(
                    &join(path, "points"),
                    o.get("points").expect("checked"),
                    "points that are not all the same (a curve needs length)",
                ));
            }
            Ok(CurveItem {
                id,
                spec: CurveSpec {
                    points,
                    widgets,
                    smoothing,
                },
            })
        },
    )
}

/// `"junctions"`: heights set on automatic curve junctions.
pub(super) fn junctions(d: &Doc) -> R<Vec<JunctionHeight>> {
    d.items(
        "junctions",
        "junction heights",
        &["at", "height_m"],
        |path, o| {
            let (at, height_m) = d.height_at(o, path)?;
            Ok(JunctionHeight { at, height_m })
        },
    )
}
