//! Sizing the preview for a person: large grids are box-filtered down to the
//! size limit, tiny ones enlarged by a whole factor with Catmull-Rom cubic
//! heights (bilinear heights have a gradient that jumps at every cell edge,
//! which a hillshade turns into a visible block pattern; the cubic passes
//! through the samples with a continuous gradient).
//! Both work on heights *before* shading, so slopes and contours are computed
//! at the resolution that is shown (shading first and shrinking after would
//! alias the light and break contour lines).

use rayon::prelude::*;
use std::borrow::Cow;

/// The preview's size for a `width × height` grid: the long side is brought
/// to at most `max_size` (uniform scale, rounded, each side ≥ 1), or, when it
/// is below `min_size`, multiplied by the smallest whole factor reaching it
/// without exceeding `max_size`.
pub fn fit(width: usize, height: usize, min_size: usize, max_size: usize) -> (usize, usize) {
    let long = width.max(height);
    if long > max_size {
        let s = max_size as f64 / long as f64;
        let side = |n: usize| ((n as f64 * s).round() as usize).clamp(1, max_size);
        (side(width), side(height))
    } else if long < min_size {
        let k = min_size.div_ceil(long).min(max_size / long).max(1);
        (width * k, height * k)
    } else {
        (width, height)
    }
}

/// Resamples row-major heights (NaN = nodata) from `w × h` to `ow × oh`,
/// one axis at a time: each axis is area-averaged when it shrinks,
/// Catmull-Rom interpolated (sample centres aligned, edges replicated) when
/// it grows.
///
/// Nodata rule, per pass: an output sample is the weighted mean of the valid
/// input samples under its filter, or nodata when they carry less than half
/// of the filter's weight — so holes neither grow nor shrink noticeably.
/// (The cubic's negative lobes make this approximate next to holes; the
/// result stays a weighted mean of nearby valid samples.) At the same size,
/// the samples themselves.
pub fn heights(data: &[f32], w: usize, h: usize, ow: usize, oh: usize) -> Cow<'_, [f32]> {
    if (w, h) == (ow, oh) {
        return Cow::Borrowed(data);
    }
    let tx = taps(w, ow);
    let ty = taps(h, oh);
    // Along x: every row independently.
    let mut mid = vec![0f32; ow * h];
    mid.par_chunks_mut(ow).enumerate().for_each(|(y, out)| {
        let row = &data[y * w..(y + 1) * w];
        for (o, t) in out.iter_mut().zip(&tx) {
            *o = apply(t, |i| row[i]);
        }
    });
    // Along y: every output row gathers from the rows its taps name.
    let mut out = vec![0f32; ow * oh];
    out.par_chunks_mut(ow).zip(&ty).for_each(|(row, t)| {
        for (x, o) in row.iter_mut().enumerate() {
            *o = apply(t, |i| mid[i * ow + x]);
        }
    });
    Cow::Owned(out)
}

/// Nearest-neighbour resampling of an index map (type masks: indices must
/// not be averaged). Output sample centres map to input positions.
pub fn nearest(data: &[u8], w: usize, h: usize, ow: usize, oh: usize) -> Vec<u8> {
    let src = |o: usize, n: usize, on: usize| (((2 * o + 1) * n) / (2 * on)).min(n - 1);
    let xs: Vec<usize> = (0..ow).map(|x| src(x, w, ow)).collect();
    let mut out = Vec::with_capacity(ow * oh);
    for y in 0..oh {
        let row = &data[src(y, h, oh) * w..][..w];
        out.extend(xs.iter().map(|&x| row[x]));
    }
    out
}

/// One output sample's filter: input indices with weights summing to 1.
type Taps = Vec<(usize, f32)>;

