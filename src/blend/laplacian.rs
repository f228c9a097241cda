//! Multi-resolution (Laplacian-pyramid) blending, seed 002 §7.4.2 after Burt
//! & Adelson: decompose source and destination into Laplacian pyramids and
//! the mask into a Gaussian pyramid, lerp each band with its mask level, and
//! collapse. Fine detail is blended over a short distance, coarse shape over
//! a long one. `band_gain[l]` (default 1) scales how much of band `l` of the
//! source is taken (Fig. 7.10: 0 for the coarse bands copies detail only).
//!
//! Down-sampling is a 2×2 box mean and up-sampling bilinear; any size works
//! (odd sides are handled by clamping).

use super::Inputs;
use crate::resample::bilinear;

fn down(w: usize, h: usize, v: &[f32]) -> (usize, usize, Vec<f32>) {
    let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
    let mut out = vec![0.0f32; cw * ch];
    for y in 0..ch {
        for x in 0..cw {
            let mut s = 0.0f32;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (px, py) = ((2 * x + dx).min(w - 1), (2 * y + dy).min(h - 1));
                s += v[py * w + px];
            }
            out[y * cw + x] = s * 0.25;
        }
    }
    (cw, ch, out)
}

fn up(cw: usize, ch: usize, v: &[f32], w: usize, h: usize) -> Vec<f32> {
    let mut out = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let p = [(x as f32 + 0.5) / 2.0, (y as f32 + 0.5) / 2.0];
            out[y * w + x] = bilinear(v, cw, ch, p);
        }
    }
    out
}

/// Blends `src` into `dst` in place over `levels` pyramid levels (at least 1;
/// levels beyond the 1×1 top are ignored).
pub fn blend(inputs: Inputs<'_>, levels: usize, band_gain: Option<&[f32]>) {
    let Inputs {
        width,
        height,
        dst,
        src,
        mask,
    } = inputs;
    // Gaussian pyramids of all three.
    let mut g_d = vec![(width, height, dst.to_vec())];
    let mut g_s = vec![(width, height, src.to_vec())];
    let mut g_m = vec![(width, height, mask.to_vec())];
    while g_d.len() < levels.max(1) {
        let (w, h, _) = g_d[g_d.len() - 1];
        if w == 1 && h == 1 {
            break;
        }
        for g in [&mut g_d, &mut g_s, &mut g_m] {
            let (w, h, v) = g.last().expect("pyramid has a base");
            let next = down(*w, *h, v);
            g.push(next);
        }
    }
    let top = g_d.len() - 1;
    let gain = |l: usize| band_gain.and_then(|g| g.get(l)).copied().unwrap_or(1.0);
    // Collapse from the top: start with the blended coarsest Gaussian level.
    let (mut cw, mut ch, _) = g_d[top];
    let mut acc: Vec<f32> = (0..cw * ch)
        .map(|i| {
            let m = g_m[top].2[i] * gain(top);
            g_d[top].2[i] * (1.0 - m) + g_s[top].2[i] * m
        })
        .collect();
    for l in (0..top).rev() {
        let (w, h, _) = g_d[l];
        let ud = up(cw, ch, &g_d[l + 1].2, w, h);
        let us = up(cw, ch, &g_s[l + 1].2, w, h);
        let mut next = up(cw, ch, &acc, w, h);
        for i in 0..w * h {
            let (ld, ls) = (g_d[l].2[i] - ud[i], g_s[l].2[i] - us[i]);
            let m = g_m[l].2[i] * gain(l);
            next[i] += ld * (1.0 - m) + ls * m;
        }
        acc = next;
        (cw, ch) = (w, h);
    }
    dst.copy_from_slice(&acc);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_of_zero_and_one_reproduce_the_inputs() {
        let (w, h) = (37, 21);
        let d: Vec<f32> = (0..w * h).map(|i| ((i * 7) % 13) as f32).collect();
        let s: Vec<f32> = (0..w * h).map(|i| ((i * 5) % 11) as f32 * 3.0).collect();
        let mut out = d.clone();
        blend(
            Inputs::new(w, h, &mut out, &s, &vec![0.0; w * h]).unwrap(),
            5,
            None,
        );
        assert!(out.iter().zip(&d).all(|(a, b)| (a - b).abs() < 1e-3));
        let mut out = d.clone();
        blend(
            Inputs::new(w, h, &mut out, &s, &vec![1.0; w * h]).unwrap(),
            5,
            None,
        );
        assert!(out.iter().zip(&s).all(|(a, b)| (a - b).abs() < 1e-3));
    }

    #[test]
    fn a_hard_mask_edge_becomes_a_gradual_transition_in_the_coarse_band() {
        // dst = 0, src = 100, mask = left half: the step is spread out.
        let (w, h) = (64, 8);
        let mask: Vec<f32> = (0..w * h)
            .map(|i| if i % w < 32 { 1.0 } else { 0.0 })
            .collect();
        let mut out = vec![0.0f32; w * h];
        let src = vec![100.0; w * h];
        blend(Inputs::new(w, h, &mut out, &src, &mask).unwrap(), 6, None);
        let row = &out[..w];
        let max_step = row
            .windows(2)
            .map(|p| (p[0] - p[1]).abs())
            .fold(0.0, f32::max);
        assert!(max_step < 50.0, "largest step {max_step}");
        assert!(
            row[0] > 90.0 && row[w - 1] < 10.0,
            "{} {}",
            row[0],
            row[w - 1]
        );
    }
}
