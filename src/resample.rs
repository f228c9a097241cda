//! Resampling heightfields to a new grid with a tent filter whose support
//! grows with the reduction factor: bilinear interpolation when enlarging,
//! an area-weighted average when reducing (so shrinking never aliases ridges
//! into stair-steps). Nodata samples carry no weight; an output sample whose
//! whole support is nodata stays nodata.
//!
//! Also [`bilinear`], the one point sampler of plain grids that the patch
//! engine's feature profiles, the Poisson solver's prolongation and the
//! Laplacian blend's upsampling share.

use crate::heightfield::Heightfield;
use crate::size::SizeError;
use rayon::prelude::*;
use std::ops::{Add, Mul, Sub};

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

/// The float types [`bilinear`] samples: `f32` grids (heights) and `f64`
/// ones (the Poisson solver's unknowns), with the same arithmetic in each.
pub trait Real: Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> {
    const ZERO: Self;
    const HALF: Self;
    const ONE: Self;
    /// `i` as this type (`i as f32`).
    fn of(i: usize) -> Self;
    /// `self.clamp(lo, hi)`.
    fn clamped(self, lo: Self, hi: Self) -> Self;
    /// `self.floor() as usize`.
    fn floor_index(self) -> usize;
}

macro_rules! real {
    ($t:ty) => {
        impl Real for $t {
            const ZERO: $t = 0.0;
            const HALF: $t = 0.5;
            const ONE: $t = 1.0;
            fn of(i: usize) -> $t {
                i as $t
            }
            fn clamped(self, lo: $t, hi: $t) -> $t {
                self.clamp(lo, hi)
            }
            fn floor_index(self) -> usize {
                self.floor() as usize
            }
        }
    };
}
real!(f32);
real!(f64);

/// Bilinear sample of a row-major `w × h` grid at `p` (in pixels, pixel
/// `(i, j)` centred on `(i + ½, j + ½)`), clamped to the outermost centres.
#[inline]
pub fn bilinear<T: Real>(field: &[T], w: usize, h: usize, p: [T; 2]) -> T {
    let x = (p[0] - T::HALF).clamped(T::ZERO, T::of(w - 1));
    let y = (p[1] - T::HALF).clamped(T::ZERO, T::of(h - 1));
    let (x0, y0) = (x.floor_index(), y.floor_index());
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (tx, ty) = (x - T::of(x0), y - T::of(y0));
    let a = field[y0 * w + x0] * (T::ONE - tx) + field[y0 * w + x1] * tx;
    let b = field[y1 * w + x0] * (T::ONE - tx) + field[y1 * w + x1] * tx;
    a * (T::ONE - ty) + b * ty
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
