//! Appearance space A^i (paper §4, after Lefebvre & Hoppe 2006): each texel
//! is described by its Gaussian-weighted 5×5 neighbourhood, reduced by PCA to
//! four modes, the first being the weighted mean height.
//!
//! The decomposition we use makes those four numbers a metric in height units:
//! with weights `g` (Σg = 1), weighted mean `μ = Σ g·n` and residual
//! `y = √g ∘ (n − μ)`, the weighted SSD of two neighbourhoods splits exactly as
//! `Σ g (n − n')² = (μ − μ')² + ‖y − y'‖²` (the cross term vanishes because
//! `Σ g (n − μ) = 0`). So mode 1 is `μ` itself, modes 2–4 are the projections
//! of `y` on its top three principal directions, and all four are quantized
//! with the *same* scale as heights (DESIGN §4): distances stay isotropic and
//! a height offset `h` changes mode 1 only, which is what makes the closed-form
//! optimal offset of eq. 7 possible.
//!
//! Storage: one packed 8-byte texel, four i16 lanes. Mode 1 is biased by
//! −32768 into the signed range (offsets cancel in every difference);
//! modes 2–4 are clamped to ±32767 units (a residual that large needs a cliff of
//! half the database's range within 5 texels; clamping only affects scoring of
//! such texels, which never match anything well anyway).

use super::kdtree::{KEY_DIMS, Key};
use super::pyramid::{Grid, Quantization};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Gaussian σ of the neighbourhood weights, in texels. The paper does not
/// give one; 1.25 keeps the outer ring of the 5×5 meaningful (corner weight
/// ≈ 0.08 of the centre) without flattening the window.
pub const SIGMA: f64 = 1.25;
/// Neighbourhood size (5×5).
pub const N: usize = 25;
/// Lanes of a PatchMatch feature vector (25 residuals padded to 32 for SIMD).
pub const FEATURE_LANES: usize = 32;
/// Bias added to mode 1 to store it as i16.
pub const MODE1_BIAS: i32 = -32768;

/// Normalised Gaussian weights of the 5×5 window, row-major, and their roots.
pub fn weights() -> ([f64; N], [f64; N]) {
    let mut g = [0.0; N];
    for (k, w) in g.iter_mut().enumerate() {
        let (dx, dy) = ((k % 5) as f64 - 2.0, (k / 5) as f64 - 2.0);
        *w = (-(dx * dx + dy * dy) / (2.0 * SIGMA * SIGMA)).exp();
    }
    let s: f64 = g.iter().sum();
    g.iter_mut().for_each(|w| *w /= s);
    let mut r = [0.0; N];
    for k in 0..N {
        r[k] = g[k].sqrt();
    }
    (g, r)
}

/// Weighted mean (units) and residual vector y (units) of texel (x, y);
/// the window is clamped to the exemplar (edge replication).
#[inline]
fn neighbourhood(
    grid: &Grid,
    q: &Quantization,
    g: &[f64; N],
    sg: &[f64; N],
    x: usize,
    y: usize,
) -> (f64, [f64; N]) {
    let mut n = [0.0; N];
    let mut mean = 0.0;
    for k in 0..N {
        let v = grid.get_clamped(
            x as isize + (k % 5) as isize - 2,
            y as isize + (k / 5) as isize - 2,
        );
        n[k] = q.units(v as f64);
        mean += g[k] * n[k];
    }
    for k in 0..N {
        n[k] = sg[k] * (n[k] - mean);
    }
    (mean, n)
}

/// The principal directions of one level (modes 2–4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Basis {
    /// Unit vectors in residual space, strongest first.
    pub modes: Vec<Vec<f32>>,
    /// Variance (units²) along each stored mode.
    pub variances: Vec<f64>,
    /// Fraction of the residual variance the stored modes explain.
    pub explained: f64,
}

/// The stored basis and the wider one used to seed the similarity search.
pub struct Pca {
    pub basis: Basis,
    /// Top [`KEY_DIMS`] unit directions (the first three are `basis.modes`).
    pub search: Vec<[f64; N]>,
    /// Largest |residual component| over the level (units), which sets the
    /// feature scale.
    pub max_residual: f64,
}

/// Bound on |feature component|: differences of two features then fit i16
/// and a pair of squared differences fits i32, so the similarity distance is
/// an exact integer computed with 16-bit multiply-adds (see `patchmatch`).
pub const FEATURE_MAX: f64 = 8191.0;

