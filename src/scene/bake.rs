//! Baking a sculpt stroke into target heights ([`bake`]): what each brush
//! asks of the terrain it is painted on, as a low-frequency grid. Here and
//! not beside the strokes in `synth::control::sculpt` because the erode
//! brush runs [`crate::erode`], which sits above the synthesis.
//!
//! Every brush starts from the **base**: the target of the strokes below
//! where one covers a node (so two raise strokes add up exactly), else the
//! terrain's heights averaged over a Gaussian of σ = step/2 (the grid's own
//! resolution: the detail under the stroke is the synthesis's to make
//! again, not the target's). The stroke's weight w (1 inside
//! `radius·(1 − falloff)`, a smoothstep down to 0 at the radius) blends the
//! base towards each brush's aim:
//!
//! - **raise / lower**: base ± strength (metres) · w;
//! - **flatten**: towards the base height under the stroke's first point,
//!   by strength (0–1) · w;
//! - **smooth**: towards the base blurred with σ = radius/2, by strength ·
//!   w;
//! - **erode**: towards the terrain eroded by [`crate::erode`] (at
//!   [`ERODE_FILTER_STRENGTH`]) under the same Gaussian, by strength · w;
//!   its grid is finer (radius/16, at least 2 px), since the valleys
//!   erosion cuts are narrow.

use crate::heightfield::Heightfield;
use crate::synth::cone::Rect;
use crate::synth::control::sculpt::brush::{Brush, BrushStroke, MAX_BAKED_NODES};
use crate::synth::control::sculpt::{SculptLayer, TargetGrid, capsule_bounds, polyline_distance};
use glam::DVec2;

/// The erosion filter's strength behind the erode brush (its own 0–10
/// scale; the brush's strength blends towards the result).
pub const ERODE_FILTER_STRENGTH: f32 = 4.0;

/// The node spacing of a stroke's grid: its brush's
/// [`Brush::step`], widened so the grid has at most [`MAX_BAKED_NODES`].
pub fn grid_step(stroke: &BrushStroke) -> f64 {
    let [bx0, by0, bx1, by1] = capsule_bounds(&stroke.points, stroke.radius_px);
    let area = (bx1 - bx0 + 2.0) * (by1 - by0 + 2.0);
    (stroke.brush.step(stroke.radius_px)).max((area / MAX_BAKED_NODES).sqrt().ceil())
}

/// The Gaussian-weighted mean of `hf` around output position `p` (σ in
/// pixels; pixels within 2σ, at least the 3×3 around it; edges clamped).
fn gauss(hf: &Heightfield, p: DVec2, sigma: f64) -> f64 {
    let reach = (2.0 * sigma).max(1.5);
    let (cx, cy) = (p.x - 0.5, p.y - 0.5);
    let (x0, x1) = ((cx - reach).ceil() as i64, (cx + reach).floor() as i64);
    let (y0, y1) = ((cy - reach).ceil() as i64, (cy + reach).floor() as i64);
    let (mut s, mut ws) = (0.0, 0.0);
    for y in y0..=y1 {
        for x in x0..=x1 {
            let d2 = (x as f64 - cx).powi(2) + (y as f64 - cy).powi(2);
            let w = (-d2 / (2.0 * sigma * sigma)).exp();
            s += w * f64::from(hf.get_clamped(x as isize, y as isize));
            ws += w;
        }
    }
    s / ws
}

/// Blurs a `w`×`h` grid with a Gaussian of σ nodes (window 2σ, weights
/// renormalized at the edges).
fn blur(v: &[f64], w: usize, h: usize, sigma: f64) -> Vec<f64> {
    let k = (2.0 * sigma).ceil() as i64;
    let weights: Vec<f64> = (-k..=k)
        .map(|d| (-(d * d) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let pass = |v: &[f64], along_x: bool| -> Vec<f64> {
        let mut out = vec![0.0; v.len()];
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let (mut s, mut ws) = (0.0, 0.0);
                for (i, d) in (-k..=k).enumerate() {
                    let (u, t) = if along_x { (x + d, y) } else { (x, y + d) };
                    if u >= 0 && t >= 0 && u < w as i64 && t < h as i64 {
                        s += weights[i] * v[t as usize * w + u as usize];
                        ws += weights[i];
                    }
                }
                out[y as usize * w + x as usize] = s / ws;
            }
        }
        out
    };
    pass(&pass(v, true), false)
}

