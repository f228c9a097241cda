//! Gradient-domain (Poisson) blending, seed 002 §7.4.3 after Pérez et al.
//! 2003: inside the mask the result has the guidance gradients, outside it
//! is the destination, unchanged. The solve is the crate's one Poisson
//! solver ([`crate::poisson::solve`]); this module only builds its
//! right-hand side from a guidance field.
//!
//! Guidance is given per grid edge: `gx[i]` is the wanted difference
//! `u(x+1, y) − u(x, y)` and `gy[i]` the wanted `u(x, y+1) − u(x, y)`
//! (the last column's `gx` and last row's `gy` are unused). The discrete
//! equation at a free pixel p is `Σ_n (u_n − u_p) = Σ_n g(p→n)`, which is
//! the Euler–Lagrange equation of `min Σ_edges (u_n − u_p − g(p→n))²`.

use super::{BlendError, Inputs, check_lengths};
use crate::poisson::{Method, SolveOptions, SolveReport, solve};

/// Solves for `u` on the pixels where `free` is set, keeping the others as
/// Dirichlet values, so that the differences of `u` best match the guidance.
pub fn solve_guided(
    width: usize,
    height: usize,
    u: &mut [f32],
    free: &[bool],
    gx: &[f32],
    gy: &[f32],
    opts: &SolveOptions,
) -> Result<SolveReport, BlendError> {
    check_lengths(
        width,
        height,
        &[
            ("heights", u.len()),
            ("free mask", free.len()),
            ("gx", gx.len()),
            ("gy", gy.len()),
        ],
    )?;
    let rhs = guided_rhs(width, height, gx, gy);
    let fixed: Vec<bool> = free.iter().map(|f| !f).collect();
    Ok(solve(
        Method::Cascadic,
        width,
        height,
        u,
        &fixed,
        Some(&rhs),
        opts,
    )?)
}

/// The right-hand side `f` of the solve for guidance `gx`, `gy` (both of
/// length `width · height`): at each pixel, the sum of the wanted
/// differences to its in-grid neighbours, `Σ_n g(p→n)`.
pub fn guided_rhs(width: usize, height: usize, gx: &[f32], gy: &[f32]) -> Vec<f32> {
    let mut rhs = vec![0.0f32; width * height];
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            let mut f = 0.0f32;
            if x + 1 < width {
                f += gx[i];
            }
            if x > 0 {
                f -= gx[i - 1];
            }
            if y + 1 < height {
                f += gy[i];
            }
            if y > 0 {
                f -= gy[i - width];
            }
            rhs[i] = f;
        }
    }
    rhs
}

/// Seamless cloning: inside `mask > 0.5` take the gradients of `src`, keep
/// `dst` elsewhere (the boundary of the mask is matched exactly).
pub fn blend(inputs: Inputs<'_>, opts: &SolveOptions) -> Result<SolveReport, BlendError> {
    let (width, height, src) = (inputs.width, inputs.height, inputs.src);
    let n = width * height;
    let free: Vec<bool> = inputs.mask.iter().map(|&m| m > 0.5).collect();
    let mut gx = vec![0.0f32; n];
    let mut gy = vec![0.0f32; n];
    for y in 0..height {
        for x in 0..width {
            let i = y * width + x;
            if x + 1 < width {
                gx[i] = src[i + 1] - src[i];
            }
            if y + 1 < height {
                gy[i] = src[i + width] - src[i];
            }
        }
    }
    solve_guided(width, height, inputs.dst, &free, &gx, &gy, opts)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_source_at_another_level_is_cloned_without_a_step_and_converges() {
        let (w, h) = (48, 40);
        let dst = vec![10.0f32; w * h];
        // Source: a bump at a base level of 500.
        let src: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 - 24.0, (i / w) as f32 - 20.0);
                500.0 + 30.0 * (-(x * x + y * y) / 40.0).exp()
            })
            .collect();
        let mask: Vec<f32> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                if (8..40).contains(&x) && (8..32).contains(&y) {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        let mut out = dst.clone();
        let opts = SolveOptions {
            tolerance: 1e-7,
            max_iterations: 5000,
        };
        let r = blend(Inputs::new(w, h, &mut out, &src, &mask).unwrap(), &opts).unwrap();
        assert!(r.converged && r.relative_residual <= 1e-7, "{r:?}");
        // Outside untouched, the bump's relief kept, no 490 m step.
        assert_eq!(out[0], 10.0);
        let peak = out[20 * w + 24];
        assert!((peak - 10.0 - 30.0).abs() < 6.0, "peak {peak}");
        let max_step = (0..w * h)
            .filter(|i| i % w + 1 < w)
            .map(|i| (out[i + 1] - out[i]).abs())
            .fold(0.0, f32::max);
        assert!(max_step < 8.0, "max step {max_step}");
    }
}
