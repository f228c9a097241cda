//! A Poisson solver on a masked grid: find `u` on the free pixels such that
//! `∇²u = f`, with every fixed pixel acting as a Dirichlet boundary value and
//! the grid border as a Neumann (zero-flux) boundary.
//!
//! One solver serves every place that needs it: harmonic nodata filling
//! (`f = 0`, see [`crate::nodata`]), Poisson seam removal and gradient-domain
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
//! holes converge in tens of iterations per level ([`Method::Cascadic`]).
//! For many small solves (the patch engine's windows),
//! [`Method::Multigrid`] instead preconditions CG with a multigrid V-cycle
//! and runs sequentially, which needs several times fewer iterations and no
//! fork-join per vector operation.
//!
//! Determinism: every reduction sums fixed-size chunks in index order, so the
//! result is bit-identical for any number of threads.

mod cascadic;
mod multigrid;
mod pcg;
#[cfg(test)]
mod tests;

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

/// Which solver runs: the same equation, stopping rule and report, for
/// grids of different sizes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// For large grids (whole-DEM nodata filling, blending): a cascadic
    /// start, each level solved on a 2x coarser grid first and interpolated
    /// up as the initial guess (the given one at free pixels is ignored),
    /// then parallel Jacobi-preconditioned CG on the finest level.
    Cascadic,
    /// For small grids (a few thousand unknowns, such as the patch windows
    /// of [`crate::patch`]): CG preconditioned by one aggregation-multigrid
    /// V-cycle per iteration, sequential, starting from the given `u` at
    /// free pixels (0 where it is not finite). A V-cycle removes the smooth
    /// error that Jacobi-preconditioned CG needs O(grid side) iterations
    /// for, so a 66² window takes tens of iterations instead of over a
    /// hundred, and without fork-join overhead per vector operation.
    /// Deterministic (one fixed order of every operation), independent of
    /// the thread pool.
    Multigrid,
}

/// Solves in place with `method`. `u` holds the boundary values at fixed
/// pixels (read) and the initial guess at free pixels (see [`Method`]); on
/// return the free pixels hold the solution. `rhs` is `f` (zero if `None`).
/// The inputs are checked first, for both methods alike.
pub fn solve(
    method: Method,
    width: usize,
    height: usize,
    u: &mut [f32],
    fixed: &[bool],
    rhs: Option<&[f32]>,
    opts: &SolveOptions,
) -> Result<SolveReport, PoissonError> {
    check_inputs(width, height, u, fixed, rhs)?;
    let problem = Problem {
        width,
        height,
        u,
        fixed,
        rhs,
    };
    Ok(match method {
        Method::Cascadic => cascadic::solve(problem, opts),
        Method::Multigrid => multigrid::solve(problem, opts),
    })
}

/// A checked problem, as [`solve`] hands it to either method.
struct Problem<'a> {
    width: usize,
    height: usize,
    u: &'a mut [f32],
    fixed: &'a [bool],
    rhs: Option<&'a [f32]>,
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

/// The checks [`solve`] makes before touching anything: every slice
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
