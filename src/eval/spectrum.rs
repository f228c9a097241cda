//! Spectral slope: how power falls with frequency. Real terrain is close to
//! a power law P(f) ∝ f^−β over a wide band; smoothing steepens it, noise
//! flattens it.
//!
//! Method: remove the least-squares plane (a regional tilt would leak
//! power at every frequency), multiply by a 2-D Hann window (so the
//! terrain's edges, which do not wrap, leak no power either), zero-pad to
//! powers of two, FFT, and average |F|² over rings of radial frequency
//! f = √(fx² + fy²) (cycles per cell) in log-spaced bins of 1/20 decade.
//! β is minus the slope of the least-squares line through (log₁₀ f,
//! log₁₀ P) of the bins in the **fit band**: wavelengths from
//! [`MIN_WAVELENGTH`] cells (shorter ones carry resampling and quantisation
//! artefacts of the DEMs) to `side / 4` cells, clamped to
//! [`MAX_WAVELENGTH`]..8 (longer ones have too few cycles in a window to
//! average). On the shared DEMs and their halves (≥ 300 cells across) the
//! band is the same 4–64 cells for every terrain.

use super::fft::{Complex64, Fft2};
use crate::heightfield::Heightfield;
use rayon::prelude::*;

/// Shortest wavelength of the fit band, in cells.
pub const MIN_WAVELENGTH: f64 = 4.0;
/// Longest wavelength of the fit band, in cells (on large terrains).
pub const MAX_WAVELENGTH: f64 = 64.0;
/// Radial bins per decade of frequency.
const BINS_PER_DECADE: f64 = 20.0;

/// A radially averaged power spectrum and its fitted slope.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Spectrum {
    /// Bin frequencies (mean of the members), cycles per cell, ascending.
    pub freq: Vec<f64>,
    /// Mean power in each bin, m² per (cycles/cell)², normalised by the
    /// window's energy so terrains of different sizes compare.
    pub power: Vec<f64>,
    /// The fit band, cycles per cell: (1 / longest, 1 / shortest wavelength).
    pub band: (f64, f64),
    /// −slope of log P against log f over the band.
    pub beta: f64,
}

/// The fit band of a `w × h` terrain, in cycles per cell.
pub fn band(w: usize, h: usize) -> (f64, f64) {
    let longest = (w.min(h) as f64 / 4.0).clamp(8.0, MAX_WAVELENGTH);
    (1.0 / longest, 1.0 / MIN_WAVELENGTH)
}

