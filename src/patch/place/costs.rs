//! Candidate costs (seed 004 §6.2, seed 001 §4.1.3).
//!
//! Seed 004's formulas lost their glyphs in extraction; what we reconstructed
//! (and why) is stated at each function. Round one (feature profile + angle,
//! and for hole filling SSD + noise) is integer so a WGSL mirror can be
//! bit-exact; round two (TPS bending, full-resolution SSD, graph cut) runs
//! on a handful of candidates per patch on the CPU and uses `f64`. The
//! hole-filling SSD of round one is the data-parallel stage `fill_ssd`
//! (`stages::fill_ssd`, mirrored in WGSL).

use crate::patch::input::control_point::{ACROSS, ALONG, Cp};

/// The 10 feature transforms of seed 004 §4.2: rotations by `k·45°`
/// (k = 0..8), then mirror in x (`x → −x`) and mirror in y (`y → −y`).
pub const FEATURE_TRANSFORMS: usize = 10;

/// Applies feature transform `t` to an angle; returns (angle, mirrored).
pub fn transform_angle(angle: u16, t: usize) -> (u16, bool) {
    match t {
        0..=7 => (angle.wrapping_add((t as u16) << 13), false),
        8 => (32768u16.wrapping_sub(angle), true),
        _ => (0u16.wrapping_sub(angle), true),
    }
}

/// Signed angle difference in `[-32768, 32767]` units.
pub fn angle_diff(a: u16, b: u16) -> i32 {
    a.wrapping_sub(b) as i16 as i32
}

/// Integer feature cost of candidate control points `cand` (source frame)
/// under transform `t` against the user's `user`, both sorted by angle and
/// of equal degree. Returns `(cost, shift)`: user cp `i` corresponds to
/// candidate cp `order[(i + shift) % d]`, where `order` is the candidate's
/// cps in increasing transformed angle (reversed for mirrors).
///
/// Reconstruction of seed 004 Listing 6.1 / §4.2.1 (glyphs lost):
/// `c = λ_a · Σ_i (Δθ_i / 64)² + λ_f · Σ_i [Σ_k (o_u,ik − o_c,ik)² + Σ_k (p_u,ik − p_c,ik)²]`
/// with `o` the along-path and `p` the across-path profiles normalised to
/// the node's prominence (64 = one prominence). `λ_a = 1`, `λ_f = 1`: one
/// 64th of a turn (5.6°) of misalignment costs as much as a profile sample
/// off by 1/64 of the prominence; both terms are then of similar size for
/// typical candidates. Overflow: |Δθ/64| ≤ 512, profile samples ≤ 1024 in
/// magnitude, at most 8 cps × 15 samples: < 2^31, so `u32` suffices (and
/// the GPU mirror can use `u32`).
pub fn feature_cost(user: &[Cp], cand: &[Cp], t: usize) -> (u32, usize) {
    let d = user.len();
    debug_assert_eq!(d, cand.len());
    // Transformed candidate angles in cyclic (increasing-angle) order.
    let mut order: [usize; 8] = [0; 8];
    let mut ang: [u16; 8] = [0; 8];
    let mirrored = transform_angle(0, t).1;
    for j in 0..d.min(8) {
        order[j] = if mirrored { d - 1 - j } else { j };
        ang[j] = transform_angle(cand[order[j]].angle, t).0;
    }
    let mut best = (u32::MAX, 0);
    for s in 0..d.min(8) {
        let mut cost: u32 = 0;
        for (i, u) in user.iter().enumerate().take(8) {
            let k = (i + s) % d;
            let da = angle_diff(u.angle, ang[k]) / 64;
            cost += (da * da) as u32;
            let c = &cand[order[k]];
            for q in 0..ALONG {
                let e = u.along[q] as i32 - c.along[q] as i32;
                cost += (e * e) as u32;
            }
            for q in 0..ACROSS {
                let cq = if mirrored { ACROSS - 1 - q } else { q };
                let e = u.across[q] as i32 - c.across[cq] as i32;
                cost += (e * e) as u32;
            }
        }
        if cost < best.0 {
            best = (cost, s);
        }
    }
    best
}

