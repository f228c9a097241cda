//! [`Method::Multigrid`], the solver for many small grids (the patch
//! engine's windows): CG preconditioned by an aggregation-multigrid
//! V-cycle, all sequential, so a solve has no fork-join overhead.
//!
//! [`Method::Multigrid`]: super::Method::Multigrid

use super::pcg::degree;
use super::{Problem, SolveOptions, SolveReport};

/// One level of the multigrid hierarchy of [`solve`]: a 5-point
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
    /// The finest level: the operator of every method restricted to free
    /// pixels.
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

/// Solves a checked problem in place, starting from the given `u` at free
/// pixels (0 where it is not finite).
pub(super) fn solve(problem: Problem<'_>, opts: &SolveOptions) -> SolveReport {
    let (width, height, fixed, rhs) = (problem.width, problem.height, problem.fixed, problem.rhs);
    let u = problem.u;
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
    SolveReport {
        unknowns,
        iterations,
        relative_residual: rel,
        converged: rel <= opts.tolerance,
    }
}