/// Covariance of residuals over every texel of `grids`, then its leading
/// eigenvectors. Rows are reduced in a fixed order, so the basis does not
/// depend on the thread count.
pub fn pca(grids: &[&Grid], q: &Quantization) -> Pca {
    let (g, sg) = weights();
    let rows: Vec<(usize, usize)> = grids
        .iter()
        .enumerate()
        .flat_map(|(e, gr)| (0..gr.height).map(move |y| (e, y)))
        .collect();
    let partials: Vec<(Vec<f64>, f64)> = rows
        .par_iter()
        .map(|&(e, y)| {
            let gr = grids[e];
            let mut c = vec![0.0f64; N * N];
            let mut max = 0.0f64;
            for x in 0..gr.width {
                let (_, r) = neighbourhood(gr, q, &g, &sg, x, y);
                for i in 0..N {
                    max = max.max(r[i].abs());
                    for j in i..N {
                        c[i * N + j] += r[i] * r[j];
                    }
                }
            }
            (c, max)
        })
        .collect();
    let mut cov = vec![0.0f64; N * N];
    let mut max_residual = 0.0f64;
    for (p, m) in &partials {
        for (c, v) in cov.iter_mut().zip(p) {
            *c += v;
        }
        max_residual = max_residual.max(*m);
    }
    let count: usize = grids.iter().map(|g| g.width * g.height).sum();
    for i in 0..N {
        for j in i..N {
            let v = cov[i * N + j] / count as f64;
            cov[i * N + j] = v;
            cov[j * N + i] = v;
        }
    }
    let (values, vectors) = jacobi_eigen(cov);
    let mut order: Vec<usize> = (0..N).collect();
    order.sort_by(|&a, &b| values[b].total_cmp(&values[a]).then(a.cmp(&b)));
    let total: f64 = values.iter().map(|v| v.max(0.0)).sum();
    let mut modes = Vec::new();
    let mut variances = Vec::new();
    let mut search = Vec::new();
    for (rank, &k) in order.iter().take(KEY_DIMS).enumerate() {
        let mut v: Vec<f64> = (0..N).map(|i| vectors[i * N + k]).collect();
        // Sign convention: the largest-magnitude component is positive, so
        // the basis is a deterministic function of the data.
        let big = (0..N)
            .max_by(|&a, &b| v[a].abs().total_cmp(&v[b].abs()).then(b.cmp(&a)))
            .expect("N > 0");
        if v[big] < 0.0 {
            v.iter_mut().for_each(|c| *c = -*c);
        }
        search.push(std::array::from_fn(|i| v[i]));
        if rank < 3 {
            modes.push(v.iter().map(|&c| c as f32).collect());
            variances.push(values[k].max(0.0));
        }
    }
    let explained = if total > 0.0 {
        variances.iter().sum::<f64>() / total
    } else {
        1.0
    };
    Pca {
        basis: Basis {
            modes,
            variances,
            explained,
        },
        search,
        max_residual,
    }
}

/// Packs four i16 modes into the stored texel.
#[inline(always)]
pub fn pack_texel(m: [i16; 4]) -> u64 {
    (m[0] as u16 as u64)
        | (m[1] as u16 as u64) << 16
        | (m[2] as u16 as u64) << 32
        | (m[3] as u16 as u64) << 48
}

/// Inverse of [`pack_texel`].
#[inline(always)]
pub fn unpack_texel(t: u64) -> [i16; 4] {
    [
        t as i16,
        (t >> 16) as i16,
        (t >> 32) as i16,
        (t >> 48) as i16,
    ]
}

fn clamp_i16(v: f64) -> i16 {
    v.round().clamp(-32767.0, 32767.0) as i16
}

/// What [`project`] computes for every texel of a level, in layout order.
pub struct Projected {
    /// Packed appearance texels (stored).
    pub texels: Vec<u64>,
    /// PatchMatch features: 25-d residuals divided by `feature_scale`,
    /// rounded, zero-padded; every component within ±[`FEATURE_MAX`].
    pub features: Vec<[i16; FEATURE_LANES]>,
    /// Height units per feature unit at this level.
    pub feature_scale: f64,
    /// Coordinates in the search space (top [`KEY_DIMS`] directions).
    pub keys: Vec<Key>,
}