/// The target grid of `stroke` painted on `terrain`, over the strokes of
/// `below`. Deterministic (fixed order f64; heights rounded to 1 cm, the
/// precision a scene stores).
pub fn bake(
    stroke: &BrushStroke,
    terrain: &Heightfield,
    below: Option<&SculptLayer>,
) -> TargetGrid {
    let [bx0, by0, bx1, by1] = capsule_bounds(&stroke.points, stroke.radius_px);
    let step = grid_step(stroke);
    // Smoothing reads the base beyond the stroke: a margin of nodes.
    let margin = match stroke.brush {
        Brush::Smooth => (stroke.radius_px / step).ceil() as usize,
        _ => 0,
    };
    let (x0, y0) = (bx0.floor(), by0.floor());
    let width = ((bx1 - x0) / step).ceil() as usize + 1;
    let height = ((by1 - y0) / step).ceil() as usize + 1;
    let (ew, eh) = (width + 2 * margin, height + 2 * margin);
    let node = |i: usize, j: usize| {
        DVec2::new(
            x0 + (i as f64 - margin as f64) * step,
            y0 + (j as f64 - margin as f64) * step,
        )
    };
    // (At most 8 px: a grid widened for a huge stroke would otherwise
    // average thousands of pixels per node.)
    let sigma = (step / 2.0).min(8.0);
    let base_at = |p: DVec2| {
        below
            .and_then(|l| l.target(p.x, p.y))
            .unwrap_or_else(|| gauss(terrain, p, sigma))
    };
    let base: Vec<f64> = (0..ew * eh)
        .map(|k| base_at(node(k % ew, k / ew)))
        .collect();
    let aim: Vec<f64> = match stroke.brush {
        Brush::Raise => base.iter().map(|b| b + stroke.strength).collect(),
        Brush::Lower => base.iter().map(|b| b - stroke.strength).collect(),
        Brush::Flatten => vec![base_at(stroke.points[0]); base.len()],
        Brush::Smooth => blur(&base, ew, eh, stroke.radius_px / 2.0 / step),
        Brush::Erode => erode_aim(stroke, terrain, &base, ew, &node, sigma),
    };
    let share = match stroke.brush.strength_in_metres() {
        true => 1.0,
        false => stroke.strength,
    };
    let mut heights_m = Vec::with_capacity(width * height);
    for j in margin..margin + height {
        for i in margin..margin + width {
            let k = j * ew + i;
            let w = share * stroke.weight(polyline_distance(&stroke.points, node(i, j)));
            let v = base[k] + w * (aim[k] - base[k]);
            heights_m.push((v * 100.0).round() / 100.0);
        }
    }
    TargetGrid {
        x0,
        y0,
        step,
        width,
        height,
        heights_m,
    }
}

/// The erode brush's aim at every node: the base moved by what erosion
/// does to the terrain under the stroke's Gaussian.
fn erode_aim(
    stroke: &BrushStroke,
    terrain: &Heightfield,
    base: &[f64],
    width: usize,
    node: &dyn Fn(usize, usize) -> DVec2,
    sigma: f64,
) -> Vec<f64> {
    let world = (terrain.width(), terrain.height());
    let [bx0, by0, bx1, by1] = capsule_bounds(&stroke.points, stroke.radius_px);
    let clip = |v: f64, n: usize| (v.max(0.0) as usize).min(n);
    let (x0, y0) = (
        clip(bx0.floor() - 2.0, world.0),
        clip(by0.floor() - 2.0, world.1),
    );
    let (x1, y1) = (
        clip(bx1.ceil() + 2.0, world.0),
        clip(by1.ceil() + 2.0, world.1),
    );
    if x1 <= x0 || y1 <= y0 {
        return base.to_vec();
    }
    let window = Rect::new(x0, y0, x1 - x0, y1 - y0);
    let extent = crate::erode::extent(world, window);
    let crop = |r: Rect| {
        terrain
            .crop(r.x0, r.y0, r.width(), r.height())
            .expect("inside the terrain")
    };
    let Ok(eroded) = crate::erode::window(&crop(extent), extent, window, ERODE_FILTER_STRENGTH)
    else {
        // Nodata under the stroke: nothing to erode.
        return base.to_vec();
    };
    let original = crop(window);
    let shift = DVec2::new(x0 as f64, y0 as f64);
    base.iter()
        .enumerate()
        .map(|(k, b)| {
            let p = node(k % width, k / width) - shift;
            b + gauss(&eroded, p, sigma) - gauss(&original, p, sigma)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brushes_aim_where_they_say() {
        let hf = Heightfield::from_fn(64, 64, 30.0, |x, _| x as f32).unwrap();
        let s = |brush, strength| BrushStroke {
            brush,
            points: vec![DVec2::new(32.0, 32.0)],
            radius_px: 16.0,
            strength,
            falloff: 0.5,
        };
        let raised = bake(&s(Brush::Raise, 100.0), &hf, None);
        assert!((raised.at(32.0, 32.0) - (31.5 + 100.0)).abs() < 0.6);
        assert!(
            (raised.at(16.0, 32.0) - 15.5).abs() < 1.0,
            "no change at the rim"
        );
        let flat = bake(&s(Brush::Flatten, 1.0), &hf, None);
        assert!((flat.at(26.0, 32.0) - flat.at(38.0, 32.0)).abs() < 0.5);
        assert_eq!(bake(&s(Brush::Smooth, 1.0), &hf, None).width, raised.width);
        // A stroke across a huge world stays a grid a document can carry.
        let mut huge = s(Brush::Raise, 10.0);
        huge.points = vec![DVec2::new(0.0, 0.0), DVec2::new(60000.0, 60000.0)];
        huge.radius_px = 4096.0;
        let step = grid_step(&huge);
        let side = ((60000.0 + 2.0 * 4096.0) / step).ceil() + 1.0;
        assert!(
            step > 16.0 && side * side <= MAX_BAKED_NODES * 1.01,
            "{step} {side}"
        );
        for b in Brush::ALL {
            assert_eq!(Brush::from_name(b.name()), Some(b));
        }
    }
}