/// Noise statistics of seed 004 §6.2.3 (after Cook & DeRose's wavelet
/// noise): for levels `l = 0..3`, the standard deviation of `L_l − up(down(L_l))`
/// where `down` is a 2×2 mean and `up` nearest-neighbour, and `L_{l+1} =
/// down(L_l)`. Heights are integer decimetres; a 2×2 block counts only when
/// all four samples are valid. Orientation-invariant for the 90° transforms
/// (so computed once per candidate, as seed 004 notes).
pub fn noise_levels(n: usize, vals: &[i32], valid: &[bool]) -> [u32; 3] {
    let mut cur: Vec<i32> = vals.to_vec();
    let mut ok: Vec<bool> = valid.to_vec();
    let mut size = n;
    let mut out = [0u32; 3];
    for o in out.iter_mut() {
        let half = size / 2;
        if half == 0 {
            break;
        }
        let mut next = vec![0i32; half * half];
        let mut nok = vec![false; half * half];
        let (mut sum2, mut count) = (0i64, 0i64);
        for by in 0..half {
            for bx in 0..half {
                let idx = [
                    2 * by * size + 2 * bx,
                    2 * by * size + 2 * bx + 1,
                    (2 * by + 1) * size + 2 * bx,
                    (2 * by + 1) * size + 2 * bx + 1,
                ];
                if idx.iter().all(|&i| ok[i]) {
                    let s: i64 = idx.iter().map(|&i| cur[i] as i64).sum();
                    let m = s.div_euclid(4) as i32;
                    for &i in &idx {
                        let r = (cur[i] - m) as i64;
                        sum2 += r * r;
                    }
                    count += 4;
                    next[by * half + bx] = m;
                    nok[by * half + bx] = true;
                }
            }
        }
        *o = if count > 0 {
            isqrt((sum2 / count) as u64) as u32
        } else {
            0
        };
        cur = next;
        ok = nok;
        size = half;
    }
    out
}

/// Noise cost: `Σ_l (σ_u,l − σ_c,l)²` (dm²). Seed 004 Listing 6.3 takes a
/// square root and a scale whose glyphs were lost; we keep the squared form
/// so it adds to the SSD in the same units (both are mean squares of
/// height differences), and weight it in [`crate::patch::Params`].
pub fn noise_cost(u: &[u32; 3], c: &[u32; 3]) -> u64 {
    u.iter()
        .zip(c)
        .map(|(&a, &b)| {
            let d = a as i64 - b as i64;
            (d * d) as u64
        })
        .sum()
}

/// Integer square root (floor).
pub fn isqrt(v: u64) -> u64 {
    if v == 0 {
        return 0;
    }
    let mut x = (v as f64).sqrt() as u64;
    while x * x > v {
        x -= 1;
    }
    while (x + 1) * (x + 1) <= v {
        x += 1;
    }
    x
}

/// DC-corrected SSD over the valid samples: `(n·Σd² − (Σd)²) / n²` with
/// `d = a − b`: the mean squared difference after the best constant offset,
/// because the gradient-domain merge removes any offset anyway (seed 004's
/// "normalized SSD", whose normalisation was lost, read this way).
/// Returns `(cost, n)`; `cost = u64::MAX` when nothing overlaps.
pub fn ssd_dc(a: &[i32], b: &[i32], valid: &[bool]) -> (u64, u64) {
    let (mut n, mut s, mut s2) = (0i64, 0i64, 0i64);
    for ((&x, &y), &v) in a.iter().zip(b).zip(valid) {
        let d = (x - y) as i64 * v as i64;
        n += v as i64;
        s += d;
        s2 += d * d;
    }
    if n == 0 {
        return (u64::MAX, 0);
    }
    (((n * s2 - s * s) / (n * n)) as u64, n as u64)
}

/// A thin-plate spline map `R² → R²` (Bookstein 1989), as in seed 001 §4.1:
/// `f(p) = a₀ + A p + Σ_i w_i U(|p − p_i|)`, `U(r) = r² log r²`, fitted
/// exactly through the control points.
#[derive(Debug, Clone)]
pub struct Tps {
    ctrl: Vec<[f64; 2]>,
    w: Vec<[f64; 2]>,
    a: [[f64; 3]; 2],
}

