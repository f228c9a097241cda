//! Jacobi-preconditioned conjugate gradients on the masked grid, data-
//! parallel over rows and fixed-size chunks (the finest level of `solve`
//! and every level of its cascadic start), with the 5-point operator it
//! applies.

use super::{SolveOptions, SolveReport};
use rayon::prelude::*;

const CHUNK: usize = 4096;

/// Applies `A = −∇²` restricted to free pixels: for free p,
/// `(A v)_p = deg(p)·v_p − Σ_{free n} v_n`; zero at fixed pixels.
fn apply(width: usize, height: usize, v: &[f64], fixed: &[bool], out: &mut [f64]) {
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (x, o) in row.iter_mut().enumerate() {
            let i = y * width + x;
            if fixed[i] {
                *o = 0.0;
                continue;
            }
            let mut acc = 0.0;
            let mut deg = 0.0;
            neighbours(width, height, x, y, |j| {
                deg += 1.0;
                if !fixed[j] {
                    acc -= v[j];
                }
            });
            *o = deg * v[i] + acc;
        }
    });
}

/// Calls `f` with the index of each in-grid 4-neighbour of pixel `(x, y)`,
/// always in the order left, right, up, down, so that sums over the
/// neighbours round the same way wherever they are taken.
fn neighbours(width: usize, height: usize, x: usize, y: usize, mut f: impl FnMut(usize)) {
    let i = y * width + x;
    if x > 0 {
        f(i - 1);
    }
    if x + 1 < width {
        f(i + 1);
    }
    if y > 0 {
        f(i - width);
    }
    if y + 1 < height {
        f(i + width);
    }
}

/// Degree (neighbour count) of pixel i.
pub(super) fn degree(width: usize, height: usize, i: usize) -> f64 {
    let (x, y) = (i % width, i / width);
    ((x > 0) as u8 + (x + 1 < width) as u8 + (y > 0) as u8 + (y + 1 < height) as u8) as f64
}

/// Deterministic parallel dot product over free pixels.
fn dot(a: &[f64], b: &[f64], fixed: &[bool]) -> f64 {
    let partial: Vec<f64> = a
        .par_chunks(CHUNK)
        .zip(b.par_chunks(CHUNK))
        .zip(fixed.par_chunks(CHUNK))
        .map(|((a, b), m)| {
            a.iter()
                .zip(b)
                .zip(m)
                .filter(|(_, m)| !**m)
                .map(|((a, b), _)| a * b)
                .sum::<f64>()
        })
        .collect();
    partial.iter().sum()
}

/// Jacobi-preconditioned CG on the free pixels, starting from `x`.
pub(super) fn cg(
    width: usize,
    height: usize,
    x: &mut [f64],
    fixed: &[bool],
    f: &[f64],
    opts: &SolveOptions,
) -> SolveReport {
    let n = width * height;
    let unknowns = fixed.iter().filter(|&&m| !m).count();
    // b = −f + Σ_{fixed n} u_n (boundary values move to the right side).
    let mut b = vec![0.0f64; n];
    b.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (xi, o) in row.iter_mut().enumerate() {
            let i = y * width + xi;
            if fixed[i] {
                continue;
            }
            let mut s = -f[i];
            neighbours(width, height, xi, y, |j| {
                if fixed[j] {
                    s += x[j];
                }
            });
            *o = s;
        }
    });
    let bnorm = dot(&b, &b, fixed).sqrt().max(1.0);
    let mut ax = vec![0.0; n];
    apply(width, height, x, fixed, &mut ax);
    let mut r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
    let inv_diag: Vec<f64> = (0..n)
        .map(|i| {
            if fixed[i] {
                0.0
            } else {
                1.0 / degree(width, height, i)
            }
        })
        .collect();
    let mut z: Vec<f64> = r.iter().zip(&inv_diag).map(|(r, d)| r * d).collect();
    let mut p = z.clone();
    let mut rz = dot(&r, &z, fixed);
    let mut rnorm = dot(&r, &r, fixed).sqrt();
    let mut iterations = 0;
    while rnorm > opts.tolerance * bnorm && iterations < opts.max_iterations {
        apply(width, height, &p, fixed, &mut ax);
        let pap = dot(&p, &ax, fixed);
        if pap <= 0.0 {
            break;
        }
        let alpha = rz / pap;
        x.par_iter_mut().zip(&p).zip(fixed).for_each(|((x, p), m)| {
            if !*m {
                *x += alpha * p
            }
        });
        r.par_iter_mut().zip(&ax).for_each(|(r, a)| *r -= alpha * a);
        z.par_iter_mut()
            .zip(&r)
            .zip(&inv_diag)
            .for_each(|((z, r), d)| *z = r * d);
        let rz_new = dot(&r, &z, fixed);
        let beta = rz_new / rz;
        rz = rz_new;
        p.par_iter_mut()
            .zip(&z)
            .for_each(|(p, z)| *p = z + beta * *p);
        rnorm = dot(&r, &r, fixed).sqrt();
        iterations += 1;
    }
    // Report the true residual, not the recurrence's estimate.
    apply(width, height, x, fixed, &mut ax);
    let true_r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
    let rel = dot(&true_r, &true_r, fixed).sqrt() / bnorm;
    SolveReport {
        unknowns,
        iterations,
        relative_residual: rel,
        converged: rel <= opts.tolerance,
    }
}
