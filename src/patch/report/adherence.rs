//! Feature adherence (issue 7), a measure of a result against its sketch,
//! not a stage of the synthesis.

use crate::Heightfield;
use crate::patch::input::sketch::{self, Kind, Sketch};

/// Feature adherence (issue 7): mean output height within `radius` of the
/// sketched ridge strokes minus that near the valley strokes, divided by the
/// output's relief (max − min). A sketch with only ridges (Zhou's λ) is
/// measured against the background instead: pixels farther than
/// `4 · radius` from every stroke. `None` without ridge strokes.
pub fn adherence(hf: &Heightfield, sketch: &Sketch, radius: f32) -> Option<f64> {
    let (w, h) = (hf.width(), hf.height());
    let stats = hf.stats()?;
    let relief = (stats.max - stats.min) as f64;
    let mean = |m: &[bool]| {
        let (s, k) = m
            .iter()
            .zip(hf.data())
            .filter(|(m, _)| **m)
            .fold((0.0f64, 0usize), |(s, k), (_, &v)| (s + v as f64, k + 1));
        if k == 0 { None } else { Some(s / k as f64) }
    };
    let ridge = mean(&sketch::stroke_mask(sketch, Kind::Ridge, w, h, radius))?;
    let low = match mean(&sketch::stroke_mask(sketch, Kind::Valley, w, h, radius)) {
        Some(v) => v,
        None => {
            let near = sketch::stroke_mask(sketch, Kind::Ridge, w, h, 4.0 * radius);
            let far: Vec<bool> = near.iter().map(|n| !n).collect();
            mean(&far)?
        }
    };
    Some((ridge - low) / relief.max(1e-9))
}
