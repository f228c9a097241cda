//! The output's broad shape (stage 6 of the pipeline): the drift the
//! merges add is removed and the sketch's broad shape added, both through
//! a prefix-sum box blur.

use crate::patch::place::candidates;
use rayon::prelude::*;

/// The sketch's height profile deforms the merged terrain (seed 004 §4.1:
/// Tasse et al. use the sketched height profile "to deform the terrain
/// after it has undergone merging and matching"): a broad version of the
/// sketch field (three box passes of radius patch/2, so it only moves whole
/// ridges and valleys, never the detail) scaled to `amount` × the
/// synthesized 2–98 % relief is added. Patches put ridges *where* the
/// sketch says; this makes them stand *higher* than their surroundings at
/// the scale of the whole terrain, which the gradient-domain merge alone
/// does not control.
pub fn deform_by_sketch(
    heights: &mut [f32],
    field: &[f32],
    w: usize,
    h: usize,
    patch: usize,
    amount: f32,
) {
    if amount <= 0.0 {
        return;
    }
    let mut broad = field.to_vec();
    for _ in 0..3 {
        broad = box_blur(&broad, w, h, (patch / 2).max(1));
    }
    let peak = broad.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    if peak <= 0.0 {
        return;
    }
    let amp = candidates::relief(heights) * amount / peak;
    for (v, b) in heights.iter_mut().zip(&broad) {
        *v += amp * b;
    }
}

/// Removes what the merge adds at scales far above a patch: the broad
/// component (three box passes of radius 2·patch, about a Gaussian of
/// σ = 2·patch) minus its mean. Each gradient-domain merge keeps its
/// patch's slopes and only pins it to its neighbours along the seam, so
/// the tilts that fill patches keep from their sources (and the slope
/// residues of feature patches after [`detrend`]) add up along the
/// placement order into a random walk of height across the output: with many
/// sources, half of a sketched circle came out a kilometre above the other
/// half as one smooth snowy mass, and the λ inside it was lost in that
/// tilt. Ridges and valleys are narrower than this scale and stay; the
/// broad shape is the sketch's to give ([`deform_by_sketch`]).
///
/// [`detrend`]: crate::patch::detrend
pub fn remove_drift(heights: &mut [f32], w: usize, h: usize, patch: usize) {
    let mut broad = heights.to_vec();
    for _ in 0..3 {
        broad = box_blur(&broad, w, h, (2 * patch).max(1));
    }
    let mean = broad.iter().map(|&v| v as f64).sum::<f64>() / broad.len().max(1) as f64;
    for (v, b) in heights.iter_mut().zip(&broad) {
        *v -= b - mean as f32;
    }
}

pub(crate) fn box_blur(v: &[f32], w: usize, h: usize, r: usize) -> Vec<f32> {
    let pass = |src: &[f32], w: usize, h: usize| -> Vec<f32> {
        // Horizontal box of radius r with clamped ends, then transpose. Each
        // row's prefix sums (f64, so the differences stay exact enough) make
        // a box O(1) per pixel: the drift removal's radius of two patches
        // summed 257 samples per pixel and pass otherwise.
        let mut out = vec![0.0f32; w * h];
        let prefix: Vec<Vec<f64>> = src
            .par_chunks(w)
            .map(|row| {
                let mut p = Vec::with_capacity(w + 1);
                p.push(0.0f64);
                let mut acc = 0.0f64;
                for &v in row {
                    acc += v as f64;
                    p.push(acc);
                }
                p
            })
            .collect();
        out.par_chunks_mut(h).enumerate().for_each(|(x, col)| {
            let (lo, hi) = (x.saturating_sub(r), (x + r).min(w - 1));
            for (o, p) in col.iter_mut().zip(&prefix) {
                *o = ((p[hi + 1] - p[lo]) / (hi - lo + 1) as f64) as f32;
            }
        });
        out
    };
    let t = pass(v, w, h);
    pass(&t, h, w)
}
