//! The solvers against the stencil computed from scratch, against each
//! other, across thread counts, and on bad input.

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

/// A `w × h` problem `(u, fixed, f)` built pixel by pixel: `cell(x, y)`
/// says whether the pixel is fixed, its value (the boundary value, or the
/// initial guess at a free pixel) and its right-hand side.
fn problem(
    w: usize,
    h: usize,
    cell: impl Fn(usize, usize) -> (bool, f32, f32),
) -> (Vec<f32>, Vec<bool>, Vec<f32>) {
    let mut u = vec![0.0f32; w * h];
    let mut fixed = vec![false; w * h];
    let mut f = vec![0.0f32; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            (fixed[i], u[i], f[i]) = cell(x, y);
        }
    }
    (u, fixed, f)
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
    let opts = SolveOptions::default();
    let rep = solve(Method::Cascadic, w, h, &mut u, &fixed, None, &opts).unwrap();
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
    let (u, fixed, f) = problem(w, h, |x, y| {
        let island = (x / 9 + y / 7) % 5 == 0 && x % 9 < 3;
        let f = ((x * 31 + y * 17) % 11) as f32 - 5.0;
        if x < 20 - y / 4 || y == 0 || island {
            (true, 100.0 + (x * 7 % 13) as f32 - y as f32 * 0.3, f)
        } else {
            (false, 50.0, f) // a poor initial guess
        }
    });
    let opts = SolveOptions {
        tolerance: 1e-8,
        max_iterations: 500,
    };
    let mut v = u.clone();
    let rep = solve(Method::Multigrid, w, h, &mut v, &fixed, Some(&f), &opts).unwrap();
    assert!(rep.converged && rep.relative_residual <= 1e-8, "{rep:?}");
    assert!(rep.iterations <= 40, "{rep:?}");
    assert!(max_defect(w, h, &v, &fixed, &f) < 5e-3);
    let mut c = u.clone();
    solve(Method::Cascadic, w, h, &mut c, &fixed, Some(&f), &opts).unwrap();
    let diff = v
        .iter()
        .zip(&c)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(diff < 1e-3, "multigrid and Jacobi CG differ by {diff}");
    let none_fixed = vec![false; w * h];
    assert!(solve(Method::Multigrid, w, h, &mut v, &none_fixed, None, &opts).is_err());
}

#[test]
fn poisson_reaches_tolerance_and_satisfies_the_stencil() {
    let (w, h) = (300, 257);
    let (mut u, fixed, f) = problem(w, h, |x, y| {
        let f = if (x / 37 + y / 23) % 2 == 0 {
            0.01
        } else {
            -0.02
        };
        if x == 0 || y == 0 {
            (true, (x as f32 * 0.1).min(7.0) + y as f32 * 0.05, f)
        } else {
            (false, 0.0, f)
        }
    });
    let opts = SolveOptions {
        tolerance: 1e-8,
        max_iterations: 20_000,
    };
    let rep = solve(Method::Cascadic, w, h, &mut u, &fixed, Some(&f), &opts).unwrap();
    assert!(rep.converged && rep.relative_residual <= 1e-8, "{rep:?}");
    // f32 output rounding limits the achievable pointwise defect.
    assert!(max_defect(w, h, &u, &fixed, &f) < 5e-3);
}

#[test]
fn same_bits_for_any_thread_count() {
    let opts = SolveOptions::default();
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
            .install(|| solve(Method::Cascadic, w, h, &mut u, &fixed, None, &opts))
            .unwrap();
        u.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn refuses_undetermined_and_bad_input() {
    let opts = SolveOptions::default();
    let mut u = vec![0.0f32; 4];
    assert_eq!(
        solve(Method::Cascadic, 2, 2, &mut u, &[false; 4], None, &opts),
        Err(PoissonError::NothingFixed)
    );
    let mut u = vec![f32::NAN, 0.0, 0.0, 0.0];
    assert_eq!(
        solve(
            Method::Cascadic,
            2,
            2,
            &mut u,
            &[true, false, false, false],
            None,
            &opts
        ),
        Err(PoissonError::NotFinite { x: 0, y: 0 })
    );
    assert!(matches!(
        solve(Method::Cascadic, 2, 2, &mut u, &[true; 3], None, &opts),
        Err(PoissonError::Length { .. })
    ));
}
