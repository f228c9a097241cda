//! A Poisson solver on a masked grid: find `u` on the free pixels such that
//! `∇²u = f`, with every fixed pixel acting as a Dirichlet boundary value and
//! the grid border as a Neumann (zero-flux) boundary.
//!
//! One solver serves every place that needs it: harmonic nodata filling
//! (`f = 0`, see [`crate::fill`]), Poisson seam removal and gradient-domain
//! blending (`f` = divergence of a guidance gradient field).
//!
//! Discretisation: the 5-point Laplacian in grid units,
//! `Σ_{n ∈ N(p)} (u_n − u_p) = f_p`, where `N(p)` are the 4-neighbours inside
//! the grid (a missing neighbour contributes no flux, which is the Neumann
//! condition). Restricted to free pixels the negated operator is symmetric
//! positive definite whenever at least one pixel is fixed, so we use
//! Jacobi-preconditioned conjugate gradients.
//!
//! Speed: plain CG needs O(hole diameter) iterations. A cascadic start
//! (solve a 2× coarser problem first, recursively, and interpolate it as the
//! initial guess) removes the low frequencies that CG is slow on, so large
//! holes converge in tens of iterations per level. For many small solves
//! (the patch engine's windows), [`solve_mg`] instead preconditions CG with
//! a multigrid V-cycle and runs sequentially, which needs several times
//! fewer iterations and no fork-join per vector operation.
//!
//! Determinism: every reduction sums fixed-size chunks in index order, so the
//! result is bit-identical for any number of threads.

use rayon::prelude::*;
use thiserror::Error;

/// Why a solve could not run.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PoissonError {
    #[error("buffer length {found} does not match the {width}x{height} grid")]
    Length {
        width: usize,
        height: usize,
        found: usize,
    },
    #[error("no pixel is fixed: the solution is undetermined (at least one known value is needed)")]
    NothingFixed,
    #[error(
        "value at pixel ({x}, {y}) is not finite: fixed values and the right-hand side must be finite"
    )]
    NotFinite { x: usize, y: usize },
}

/// Stopping rule.
#[derive(Debug, Clone, Copy)]
pub struct SolveOptions {
    /// Stop when ‖b − Ax‖₂ ≤ `tolerance` · max(‖b‖₂, 1). The floor of 1 keeps
    /// the criterion meaningful when the boundary values are all zero.
    pub tolerance: f64,
    /// Upper bound on CG iterations on the finest level.
    pub max_iterations: usize,
}

impl Default for SolveOptions {
    fn default() -> Self {
        SolveOptions {
            tolerance: 1e-6,
            max_iterations: 10_000,
        }
    }
}

/// What a solve achieved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveReport {
    /// Free pixels solved for.
    pub unknowns: usize,
    /// CG iterations on the finest level.
    pub iterations: usize,
    /// Final relative residual ‖b − Ax‖₂ / max(‖b‖₂, 1).
    pub relative_residual: f64,
    /// Whether `relative_residual ≤ tolerance`.
    pub converged: bool,
}

const CHUNK: usize = 4096;

/// The checks both solvers make before touching anything: every slice
/// `width × height` long, fixed values and `f` finite, at least one fixed
/// pixel (otherwise the solution is defined only up to a constant).
fn check_inputs(
    width: usize,
    height: usize,
    u: &[f32],
    fixed: &[bool],
    rhs: Option<&[f32]>,
) -> Result<(), PoissonError> {
    let n = width * height;
    for len in [u.len(), fixed.len(), rhs.map_or(n, |r| r.len())] {
        if len != n {
            return Err(PoissonError::Length {
                width,
                height,
                found: len,
            });
        }
    }
    for i in 0..n {
        let bad_fixed = fixed[i] && !u[i].is_finite();
        if bad_fixed || rhs.is_some_and(|r| !r[i].is_finite()) {
            return Err(PoissonError::NotFinite {
                x: i % width,
                y: i / width,
            });
        }
    }
    if !fixed.iter().any(|&f| f) {
        return Err(PoissonError::NothingFixed);
    }
    Ok(())
}

