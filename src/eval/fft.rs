//! 2-D complex FFTs in f64 over rustfft: what the spectral descriptor and
//! the novelty measure's cross-correlations need. Evaluation is CPU-only
//! float work (DESIGN §6 rule 5), so plain floats are fine here; every
//! transform is a fixed sequence of row and column transforms, so results
//! do not depend on the thread count.
//!
//! Spectra can stay **transposed** (`s[u·h + v]` holds bin (u, v)): a
//! forward transform ends with its column transforms, which run on
//! contiguous memory only after a transpose, and an inverse begins with
//! them — so a spectrum that is only multiplied and transformed back never
//! needs transposing back and forth (one transpose per transform instead of
//! two; the cross-correlations of `novelty` are ~90 % transforms).

use rayon::prelude::*;
pub use rustfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

/// A plan for 2-D transforms of row-major `w × h` grids (any sizes; powers
/// of two are fastest).
pub struct Fft2 {
    w: usize,
    h: usize,
    rows: [Arc<dyn Fft<f64>>; 2],
    cols: [Arc<dyn Fft<f64>>; 2],
}

/// Forward or inverse.
const FORWARD: usize = 0;
const INVERSE: usize = 1;

impl Fft2 {
    pub fn new(w: usize, h: usize) -> Fft2 {
        let mut p = FftPlanner::new();
        Fft2 {
            w,
            h,
            rows: [p.plan_fft_forward(w), p.plan_fft_inverse(w)],
            cols: [p.plan_fft_forward(h), p.plan_fft_inverse(h)],
        }
    }

    /// In-place forward transform, `X_{u,v} = Σ x_{x,y} e^{−2πi(ux/w + vy/h)}`
    /// (unscaled), row-major.
    pub fn forward(&self, buf: &mut [Complex64]) {
        let mut t = vec![Complex64::default(); buf.len()];
        self.forward_transposed(buf, self.h, &mut t);
        transpose_into(&t, self.h, self.w, self.h, buf);
    }

    /// In-place inverse transform, scaled by 1/(w·h) so that it undoes
    /// [`Fft2::forward`], row-major.
    pub fn inverse(&self, buf: &mut [Complex64]) {
        let mut t = vec![Complex64::default(); buf.len()];
        transpose_into(buf, self.w, self.h, self.w, &mut t);
        self.inverse_transposed(&mut t, self.h, buf);
    }

    /// The forward transform of `x` (row-major; destroyed) into `out`,
    /// transposed: `out[u·h + v]` = X_{u,v}. Rows `rows..h` of `x` are
    /// taken as zero (their transforms are skipped: a small template in a
    /// large grid has few non-zero rows).
    pub fn forward_transposed(&self, x: &mut [Complex64], rows: usize, out: &mut [Complex64]) {
        let (w, h) = (self.w, self.h);
        self.check(x);
        self.check(out);
        let rows = rows.min(h);
        self.each(&mut x[..rows * w], w, FORWARD, true);
        x[rows * w..]
            .iter_mut()
            .for_each(|c| *c = Complex64::default());
        transpose_into(x, w, h, w, out);
        self.each(out, h, FORWARD, false);
    }

    /// The inverse transform of the transposed spectrum `s` (destroyed),
    /// scaled by 1/(w·h): rows `..rows` of the result into `out`
    /// (row-major; the rest of `out` is left as it was).
    pub fn inverse_transposed(&self, s: &mut [Complex64], rows: usize, out: &mut [Complex64]) {
        let (w, h) = (self.w, self.h);
        self.check(s);
        self.check(out);
        let rows = rows.min(h);
        self.each(s, h, INVERSE, false);
        transpose_into(s, h, w, rows, out);
        let out = &mut out[..rows * w];
        self.each(out, w, INVERSE, true);
        let scale = 1.0 / (w * h) as f64;
        out.par_chunks_mut(w)
            .for_each(|r| r.iter_mut().for_each(|v| *v *= scale));
    }

