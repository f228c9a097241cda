//! A radix-2 complex FFT, in f64: what the spectral descriptor needs and no
//! more (power-of-two sizes; the spectrum zero-pads to one). Evaluation is
//! CPU-only float work (DESIGN §6 rule 5), so plain floats are fine here.

use rayon::prelude::*;

/// Twiddle factors and bit reversal for one transform length.
pub struct Fft {
    n: usize,
    /// cos and −sin of 2πk/n for k < n/2 (forward transform).
    cos: Vec<f64>,
    sin: Vec<f64>,
    rev: Vec<u32>,
}

impl Fft {
    /// A plan for length `n`, a power of two ≥ 1.
    pub fn new(n: usize) -> Fft {
        assert!(n.is_power_of_two(), "FFT length {n} is not a power of two");
        let bits = n.trailing_zeros();
        let (cos, sin) = (0..n / 2)
            .map(|k| {
                let a = -2.0 * std::f64::consts::PI * k as f64 / n as f64;
                (a.cos(), a.sin())
            })
            .unzip();
        let rev = (0..n as u32)
            .map(|i| {
                if bits == 0 {
                    0
                } else {
                    i.reverse_bits() >> (32 - bits)
                }
            })
            .collect();
        Fft { n, cos, sin, rev }
    }

    pub fn len(&self) -> usize {
        self.n
    }

    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// In-place forward transform, `X_k = Σ x_j e^{−2πi jk/n}` (unscaled).
    pub fn forward(&self, re: &mut [f64], im: &mut [f64]) {
        debug_assert!(re.len() == self.n && im.len() == self.n);
        for i in 0..self.n {
            let j = self.rev[i] as usize;
            if i < j {
                re.swap(i, j);
                im.swap(i, j);
            }
        }
        let mut len = 2;
        while len <= self.n {
            let half = len / 2;
            let step = self.n / len;
            for start in (0..self.n).step_by(len) {
                for k in 0..half {
                    let (c, s) = (self.cos[k * step], self.sin[k * step]);
                    let (a, b) = (start + k, start + k + half);
                    let tr = re[b] * c - im[b] * s;
                    let ti = re[b] * s + im[b] * c;
                    re[b] = re[a] - tr;
                    im[b] = im[a] - ti;
                    re[a] += tr;
                    im[a] += ti;
                }
            }
            len *= 2;
        }
    }

    /// In-place inverse transform, scaled by 1/n (so it undoes [`Fft::forward`]).
    pub fn inverse(&self, re: &mut [f64], im: &mut [f64]) {
        im.iter_mut().for_each(|v| *v = -*v);
        self.forward(re, im);
        let s = 1.0 / self.n as f64;
        re.iter_mut().for_each(|v| *v *= s);
        im.iter_mut().for_each(|v| *v *= -s);
    }
}

/// 2-D transform of a row-major `w × h` grid (both powers of two), rows in
/// parallel, then columns (through a transpose and back).
pub fn fft2(re: &mut [f64], im: &mut [f64], w: usize, h: usize, inverse: bool) {
    let run = |plan: &Fft, re: &mut [f64], im: &mut [f64], n: usize| {
        re.par_chunks_mut(n)
            .zip(im.par_chunks_mut(n))
            .for_each(|(r, i)| {
                if inverse {
                    plan.inverse(r, i)
                } else {
                    plan.forward(r, i)
                }
            });
    };
    run(&Fft::new(w), re, im, w);
    let (mut tr, mut ti) = (transpose(re, w, h), transpose(im, w, h));
    run(&Fft::new(h), &mut tr, &mut ti, h);
    re.copy_from_slice(&transpose(&tr, h, w));
    im.copy_from_slice(&transpose(&ti, h, w));
}

/// The transpose of a row-major `w × h` grid (an `h × w` grid).
fn transpose(v: &[f64], w: usize, h: usize) -> Vec<f64> {
    let mut out = vec![0.0; w * h];
    out.par_chunks_mut(h).enumerate().for_each(|(x, col)| {
        for (y, o) in col.iter_mut().enumerate() {
            *o = v[y * w + x];
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FFT equals the defining sum, and the inverse undoes it.
    #[test]
    fn matches_the_naive_dft_and_inverts() {
        for n in [1usize, 2, 8, 64] {
            let x: Vec<f64> = (0..n).map(|i| ((i * 7 + 3) % 11) as f64 - 4.5).collect();
            let (mut re, mut im) = (x.clone(), vec![0.0; n]);
            let plan = Fft::new(n);
            plan.forward(&mut re, &mut im);
            for k in 0..n {
                let (mut sr, mut si) = (0.0, 0.0);
                for (j, &v) in x.iter().enumerate() {
                    let a = -2.0 * std::f64::consts::PI * (j * k) as f64 / n as f64;
                    sr += v * a.cos();
                    si += v * a.sin();
                }
                assert!((re[k] - sr).abs() < 1e-9 && (im[k] - si).abs() < 1e-9);
            }
            plan.inverse(&mut re, &mut im);
            for (a, b) in re.iter().zip(&x) {
                assert!((a - b).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn two_d_transform_of_a_plane_wave_is_one_peak() {
        let (w, h) = (16, 8);
        let mut re: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                (2.0 * std::f64::consts::PI * (3.0 * x / w as f64 + 2.0 * y / h as f64)).cos()
            })
            .collect();
        let mut im = vec![0.0; w * h];
        fft2(&mut re, &mut im, w, h, false);
        let power: Vec<f64> = re.iter().zip(&im).map(|(r, i)| r * r + i * i).collect();
        let peak = (w * h / 2) as f64;
        for (k, &p) in power.iter().enumerate() {
            let (u, v) = (k % w, k / w);
            let expected = if (u, v) == (3, 2) || (u, v) == (w - 3, h - 2) {
                peak * peak
            } else {
                0.0
            };
            assert!((p - expected).abs() < 1e-6, "bin ({u}, {v}): {p}");
        }
    }
}