/// Solves in place. `u` holds the boundary values at fixed pixels (read) and
/// the initial guess at free pixels (ignored: the cascadic start replaces it);
/// on return the free pixels hold the solution. `rhs` is `f` (zero if `None`).
pub fn solve(
    width: usize,
    height: usize,
    u: &mut [f32],
    fixed: &[bool],
    rhs: Option<&[f32]>,
    opts: &SolveOptions,
) -> Result<SolveReport, PoissonError> {
    check_inputs(width, height, u, fixed, rhs)?;
    let n = width * height;
    let unknowns = fixed.iter().filter(|&&f| !f).count();
    if unknowns == 0 {
        return Ok(SolveReport {
            unknowns,
            iterations: 0,
            relative_residual: 0.0,
            converged: true,
        });
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
    Ok(report)
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
    let sample = |fx: f64, fy: f64| -> f64 {
        let gx = (fx - 0.5).clamp(0.0, (cw - 1) as f64);
        let gy = (fy - 0.5).clamp(0.0, (ch - 1) as f64);
        let (x0, y0) = (gx.floor() as usize, gy.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(cw - 1), (y0 + 1).min(ch - 1));
        let (tx, ty) = (gx - x0 as f64, gy - y0 as f64);
        let a = cx[y0 * cw + x0] * (1.0 - tx) + cx[y0 * cw + x1] * tx;
        let b = cx[y1 * cw + x0] * (1.0 - tx) + cx[y1 * cw + x1] * tx;
        a * (1.0 - ty) + b * ty
    };
    x.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        for (xi, v) in row.iter_mut().enumerate() {
            if !fixed[y * width + xi] {
                *v = sample((xi as f64 + 0.5) / 2.0, (y as f64 + 0.5) / 2.0);
            }
        }
    });
}

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
            let mut visit = |j: usize| {
                deg += 1.0;
                if !fixed[j] {
                    acc -= v[j];
                }
            };
            if x > 0 {
                visit(i - 1);
            }
            if x + 1 < width {
                visit(i + 1);
            }
            if y > 0 {
                visit(i - width);
            }
            if y + 1 < height {
                visit(i + width);
            }
            *o = deg * v[i] + acc;
        }
    });
}

