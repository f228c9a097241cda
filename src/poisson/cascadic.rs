//! [`Method::Cascadic`], the solver for large grids (whole-DEM nodata
//! filling, blending): a cascadic start, each level solved on a 2x coarser
//! grid first and interpolated up as the initial guess, then the parallel
//! Jacobi-preconditioned CG of `pcg` on the finest level.
//!
//! [`Method::Cascadic`]: super::Method::Cascadic

use super::pcg::cg;
use super::{Problem, SolveOptions, SolveReport};
use crate::resample::bilinear;
use rayon::prelude::*;

/// Solves a checked problem in place; the initial guess at free pixels is
/// ignored (the cascadic start replaces it).
pub(super) fn solve(problem: Problem<'_>, opts: &SolveOptions) -> SolveReport {
    let (width, height, fixed, rhs) = (problem.width, problem.height, problem.fixed, problem.rhs);
    let u = problem.u;
    let n = width * height;
    let unknowns = fixed.iter().filter(|&&f| !f).count();
    if unknowns == 0 {
        return SolveReport {
            unknowns,
            iterations: 0,
            relative_residual: 0.0,
            converged: true,
        };
    }
    let mut x: Vec<f64> = u
        .iter()
        .map(|&v| if v.is_finite() { v as f64 } else { 0.0 })
        .collect();
    let f: Vec<f64> = match rhs {
        Some(r) => r.iter().map(|&v| v as f64).collect(),
        None => vec![0.0; n],
    };
    cascadic_start(width, height, &mut x, fixed, &f);
    let report = cg(width, height, &mut x, fixed, &f, opts);
    for i in 0..n {
        if !fixed[i] {
            u[i] = x[i] as f32;
        }
    }
    report
}

/// Solves a 2× coarser problem (recursively) and interpolates it into the
/// free pixels of `x` as the initial guess.
fn cascadic_start(width: usize, height: usize, x: &mut [f64], fixed: &[bool], f: &[f64]) {
    // Below this size CG from a flat start is already cheap.
    if width * height <= 64 * 64 {
        let mean = {
            let (s, c) = (0..x.len())
                .filter(|&i| fixed[i])
                .fold((0.0, 0usize), |(s, c), i| (s + x[i], c + 1));
            s / c as f64
        };
        for i in 0..x.len() {
            if !fixed[i] {
                x[i] = mean;
            }
        }
        return;
    }
    let (cw, ch) = (width.div_ceil(2), height.div_ceil(2));
    let mut cx = vec![0.0f64; cw * ch];
    let mut cfixed = vec![false; cw * ch];
    let mut cf = vec![0.0f64; cw * ch];
    for cy in 0..ch {
        for cxi in 0..cw {
            let (mut sum, mut count) = (0.0, 0);
            let mut fsum = 0.0;
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (px, py) = (2 * cxi + dx, 2 * cy + dy);
                if px < width && py < height {
                    let i = py * width + px;
                    fsum += f[i];
                    if fixed[i] {
                        sum += x[i];
                        count += 1;
                    }
                }
            }
            let ci = cy * cw + cxi;
            // A coarse pixel is fixed when any child is: boundary values
            // carry down; f sums the children because the coarse stencil
            // spans 2× the spacing (Σ(u_n − u_p) scales with h²).
            cfixed[ci] = count > 0;
            cx[ci] = if count > 0 { sum / count as f64 } else { 0.0 };
            cf[ci] = fsum;
        }
    }
    cascadic_start(cw, ch, &mut cx, &cfixed, &cf);
    let coarse_opts = SolveOptions {
        tolerance: 1e-3,
        max_iterations: 200,
    };
    cg(cw, ch, &mut cx, &cfixed, &cf, &coarse_opts);
    // Bilinear prolongation of the coarse solution onto free fine pixels.
    x.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (xi, v) in row.iter_mut().enumerate() {
            if !fixed[y * width + xi] {
                *v = bilinear(
                    &cx,
                    cw,
                    ch,
                    [(xi as f64 + 0.5) / 2.0, (y as f64 + 0.5) / 2.0],
                );
            }
        }
    });
}
