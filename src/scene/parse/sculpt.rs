//! `"sculpt"`: sculpt brush strokes and the target grids baked from them.

use super::*;
use crate::synth::control::sculpt::{Brush, BrushStroke, TargetGrid};

/// Most nodes one stroke's target grid may have.
const MAX_NODES: usize = 1_000_000;

pub(super) fn sculpt(d: &Doc) -> R<Vec<SculptSpec>> {
    let r = d.r;
    let keys = [
        "brush",
        "points",
        "radius_px",
        "strength",
        "falloff",
        "targets",
    ];
    d.items("sculpt", "sculpt strokes", &keys, |path, o| {
        let names = "\"raise\", \"lower\", \"smooth\", \"flatten\" or \"erode\"";
        let (bv, bp) = r.field(o, path, "brush", "a brush name")?;
        let brush = bv
            .as_str()
            .and_then(Brush::from_name)
            .ok_or_else(|| r.invalid(&bp, bv, names))?;
        let s = r.stroke(o, path, d.size)?;
        let (sv, sp) = r.field(o, path, "strength", "the brush's strength")?;
        let strength = match brush.strength_in_metres() {
            true => r.number(
                sv,
                &sp,
                Range::above(0.0, MAX_ABS_HEIGHT_M, "0 < strength <= 20000 m"),
            )?,
            false => r.number(sv, &sp, Range::above(0.0, 1.0, "0 < strength <= 1"))?,
        };
        let falloff = r.number_or(o, path, "falloff", Range::closed(0.0, 1.0, "0..=1"), 0.5)?;
        let targets = match o.get("targets") {
            Some(v) => Some(grid(r, v, &join(path, "targets"))?),
            None => None,
        };
        Ok(SculptSpec {
            stroke: BrushStroke {
                brush,
                points: s.points,
                radius_px: s.radius_px,
                strength,
                falloff,
            },
            targets,
        })
    })
}

fn grid(r: &Reader, v: &Value, path: &str) -> R<TargetGrid> {
    let o = r.object(v, path, &["at", "step_px", "size", "heights_m"])?;
    let (av, ap) = r.field(o, path, "at", "[x, y] of node (0, 0) in pixels")?;
    let within = Range::closed(-70000.0, 70000.0, "-70000..=70000 pixels");
    let at = match av.as_array().map(|a| a.as_slice()) {
        Some([x, y]) => [
            r.number(x, &format!("{ap}[0]"), within)?,
            r.number(y, &format!("{ap}[1]"), within)?,
        ],
        _ => return Err(r.invalid(&ap, av, "[x, y] in pixels")),
    };
    let (v, vp) = r.field(o, path, "step_px", "the node spacing in pixels")?;
    let step = r.number(v, &vp, Range::above(0.0, 256.0, "0 < step <= 256 pixels"))?;
    let (sv, sp) = r.field(o, path, "size", "[nodes across, nodes down]")?;
    let nodes = |v: &Value| v.as_u64().filter(|&n| n >= 1).map(|n| n as usize);
    let size = match sv.as_array().map(|a| a.as_slice()) {
        Some([w, h]) => nodes(w).zip(nodes(h)),
        _ => None,
    }
    .filter(|(w, h)| w.saturating_mul(*h) <= MAX_NODES)
    .ok_or_else(|| r.invalid(&sp, sv, "[w, h], each >= 1, w·h <= 1000000"))?;
    let (hv, hp) = r.field(o, path, "heights_m", "the node heights in metres")?;
    let heights = match hv.as_array() {
        Some(a) if a.len() == size.0 * size.1 => a,
        _ => {
            let n = size.0 * size.1;
            return Err(r.invalid(
                &hp,
                hv,
                format!("an array of size[0]·size[1] = {n} heights"),
            ));
        }
    };
    let heights_m = heights
        .iter()
        .enumerate()
        .map(|(k, h)| r.height(h, &format!("{hp}[{k}]")))
        .collect::<R<Vec<f64>>>()?;
    Ok(TargetGrid {
        x0: at[0],
        y0: at[1],
        step,
        width: size.0,
        height: size.1,
        heights_m,
    })
}