/// Degree (neighbour count) of pixel i.
fn degree(width: usize, height: usize, i: usize) -> f64 {
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
fn cg(
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
            let mut take = |j: usize| {
                if fixed[j] {
                    s += x[j];
                }
            };
            if xi > 0 {
                take(i - 1);
            }
            if xi + 1 < width {
                take(i + 1);
            }
            if y > 0 {
                take(i - width);
            }
            if y + 1 < height {
                take(i + width);
            }
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

/// One level of the multigrid hierarchy of [`solve_mg`]: a 5-point
/// operator with variable coefficients on the active (free) cells,
/// `(A v)_p = diag_p·v_p − Σ_n w_pn·v_n`.
struct Level {
    w: usize,
    h: usize,
    active: Vec<bool>,
    diag: Vec<f64>,
    /// Coupling to the east / south neighbour (0 where either is inactive).
    east: Vec<f64>,
    south: Vec<f64>,
}

impl Level {
    /// The finest level: the operator of [`solve`] restricted to free pixels.
    fn finest(w: usize, h: usize, fixed: &[bool]) -> Level {
        let active: Vec<bool> = fixed.iter().map(|f| !f).collect();
        let mut east = vec![0.0; w * h];
        let mut south = vec![0.0; w * h];
        for i in 0..w * h {
            let (x, y) = (i % w, i / w);
            if x + 1 < w && active[i] && active[i + 1] {
                east[i] = 1.0;
            }
            if y + 1 < h && active[i] && active[i + w] {
                south[i] = 1.0;
            }
        }
        let diag = (0..w * h)
            .map(|i| if active[i] { degree(w, h, i) } else { 0.0 })
            .collect();
        Level {
            w,
            h,
            active,
            diag,
            east,
            south,
        }
    }

    /// The Galerkin coarse level `PᵀAP` for `P` = piecewise-constant
    /// interpolation from 2×2 aggregates (exact for any mask).
    fn coarsen(&self) -> Level {
        let (w, h) = (self.w, self.h);
        let (cw, ch) = (w.div_ceil(2), h.div_ceil(2));
        let agg = |i: usize| (i / w / 2) * cw + (i % w) / 2;
        let mut active = vec![false; cw * ch];
        let mut diag = vec![0.0; cw * ch];
        let mut east = vec![0.0; cw * ch];
        let mut south = vec![0.0; cw * ch];
        for i in 0..w * h {
            if !self.active[i] {
                continue;
            }
            let a = agg(i);
            active[a] = true;
            diag[a] += self.diag[i];
            for (wt, j, coarse) in [
                (self.east[i], i + 1, &mut east),
                (self.south[i], i + w, &mut south),
            ] {
                if wt == 0.0 {
                    continue;
                }
                if agg(j) == a {
                    diag[a] -= 2.0 * wt;
                } else {
                    coarse[a] += wt;
                }
            }
        }
        Level {
            w: cw,
            h: ch,
            active,
            diag,
            east,
            south,
        }
    }

    /// `Σ_n w_pn·v_n` at cell `i = y·w + x` (coordinates passed in: a
    /// division per call would cost more than the sum).
    #[inline]
    fn off(&self, v: &[f64], i: usize, x: usize, y: usize) -> f64 {
        let mut s = 0.0;
        if x + 1 < self.w {
            s += self.east[i] * v[i + 1];
        }
        if x > 0 {
            s += self.east[i - 1] * v[i - 1];
        }
        if y + 1 < self.h {
            s += self.south[i] * v[i + self.w];
        }
        if y > 0 {
            s += self.south[i - self.w] * v[i - self.w];
        }
        s
    }

    /// One Gauss–Seidel sweep on `A x = b`, forward or backward.
    fn sweep(&self, x: &mut [f64], b: &[f64], forward: bool) {
        let (w, h) = (self.w, self.h);
        let mut visit = |cx: usize, cy: usize| {
            let i = cy * w + cx;
            if self.active[i] && self.diag[i] > 0.0 {
                x[i] = (b[i] + self.off(x, i, cx, cy)) / self.diag[i];
            }
        };
        if forward {
            for cy in 0..h {
                for cx in 0..w {
                    visit(cx, cy);
                }
            }
        } else {
            for cy in (0..h).rev() {
                for cx in (0..w).rev() {
                    visit(cx, cy);
                }
            }
        }
    }

    /// `A v` on the active cells (0 elsewhere).
    fn apply(&self, v: &[f64], out: &mut [f64]) {
        for y in 0..self.h {
            for x in 0..self.w {
                let i = y * self.w + x;
                out[i] = if self.active[i] {
                    self.diag[i] * v[i] - self.off(v, i, x, y)
                } else {
                    0.0
                };
            }
        }
    }
}

/// One symmetric V-cycle from zero for `A x = b` on `levels[l..]`:
/// forward Gauss–Seidel, coarse correction, backward Gauss–Seidel (the
/// adjoint pair keeps the preconditioner symmetric, as CG needs).
fn v_cycle(levels: &[Level], b: &[f64]) -> Vec<f64> {
    let lv = &levels[0];
    let n = lv.w * lv.h;
    let mut x = vec![0.0; n];
    if levels.len() == 1 {
        for _ in 0..16 {
            lv.sweep(&mut x, b, true);
            lv.sweep(&mut x, b, false);
        }
        return x;
    }
    lv.sweep(&mut x, b, true);
    let next = &levels[1];
    let mut ax = vec![0.0; n];
    lv.apply(&x, &mut ax);
    let mut bc = vec![0.0; next.w * next.h];
    for y in 0..lv.h {
        for xx in 0..lv.w {
            let i = y * lv.w + xx;
            if lv.active[i] {
                bc[(y / 2) * next.w + xx / 2] += b[i] - ax[i];
            }
        }
    }
    let xc = v_cycle(&levels[1..], &bc);
    for y in 0..lv.h {
        for xx in 0..lv.w {
            let i = y * lv.w + xx;
            if lv.active[i] {
                x[i] += xc[(y / 2) * next.w + xx / 2];
            }
        }
    }
    lv.sweep(&mut x, b, false);
    x
}

/// [`solve`] for small grids (a few thousand unknowns, such as the patch
/// windows of [`crate::patch`]): conjugate gradients preconditioned by one
/// aggregation-multigrid V-cycle per iteration, sequential, starting from
/// the given `u` at free pixels (0 where it is not finite). Same equation,
/// same stopping rule and report as [`solve`]; a V-cycle removes the smooth
/// error that Jacobi-preconditioned CG needs O(grid side) iterations for,
/// so a 66² window takes tens of iterations instead of over a hundred, and
/// without fork-join overhead per vector operation. Deterministic (one
/// fixed order of every operation), independent of the thread pool.
pub fn solve_mg(
    width: usize,
    height: usize,
    u: &mut [f32],
    fixed: &[bool],
    rhs: Option<&[f32]>,
    opts: &SolveOptions,
) -> Result<SolveReport, PoissonError> {
    check_inputs(width, height, u, fixed, rhs)?;
    let n = width * height;
    let mut levels = vec![Level::finest(width, height, fixed)];
    while let Some(l) = levels.last()
        && l.w.max(l.h) > 4
    {
        let c = l.coarsen();
        levels.push(c);
    }
    let lv = &levels[0];
    let val = |i: usize| if u[i].is_finite() { u[i] as f64 } else { 0.0 };
    // b = −f + Σ_{fixed n} u_n, as in `cg`.
    let mut b = vec![0.0f64; n];
    for (i, bi) in b.iter_mut().enumerate() {
        if fixed[i] {
            continue;
        }
        let (x, y) = (i % width, i / width);
        let mut s = -rhs.map_or(0.0, |r| r[i] as f64);
        for (ok, j) in [
            (x > 0, i.wrapping_sub(1)),
            (x + 1 < width, i + 1),
            (y > 0, i.wrapping_sub(width)),
            (y + 1 < height, i + width),
        ] {
            if ok && fixed[j] {
                s += val(j);
            }
        }
        *bi = s;
    }
    let mut x: Vec<f64> = (0..n)
        .map(|i| if fixed[i] { 0.0 } else { val(i) })
        .collect();
    let dot = |a: &[f64], c: &[f64]| -> f64 {
        a.iter()
            .zip(c)
            .zip(fixed)
            .filter(|(_, f)| !**f)
            .map(|((a, c), _)| a * c)
            .sum()
    };
    let apply = |v: &[f64], out: &mut [f64]| lv.apply(v, out);
    let unknowns = fixed.iter().filter(|&&f| !f).count();
    let bnorm = dot(&b, &b).sqrt().max(1.0);
    let mut ax = vec![0.0; n];
    apply(&x, &mut ax);
    let mut r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
    let mut z = v_cycle(&levels, &r);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let mut rnorm = dot(&r, &r).sqrt();
    let mut iterations = 0;
    while rnorm > opts.tolerance * bnorm && iterations < opts.max_iterations {
        apply(&p, &mut ax);
        let pap = dot(&p, &ax);
        if pap <= 0.0 {
            break;
        }
        let alpha = rz / pap;
        for i in 0..n {
            if !fixed[i] {
                x[i] += alpha * p[i];
                r[i] -= alpha * ax[i];
            }
        }
        z = v_cycle(&levels, &r);
        let rz_new = dot(&r, &z);
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            p[i] = z[i] + beta * p[i];
        }
        rnorm = dot(&r, &r).sqrt();
        iterations += 1;
    }
    apply(&x, &mut ax);
    let true_r: Vec<f64> = b.iter().zip(&ax).map(|(b, a)| b - a).collect();
    let rel = dot(&true_r, &true_r).sqrt() / bnorm;
    for i in 0..n {
        if !fixed[i] {
            u[i] = x[i] as f32;
        }
    }
    Ok(SolveReport {
        unknowns,
        iterations,
        relative_residual: rel,
        converged: rel <= opts.tolerance,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Max |∇²u − f| over free pixels, from scratch (independent of the solver).
    fn max_defect(w: usize, h: usize, u: &[f32], fixed: &[bool], f: &[f32]) -> f64 {
        let mut worst = 0.0f64;
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if fixed[i] {
                    continue;
                }
                let mut lap = 0.0f64;
                for (dx, dy) in [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)] {
                    let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                    if nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h {
                        lap += u[ny as usize * w + nx as usize] as f64 - u[i] as f64;
                    }
                }
                worst = worst.max((lap - f[i] as f64).abs());
            }
        }
        worst
    }

    #[test]
    fn linear_function_is_reproduced_inside_a_hole() {
        // A plane is harmonic: filling a hole in it must give the plane back.
        let (w, h) = (200, 150);
        let plane = |x: usize, y: usize| 3.0 + 0.25 * x as f32 - 0.5 * y as f32;
        let mut u = vec![0.0f32; w * h];
        let mut fixed = vec![true; w * h];
        for y in 0..h {
            for x in 0..w {
                u[y * w + x] = plane(x, y);
                if (20..180).contains(&x) && (30..120).contains(&y) {
                    fixed[y * w + x] = false;
                    u[y * w + x] = f32::NAN;
                }
            }
        }
        let rep = solve(w, h, &mut u, &fixed, None, &SolveOptions::default()).unwrap();
        assert!(rep.converged, "{rep:?}");
        for y in 0..h {
            for x in 0..w {
                assert!((u[y * w + x] - plane(x, y)).abs() < 1e-3, "({x},{y})");
            }
        }
    }

    #[test]
    fn multigrid_solve_matches_the_stencil_in_few_iterations() {
        // An irregular hole (fixed ring, fixed islands, a Neumann side) on a
        // patch-window-sized grid, with a rough right-hand side.
        let (w, h) = (66, 61);
        let mut u = vec![0.0f32; w * h];
        let mut fixed = vec![false; w * h];
        let mut f = vec![0.0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let island = (x / 9 + y / 7) % 5 == 0 && x % 9 < 3;
                if x < 20 - y / 4 || y == 0 || island {
                    fixed[i] = true;
                    u[i] = 100.0 + (x * 7 % 13) as f32 - y as f32 * 0.3;
                } else {
                    u[i] = 50.0; // a poor initial guess
                }
                f[i] = ((x * 31 + y * 17) % 11) as f32 - 5.0;
            }
        }
        let opts = SolveOptions {
            tolerance: 1e-8,
            max_iterations: 500,
        };
        let mut v = u.clone();
        let rep = solve_mg(w, h, &mut v, &fixed, Some(&f), &opts).unwrap();
        assert!(rep.converged && rep.relative_residual <= 1e-8, "{rep:?}");
        assert!(rep.iterations <= 40, "{rep:?}");
        assert!(max_defect(w, h, &v, &fixed, &f) < 5e-3);
        let mut c = u.clone();
        solve(w, h, &mut c, &fixed, Some(&f), &opts).unwrap();
        let diff = v
            .iter()
            .zip(&c)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(diff < 1e-3, "multigrid and Jacobi CG differ by {diff}");
        assert!(solve_mg(w, h, &mut v, &vec![false; w * h], None, &opts).is_err());
    }

    #[test]
    fn poisson_reaches_tolerance_and_satisfies_the_stencil() {
        let (w, h) = (300, 257);
        let mut u = vec![0.0f32; w * h];
        let mut fixed = vec![false; w * h];
        let mut f = vec![0.0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                if x == 0 || y == 0 {
                    fixed[i] = true;
                    u[i] = (x as f32 * 0.1).min(7.0) + y as f32 * 0.05;
                }
                f[i] = if (x / 37 + y / 23) % 2 == 0 {
                    0.01
                } else {
                    -0.02
                };
            }
        }
        let opts = SolveOptions {
            tolerance: 1e-8,
            max_iterations: 20_000,
        };
        let rep = solve(w, h, &mut u, &fixed, Some(&f), &opts).unwrap();
        assert!(rep.converged && rep.relative_residual <= 1e-8, "{rep:?}");
        // f32 output rounding limits the achievable pointwise defect.
        assert!(max_defect(w, h, &u, &fixed, &f) < 5e-3);
    }

    #[test]
    fn same_bits_for_any_thread_count() {
        let (w, h) = (180, 140);
        let mut u0 = vec![0.0f32; w * h];
        let mut fixed = vec![false; w * h];
        for i in (0..w * h).step_by(97) {
            fixed[i] = true;
            u0[i] = (i % 13) as f32;
        }
        let run = |threads| {
            let mut u = u0.clone();
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| solve(w, h, &mut u, &fixed, None, &SolveOptions::default()))
                .unwrap();
            u.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        };
        assert_eq!(run(1), run(2));
    }

    #[test]
    fn refuses_undetermined_and_bad_input() {
        let mut u = vec![0.0f32; 4];
        assert_eq!(
            solve(2, 2, &mut u, &[false; 4], None, &SolveOptions::default()),
            Err(PoissonError::NothingFixed)
        );
        let mut u = vec![f32::NAN, 0.0, 0.0, 0.0];
        assert_eq!(
            solve(
                2,
                2,
                &mut u,
                &[true, false, false, false],
                None,
                &SolveOptions::default()
            ),
            Err(PoissonError::NotFinite { x: 0, y: 0 })
        );
        assert!(matches!(
            solve(2, 2, &mut u, &[true; 3], None, &SolveOptions::default()),
            Err(PoissonError::Length { .. })
        ));
    }
}
