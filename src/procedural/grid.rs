//! Flat f64 grids shared by the erosion stages and the styles: the Moore
//! neighbourhood, row-parallel Jacobi sweeps and resampling.
//!
//! Every sweep writes each output cell from a pure function of the previous
//! buffers, one rayon task per row: which thread computes a row can never
//! change a bit of it.

use crate::heightfield::{FirstNodata, Heightfield};
use rayon::prelude::*;

/// The eight neighbours: (dx, dy, distance in cells).
pub(crate) const MOORE: [(isize, isize, f64); 8] = [
    (-1, -1, std::f64::consts::SQRT_2),
    (0, -1, 1.0),
    (1, -1, std::f64::consts::SQRT_2),
    (-1, 0, 1.0),
    (1, 0, 1.0),
    (-1, 1, std::f64::consts::SQRT_2),
    (0, 1, 1.0),
    (1, 1, std::f64::consts::SQRT_2),
];

/// Index of the neighbour (dx, dy) of (x, y), or `None` outside the grid.
#[inline]
pub(crate) fn neighbour(
    x: usize,
    y: usize,
    dx: isize,
    dy: isize,
    width: usize,
    height: usize,
) -> Option<usize> {
    let nx = x.checked_add_signed(dx).filter(|&v| v < width)?;
    let ny = y.checked_add_signed(dy).filter(|&v| v < height)?;
    Some(ny * width + nx)
}

/// `out[y·w + x] = f(x, y)` for every cell, rows in parallel.
pub(crate) fn sweep<T: Send>(out: &mut [T], width: usize, f: impl Fn(usize, usize) -> T + Sync) {
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, v) in row.iter_mut().enumerate() {
            *v = f(x, y);
        }
    });
}

/// `out[y·w + x] += f(x, y)` for every cell, rows in parallel.
pub(crate) fn sweep_add(out: &mut [f32], width: usize, f: impl Fn(usize, usize) -> f64 + Sync) {
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, v) in row.iter_mut().enumerate() {
            *v = (*v as f64 + f(x, y)) as f32;
        }
    });
}

/// The heights of a heightfield as f64, or the first nodata pixel.
pub(crate) fn to_f64(hf: &Heightfield) -> Result<Vec<f64>, super::ProceduralError> {
    if let Some(FirstNodata { count, x, y }) = hf.first_nodata() {
        return Err(super::ProceduralError::NoData { count, x, y });
    }
    Ok(hf.data().iter().map(|&v| v as f64).collect())
}

/// Stores f64 heights back into a heightfield of the same size.
pub(crate) fn store(hf: &mut Heightfield, values: &[f64]) {
    let w = hf.width();
    hf.data_mut()
        .par_chunks_mut(w)
        .zip(values.par_chunks(w))
        .for_each(|(dst, src)| {
            for (d, s) in dst.iter_mut().zip(src) {
                *d = *s as f32;
            }
        });
}

/// Catmull-Rom weights for fractional offset `t` (taps at −1, 0, 1, 2).
fn catmull_rom(t: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        0.5 * (-t3 + 2.0 * t2 - t),
        0.5 * (3.0 * t3 - 5.0 * t2 + 2.0),
        0.5 * (-3.0 * t3 + 4.0 * t2 + t),
        0.5 * (t3 - t2),
    ]
}

/// Upsamples a heightfield by 2 with a Catmull-Rom (bicubic) filter; the cell
/// size halves. Sample centres are aligned (fine centre `i` sits at coarse
/// coordinate `(i + ½)/2 − ½`), edges are replicated.
pub(crate) fn upsample2(hf: &Heightfield) -> Heightfield {
    let (w, h) = (hf.width(), hf.height());
    let weights = [catmull_rom(0.75), catmull_rom(0.25)];
    let tap = |x: usize, y: usize| -> f32 {
        // even fine index 2k → coarse k − 0.25 → base k − 1, t = 0.75;
        // odd 2k + 1 → coarse k + 0.25 → base k, t = 0.25
        let (bx, wx) = ((x / 2) as isize - 1 + (x % 2) as isize, &weights[x % 2]);
        let (by, wy) = ((y / 2) as isize - 1 + (y % 2) as isize, &weights[y % 2]);
        let mut acc = 0.0f64;
        for (j, wyj) in wy.iter().enumerate() {
            let mut row = 0.0f64;
            for (i, wxi) in wx.iter().enumerate() {
                row += wxi * hf.get_clamped(bx + i as isize - 1, by + j as isize - 1) as f64;
            }
            acc += wyj * row;
        }
        acc as f32
    };
    Heightfield::from_fn(2 * w, 2 * h, hf.cell_size() / 2.0, tap)
        .expect("twice a valid size stays valid below MAX_SIDE / 2")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catmull_rom_weights_sum_to_one_and_interpolate() {
        for t in [0.0, 0.25, 0.5, 0.75] {
            let w = catmull_rom(t);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
        assert_eq!(catmull_rom(0.0), [0.0, 1.0, 0.0, 0.0]);
    }

    #[test]
    fn upsampling_reproduces_a_linear_ramp() {
        let hf = Heightfield::from_fn(8, 8, 4.0, |x, y| (x as f32) * 2.0 + y as f32).unwrap();
        let up = upsample2(&hf);
        assert_eq!((up.width(), up.height(), up.cell_size()), (16, 16, 2.0));
        // away from the replicated edges a ramp stays a ramp with half the step
        for y in 3..13 {
            for x in 3..13 {
                let want = (x as f32 / 2.0 - 0.25) * 2.0 + (y as f32 / 2.0 - 0.25);
                assert!((up.get(x, y) - want).abs() < 1e-5, "({x}, {y})");
            }
        }
    }
}