    fn check(&self, buf: &[Complex64]) {
        assert_eq!(
            buf.len(),
            self.w * self.h,
            "buffer of {} for a {}x{} plan",
            buf.len(),
            self.w,
            self.h
        );
    }

    /// Transforms every `n`-long run of `buf` in direction `d`, along rows
    /// (`row`) or columns of the plan.
    fn each(&self, buf: &mut [Complex64], n: usize, d: usize, row: bool) {
        let plan = if row { &self.rows[d] } else { &self.cols[d] };
        buf.par_chunks_mut(n).for_each_init(
            || vec![Complex64::default(); plan.get_inplace_scratch_len()],
            |scratch, run| plan.process_with_scratch(run, scratch),
        );
    }
}

/// The first `rows` rows of the transpose of the row-major `w × h` grid
/// `v` (an `h × w` grid) into `out`, in tiles of 32 × 32 (both sides of a
/// tile stay in cache).
fn transpose_into(v: &[Complex64], w: usize, h: usize, rows: usize, out: &mut [Complex64]) {
    const TILE: usize = 32;
    out[..rows * h]
        .par_chunks_mut(h * TILE)
        .enumerate()
        .for_each(|(tx, band)| {
            let x0 = tx * TILE;
            let nx = band.len() / h;
            for y0 in (0..h).step_by(TILE) {
                for y in y0..(y0 + TILE).min(h) {
                    let row = &v[y * w + x0..][..nx];
                    for (k, &c) in row.iter().enumerate() {
                        band[k * h + y] = c;
                    }
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 2-D transform equals the defining sum and the inverse undoes it,
    /// for sizes that are and are not powers of two; the transposed forms
    /// of a grid with zero rows, and a partial inverse, agree with them.
    #[test]
    fn matches_the_naive_dft_and_inverts() {
        for (w, h) in [(1usize, 1usize), (8, 4), (6, 5), (16, 16)] {
            let x: Vec<Complex64> = (0..w * h)
                .map(|i| Complex64::new(((i * 7 + 3) % 11) as f64 - 4.5, ((i * 5) % 3) as f64))
                .collect();
            let plan = Fft2::new(w, h);
            let mut f = x.clone();
            plan.forward(&mut f);
            for v in 0..h {
                for u in 0..w {
                    let mut s = Complex64::default();
                    for y in 0..h {
                        for xx in 0..w {
                            let a = -std::f64::consts::TAU
                                * ((u * xx) as f64 / w as f64 + (v * y) as f64 / h as f64);
                            s += x[y * w + xx] * Complex64::new(a.cos(), a.sin());
                        }
                    }
                    assert!((f[v * w + u] - s).norm() < 1e-9, "{w}x{h} bin ({u}, {v})");
                }
            }
            let mut back = f.clone();
            plan.inverse(&mut back);
            for (a, b) in back.iter().zip(&x) {
                assert!((a - b).norm() < 1e-9);
            }
            // Zero rows below `k`: the transposed forward is the full one.
            let k = h.div_ceil(2);
            let mut z = x.clone();
            z[k * w..]
                .iter_mut()
                .for_each(|c| *c = Complex64::default());
            let mut full = z.clone();
            plan.forward(&mut full);
            let mut t = vec![Complex64::default(); w * h];
            plan.forward_transposed(&mut z, k, &mut t);
            for v in 0..h {
                for u in 0..w {
                    assert!((full[v * w + u] - t[u * h + v]).norm() < 1e-9);
                }
            }
            // And its partial inverse gives the first rows of the grid.
            let mut out = vec![Complex64::new(7.0, 7.0); w * h];
            plan.inverse_transposed(&mut t, k, &mut out);
            for i in 0..w * h {
                let want = if i < k * w {
                    x[i]
                } else {
                    Complex64::new(7.0, 7.0)
                };
                assert!((out[i] - want).norm() < 1e-9, "{w}x{h} cell {i}");
            }
        }
    }
}