fn taps(n: usize, on: usize) -> Vec<Taps> {
    let scale = n as f64 / on as f64;
    (0..on)
        .map(|o| {
            if on < n {
                // Area average over [o·scale, (o+1)·scale).
                let (a, b) = (o as f64 * scale, (o + 1) as f64 * scale);
                let first = a.floor() as usize;
                let last = (b.ceil() as usize).min(n);
                (first..last)
                    .map(|i| {
                        let cover = (b.min(i as f64 + 1.0) - a.max(i as f64)).max(0.0);
                        (i, (cover / scale) as f32)
                    })
                    .filter(|&(_, wt)| wt > 0.0)
                    .collect()
            } else if on > n {
                // Catmull-Rom through the four nearest centres; positions
                // beyond the outer centres clamp, indices replicate the edge.
                let x = ((o as f64 + 0.5) * scale - 0.5).clamp(0.0, (n - 1) as f64);
                let i = x.floor() as i64;
                let f = x - i as f64;
                let (f2, f3) = (f * f, f * f * f);
                let w = [
                    (-f3 + 2.0 * f2 - f) / 2.0,
                    (3.0 * f3 - 5.0 * f2 + 2.0) / 2.0,
                    (-3.0 * f3 + 4.0 * f2 + f) / 2.0,
                    (f3 - f2) / 2.0,
                ];
                let mut taps: Taps = Vec::with_capacity(4);
                for (k, wk) in w.into_iter().enumerate() {
                    let idx = (i + k as i64 - 1).clamp(0, n as i64 - 1) as usize;
                    match taps.iter_mut().find(|t| t.0 == idx) {
                        Some(t) => t.1 += wk as f32,
                        None => taps.push((idx, wk as f32)),
                    }
                }
                taps.retain(|t| t.1 != 0.0);
                taps
            } else {
                vec![(o, 1.0)]
            }
        })
        .collect()
}

fn apply(taps: &[(usize, f32)], get: impl Fn(usize) -> f32) -> f32 {
    let (mut sum, mut weight) = (0f32, 0f32);
    for &(i, wt) in taps {
        let v = get(i);
        if !v.is_nan() {
            sum += v * wt;
            weight += wt;
        }
    }
    if weight >= 0.5 {
        sum / weight
    } else {
        f32::NAN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_shrinks_grows_and_keeps_aspect() {
        assert_eq!(fit(4096, 2048, 512, 2048), (2048, 1024));
        assert_eq!(fit(3, 2049, 512, 2048), (3, 2048));
        assert_eq!(fit(100, 50, 512, 2048), (600, 300));
        assert_eq!(fit(1, 1, 512, 2048), (512, 512));
        assert_eq!(fit(1, 3000, 512, 2048), (1, 2048));
        assert_eq!(fit(800, 800, 512, 2048), (800, 800));
    }

    #[test]
    fn box_average_and_nodata_rule() {
        let d = [1.0, 3.0, 5.0, 7.0];
        assert_eq!(heights(&d, 4, 1, 2, 1), vec![2.0, 6.0]);
        let d = [1.0, f32::NAN, f32::NAN, f32::NAN];
        let out = heights(&d, 4, 1, 2, 1);
        assert_eq!(out[0], 1.0);
        assert!(out[1].is_nan());
        // 3 → 2: the middle sample is split between both outputs.
        let out = heights(&[0.0, 3.0, 6.0], 3, 1, 2, 1);
        assert_eq!(out, vec![1.0, 5.0]);
    }

    #[test]
    fn cubic_growth_passes_through_samples_and_keeps_ramps() {
        // ×4 along a ramp: away from the edges the cubic is exactly linear.
        let ramp: Vec<f32> = (0..8).map(|i| i as f32 * 2.0).collect();
        let out = heights(&ramp, 8, 1, 32, 1);
        for (o, v) in out.iter().enumerate().take(26).skip(6) {
            let x = (o as f32 + 0.5) / 4.0 - 0.5;
            assert!((v - 2.0 * x).abs() < 1e-4, "{o}: {v}");
        }
        // Constants stay constant, the ends are the end samples.
        let out = heights(&[2.0], 1, 1, 3, 3);
        assert!(out.iter().all(|&v| v == 2.0));
        let out = heights(&[1.0, 5.0, 3.0], 3, 1, 9, 1);
        assert_eq!((out[0], out[4], out[8]), (1.0, 5.0, 3.0));
    }

    #[test]
    fn nearest_picks_centres() {
        assert_eq!(nearest(&[1, 2], 2, 1, 4, 1), vec![1, 1, 2, 2]);
        assert_eq!(nearest(&[1, 2, 3, 4], 4, 1, 2, 1), vec![2, 4]);
    }
}