/// Appearance texels, PatchMatch features and search keys of every
/// exemplar at one level.
pub fn project(grids: &[&Grid], q: &Quantization, pca: &Pca) -> Projected {
    let basis = &pca.basis;
    let feature_scale = if pca.max_residual > 0.0 {
        pca.max_residual / FEATURE_MAX
    } else {
        1.0
    };
    let (g, sg) = weights();
    let mut out = Projected {
        texels: Vec::new(),
        features: Vec::new(),
        feature_scale,
        keys: Vec::new(),
    };
    for gr in grids {
        type Row = (Vec<u64>, Vec<[i16; FEATURE_LANES]>, Vec<Key>);
        let rows: Vec<Row> = (0..gr.height)
            .into_par_iter()
            .map(|y| {
                let mut t = Vec::with_capacity(gr.width);
                let mut f = Vec::with_capacity(gr.width);
                let mut keys = Vec::with_capacity(gr.width);
                for x in 0..gr.width {
                    let (mean, r) = neighbourhood(gr, q, &g, &sg, x, y);
                    let mut m = [0i16; 4];
                    m[0] = (mean.round().clamp(0.0, 65535.0) as i32 + MODE1_BIAS) as i16;
                    for (k, mode) in basis.modes.iter().enumerate() {
                        let p: f64 = mode.iter().zip(&r).map(|(&e, &v)| e as f64 * v).sum();
                        m[k + 1] = clamp_i16(p);
                    }
                    t.push(pack_texel(m));
                    let mut feat = [0i16; FEATURE_LANES];
                    for k in 0..N {
                        feat[k] = (r[k] / feature_scale)
                            .round()
                            .clamp(-FEATURE_MAX, FEATURE_MAX)
                            as i16;
                    }
                    f.push(feat);
                    keys.push(std::array::from_fn(|d| {
                        pca.search.get(d).map_or(0.0, |e| {
                            e.iter().zip(&r).map(|(a, b)| a * b).sum::<f64>() as f32
                        })
                    }));
                }
                (t, f, keys)
            })
            .collect();
        for (t, f, k) in rows {
            out.texels.extend(t);
            out.features.extend(f);
            out.keys.extend(k);
        }
    }
    out
}

/// Eigen-decomposition of a symmetric N×N matrix by cyclic Jacobi rotations.
/// Returns (eigenvalues, eigenvectors as columns, row-major). N = 25 is tiny;
/// Jacobi is simple, unconditionally stable and accurate to the last bits.
fn jacobi_eigen(mut a: Vec<f64>) -> (Vec<f64>, Vec<f64>) {
    let mut v = vec![0.0f64; N * N];
    for i in 0..N {
        v[i * N + i] = 1.0;
    }
    for _sweep in 0..100 {
        let off: f64 = (0..N)
            .flat_map(|i| (0..N).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * N + j] * a[i * N + j])
            .sum();
        let diag: f64 = (0..N).map(|i| a[i * N + i] * a[i * N + i]).sum();
        if off <= 1e-30 * diag.max(1e-300) {
            break;
        }
        for p in 0..N {
            for q in p + 1..N {
                let apq = a[p * N + q];
                if apq.abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q * N + q] - a[p * N + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..N {
                    let akp = a[k * N + p];
                    let akq = a[k * N + q];
                    a[k * N + p] = c * akp - s * akq;
                    a[k * N + q] = s * akp + c * akq;
                }
                for k in 0..N {
                    let apk = a[p * N + k];
                    let aqk = a[q * N + k];
                    a[p * N + k] = c * apk - s * aqk;
                    a[q * N + k] = s * apk + c * aqk;
                }
                for k in 0..N {
                    let vkp = v[k * N + p];
                    let vkq = v[k * N + q];
                    v[k * N + p] = c * vkp - s * vkq;
                    v[k * N + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ((0..N).map(|i| a[i * N + i]).collect(), v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn terrain(w: usize, h: usize) -> Grid {
        let data = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                100.0 + 40.0 * ((x * 0.21).sin() * (y * 0.13).cos()) + 0.5 * x + ((x * y) % 7.0)
            })
            .collect();
        Grid {
            width: w,
            height: h,
            data,
        }
    }

    #[test]
    fn weights_are_normalised() {
        let (g, sg) = weights();
        assert!((g.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((sg[12] * sg[12] - g[12]).abs() < 1e-15);
    }

    #[test]
    fn modes_are_orthonormal_and_sorted() {
        let t = terrain(64, 48);
        let q = Quantization::spanning(0.0, 300.0);
        let b = pca(&[&t], &q).basis;
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = b.modes[i]
                    .iter()
                    .zip(&b.modes[j])
                    .map(|(a, b)| *a as f64 * *b as f64)
                    .sum();
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((d - want).abs() < 1e-5, "modes {i},{j}: {d}");
            }
        }
        assert!(b.variances[0] >= b.variances[1] && b.variances[1] >= b.variances[2]);
        assert!(b.explained > 0.0 && b.explained <= 1.0);
    }

    #[test]
    fn jacobi_diagonalises() {
        let mut a = vec![0.0; N * N];
        for i in 0..N {
            for j in 0..N {
                a[i * N + j] = 1.0 / (1.0 + i as f64 + j as f64);
            }
        }
        let (vals, vecs) = jacobi_eigen(a.clone());
        // A·v = λ·v for every column.
        for k in 0..N {
            for i in 0..N {
                let av: f64 = (0..N).map(|j| a[i * N + j] * vecs[j * N + k]).sum();
                assert!((av - vals[k] * vecs[i * N + k]).abs() < 1e-9);
            }
        }
    }

    #[test]
    fn texel_packing_round_trips() {
        for m in [
            [0, 0, 0, 0],
            [-32768, 32767, -1, 1],
            [12345, -2, 300, -32767],
        ] {
            assert_eq!(unpack_texel(pack_texel(m)), m);
        }
    }
}