/// The spectrum of a terrain (see the module docs).
pub fn spectrum(hf: &Heightfield) -> Spectrum {
    let (w, h) = (hf.width(), hf.height());
    let (pw, ph) = (w.next_power_of_two(), h.next_power_of_two());
    let (a, bx, by) = plane(hf);
    let hann = |n: usize| -> Vec<f64> {
        (0..n)
            .map(|i| 0.5 - 0.5 * (2.0 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64).cos())
            .collect()
    };
    let (wx, wy) = (hann(w), hann(h));
    let (cx, cy) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
    let mut spec = vec![Complex64::default(); pw * ph];
    spec.par_chunks_mut(pw)
        .take(h)
        .enumerate()
        .for_each(|(y, row)| {
            for x in 0..w {
                let trend = a + bx * (x as f64 - cx) + by * (y as f64 - cy);
                row[x].re = (hf.get(x, y) as f64 - trend) * wx[x] * wy[y];
            }
        });
    // The spectrum transposed: bin (u, v) at u·ph + v.
    let mut bins_t = vec![Complex64::default(); pw * ph];
    Fft2::new(pw, ph).forward_transposed(&mut spec, h, &mut bins_t);
    let energy: f64 = wx.iter().map(|v| v * v).sum::<f64>() * wy.iter().map(|v| v * v).sum::<f64>();

    // Ring averages in log-spaced bins from the lowest non-zero frequency.
    let f_min = 1.0 / pw.max(ph) as f64;
    let bin_of = |f: f64| ((f / f_min).log10() * BINS_PER_DECADE).floor() as usize;
    let bins = bin_of(std::f64::consts::SQRT_2 * 0.5) + 1;
    // Per row in parallel, rows added in order: a rayon fold/reduce
    // groups rows by work stealing, and its rounding changed between runs.
    let rows: Vec<Vec<(f64, f64, u64)>> = (0..ph)
        .into_par_iter()
        .map(|v| {
            let mut acc = vec![(0.0f64, 0.0f64, 0u64); bins];
            let fy = signed(v, ph) as f64 / ph as f64;
            for u in 0..pw {
                let fx = signed(u, pw) as f64 / pw as f64;
                let f = (fx * fx + fy * fy).sqrt();
                if f < f_min {
                    continue; // the mean (removed) and sub-bin frequencies
                }
                let b = &mut acc[bin_of(f).min(bins - 1)];
                b.0 += f;
                b.1 += bins_t[u * ph + v].norm_sqr();
                b.2 += 1;
            }
            acc
        })
        .collect();
    let mut sums = vec![(0.0f64, 0.0f64, 0u64); bins];
    for row in rows {
        for (x, y) in sums.iter_mut().zip(row) {
            x.0 += y.0;
            x.1 += y.1;
            x.2 += y.2;
        }
    }
    let (freq, power): (Vec<f64>, Vec<f64>) = sums
        .iter()
        .filter(|b| b.2 > 0)
        .map(|&(fs, ps, n)| (fs / n as f64, ps / n as f64 / energy))
        .unzip();
    let band = band(w, h);
    let beta = -fit_slope(&freq, &power, band);
    Spectrum {
        freq,
        power,
        band,
        beta,
    }
}

/// The frequency index `i` of an `n`-point FFT as a signed frequency.
fn signed(i: usize, n: usize) -> isize {
    if i <= n / 2 {
        i as isize
    } else {
        i as isize - n as isize
    }
}

/// Least-squares plane `a + bx·(x − cx) + by·(y − cy)` through the heights
/// (centred coordinates make the three normal equations independent).
fn plane(hf: &Heightfield) -> (f64, f64, f64) {
    let (w, h) = (hf.width(), hf.height());
    let (cx, cy) = ((w as f64 - 1.0) / 2.0, (h as f64 - 1.0) / 2.0);
    let (s, sx, sy) = (0..h)
        .into_par_iter()
        .map(|y| {
            let dy = y as f64 - cy;
            hf.row(y)
                .iter()
                .enumerate()
                .fold((0.0, 0.0, 0.0), |(s, sx, sy), (x, &v)| {
                    let v = v as f64;
                    (s + v, sx + v * (x as f64 - cx), sy + v * dy)
                })
        })
        .collect::<Vec<_>>()
        .into_iter()
        .fold((0.0, 0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2));
    let n = (w * h) as f64;
    // Σ (x − cx)² over the grid = h · w(w² − 1)/12.
    let vx = h as f64 * w as f64 * (w as f64 * w as f64 - 1.0) / 12.0;
    let vy = w as f64 * h as f64 * (h as f64 * h as f64 - 1.0) / 12.0;
    let slope = |s: f64, v: f64| if v > 0.0 { s / v } else { 0.0 };
    (s / n, slope(sx, vx), slope(sy, vy))
}

/// Slope of the least-squares line through (log₁₀ f, log₁₀ P) of the bins
/// with f in `band`; 0 if fewer than two bins have power there.
fn fit_slope(freq: &[f64], power: &[f64], band: (f64, f64)) -> f64 {
    let pts: Vec<(f64, f64)> = freq
        .iter()
        .zip(power)
        .filter(|&(&f, &p)| f >= band.0 * (1.0 - 1e-9) && f <= band.1 * (1.0 + 1e-9) && p > 0.0)
        .map(|(&f, &p)| (f.log10(), p.log10()))
        .collect();
    if pts.len() < 2 {
        return 0.0;
    }
    let n = pts.len() as f64;
    let (mx, my) = (
        pts.iter().map(|p| p.0).sum::<f64>() / n,
        pts.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    if sxx > 0.0 { sxy / sxx } else { 0.0 }
}
