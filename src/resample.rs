//! Resampling heightfields to a new grid with a tent filter whose support
//! grows with the reduction factor: bilinear interpolation when enlarging,
//! an area-weighted average when reducing (so shrinking never aliases ridges
//! into stair-steps). Nodata samples carry no weight; an output sample whose
//! whole support is nodata stays nodata.

use crate::heightfield::Heightfield;
use crate::size::SizeError;
use rayon::prelude::*;

/// Weights of one output sample along one axis: (first source index, weights).
fn taps(src: usize, dst: usize) -> Vec<(usize, Vec<f32>)> {
    let scale = src as f64 / dst as f64;
    let support = scale.max(1.0);
    (0..dst)
        .map(|i| {
            let centre = (i as f64 + 0.5) * scale - 0.5;
            let lo = (centre - support).floor().max(0.0) as usize;
            let hi = ((centre + support).ceil() as usize).min(src - 1);
            let w: Vec<f32> = (lo..=hi)
                .map(|j| (1.0 - (j as f64 - centre).abs() / support).max(0.0) as f32)
                .collect();
            (lo, w)
        })
        .collect()
}

fn apply(data: &[f32], stride: usize, (lo, w): &(usize, Vec<f32>)) -> f32 {
    let (mut s, mut ws) = (0.0f64, 0.0f64);
    for (k, &wk) in w.iter().enumerate() {
        let v = data[(lo + k) * stride];
        if wk > 0.0 && !v.is_nan() {
            s += wk as f64 * v as f64;
            ws += wk as f64;
        }
    }
    if ws > 0.0 { (s / ws) as f32 } else { f32::NAN }
}

/// Resamples to `width × height`; the cell size scales with the width ratio.
pub fn resample(hf: &Heightfield, width: usize, height: usize) -> Result<Heightfield, SizeError> {
    crate::size::check_dims(width, height)?;
    let (sw, sh) = (hf.width(), hf.height());
    let tx = taps(sw, width);
    let ty = taps(sh, height);
    // Horizontal pass: sh × width.
    let mut mid = vec![0.0f32; sh * width];
    mid.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let src = hf.row(y);
        for (x, o) in row.iter_mut().enumerate() {
            *o = apply(src, 1, &tx[x]);
        }
    });
    let cell = hf.cell_size() * sw as f64 / width as f64;
    let mut out = Heightfield::new(width, height, cell)?;
    out.data_mut()
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, o) in row.iter_mut().enumerate() {
                *o = apply(&mid[x..], width, &ty[y]);
            }
        });
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_stay_planes_and_constants_stay_constant() {
        let hf = Heightfield::from_fn(40, 30, 10.0, |x, y| 5.0 + 2.0 * x as f32 + 3.0 * y as f32)
            .unwrap();
        let up = resample(&hf, 80, 60).unwrap();
        assert!((up.cell_size() - 5.0).abs() < 1e-12);
        // Away from the clamped border a plane is reproduced exactly.
        for y in 4..56 {
            for x in 4..76 {
                let want = 5.0
                    + 2.0 * ((x as f32 + 0.5) / 2.0 - 0.5)
                    + 3.0 * ((y as f32 + 0.5) / 2.0 - 0.5);
                assert!((up.get(x, y) - want).abs() < 1e-3, "({x},{y})");
            }
        }
        let c = Heightfield::from_fn(33, 17, 1.0, |_, _| 7.5).unwrap();
        let down = resample(&c, 10, 5).unwrap();
        assert!(down.data().iter().all(|&v| (v - 7.5).abs() < 1e-5));
    }

    #[test]
    fn nodata_has_no_weight() {
        let hf = Heightfield::from_vec(4, 1, 1.0, vec![1.0, f32::NAN, 1.0, 1.0]).unwrap();
        let r = resample(&hf, 2, 1).unwrap();
        assert_eq!(r.data(), &[1.0, 1.0]);
        let all = Heightfield::from_vec(2, 1, 1.0, vec![f32::NAN; 2]).unwrap();
        assert!(resample(&all, 1, 1).unwrap().get(0, 0).is_nan());
    }
}