fn tps_u(r2: f64) -> f64 {
    if r2 <= 0.0 { 0.0 } else { r2 * r2.ln() }
}

impl Tps {
    /// Fits `src[i] → dst[i]`; `None` if the points are degenerate
    /// (collinear or coincident).
    pub fn fit(src: &[[f64; 2]], dst: &[[f64; 2]]) -> Option<Tps> {
        let n = src.len();
        if n < 3 || dst.len() != n {
            return None;
        }
        let m = n + 3;
        let mut mat = vec![vec![0.0f64; m + 2]; m];
        for i in 0..n {
            for j in 0..n {
                let (dx, dy) = (src[i][0] - src[j][0], src[i][1] - src[j][1]);
                mat[i][j] = tps_u(dx * dx + dy * dy);
            }
            mat[i][n] = 1.0;
            mat[i][n + 1] = src[i][0];
            mat[i][n + 2] = src[i][1];
            mat[n][i] = 1.0;
            mat[n + 1][i] = src[i][0];
            mat[n + 2][i] = src[i][1];
            mat[i][m] = dst[i][0];
            mat[i][m + 1] = dst[i][1];
        }
        // Gaussian elimination with partial pivoting.
        for col in 0..m {
            let piv = (col..m).max_by(|&a, &b| mat[a][col].abs().total_cmp(&mat[b][col].abs()))?;
            if mat[piv][col].abs() < 1e-9 {
                return None;
            }
            mat.swap(col, piv);
            let pivot_row = mat[col].clone();
            for (row, r) in mat.iter_mut().enumerate() {
                if row != col {
                    let f = r[col] / pivot_row[col];
                    if f != 0.0 {
                        for (x, p) in r[col..].iter_mut().zip(&pivot_row[col..]) {
                            *x -= f * p;
                        }
                    }
                }
            }
        }
        let sol = |i: usize, c: usize| mat[i][m + c] / mat[i][i];
        Some(Tps {
            ctrl: src.to_vec(),
            w: (0..n).map(|i| [sol(i, 0), sol(i, 1)]).collect(),
            a: [
                [sol(n, 0), sol(n + 1, 0), sol(n + 2, 0)],
                [sol(n, 1), sol(n + 1, 1), sol(n + 2, 1)],
            ],
        })
    }

    /// Evaluates the map.
    pub fn map(&self, p: [f64; 2]) -> [f64; 2] {
        let mut o = [
            self.a[0][0] + self.a[0][1] * p[0] + self.a[0][2] * p[1],
            self.a[1][0] + self.a[1][1] * p[0] + self.a[1][2] * p[1],
        ];
        for (c, w) in self.ctrl.iter().zip(&self.w) {
            let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
            let u = tps_u(dx * dx + dy * dy);
            o[0] += w[0] * u;
            o[1] += w[1] * u;
        }
        o
    }

    /// Bending energy `wₓᵀ K wₓ + w_yᵀ K w_y` (proportional to the integral
    /// bending norm; zero for affine maps).
    pub fn bending_energy(&self) -> f64 {
        let mut e = 0.0;
        for (i, ci) in self.ctrl.iter().enumerate() {
            for (j, cj) in self.ctrl.iter().enumerate() {
                let (dx, dy) = (ci[0] - cj[0], ci[1] - cj[1]);
                let k = tps_u(dx * dx + dy * dy);
                e += k * (self.w[i][0] * self.w[j][0] + self.w[i][1] * self.w[j][1]);
            }
        }
        e.abs()
    }

    /// How far the affine part is from a rotation/reflection:
    /// `‖AᵀA − I‖²_F` (seed 001's bending energy is blind to affine
    /// stretch, which three control points of a path can only produce).
    pub fn stretch(&self) -> f64 {
        let (a, b, c, d) = (self.a[0][1], self.a[0][2], self.a[1][1], self.a[1][2]);
        let (m00, m01, m11) = (a * a + c * c - 1.0, a * b + c * d, b * b + d * d - 1.0);
        m00 * m00 + 2.0 * m01 * m01 + m11 * m11
    }
}
