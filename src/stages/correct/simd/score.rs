//! Scoring (paper eq. 7): the synthesis neighbourhood N_S of a pixel and
//! the cost of each gathered candidate against it, two diagonals per
//! vector.

use super::super::{CLAMP, DIAGONALS, FLAT, Prior};
use super::gather::Pending;
use super::grid::{Grid, Window, at, window};
use wide::{i16x8, i32x8};

/// Two packed appearance texels as eight i16 lanes.
#[inline(always)]
fn pair(app: &[u64], a: i32, b: i32) -> i16x8 {
    wide::bytemuck::cast([app[a as usize], app[b as usize]])
}

/// The synthesis neighbourhood N_S (×3), two diagonals per vector, mode 1
/// including the offsets V.
#[derive(Clone, Copy)]
pub(super) struct Neighbourhood {
    ns01: i32x8,
    ns23: i32x8,
}

/// Score (×κ) and optimal offset of the candidate whose texel index is
/// `q` in an exemplar of row stride `s` (same arithmetic as the scalar
/// `score`; the prior's weight P is a constant, so its closed form divides
/// by a constant).
#[inline(always)]
fn score<const P: u32>(
    app: &[u64],
    ns: &Neighbourhood,
    q: i32,
    s: i32,
    kappa: u32,
    vp: i32,
) -> (u32, i32) {
    score_with::<P>(app, ns, q, s, kappa, None, vp)
}

/// [`score`] with the offset fixed to `fixed` when given (a coherent
/// previous result keeps its own offset).
#[inline(always)]
pub(super) fn score_with<const P: u32>(
    app: &[u64],
    ns: &Neighbourhood,
    q: i32,
    s: i32,
    kappa: u32,
    fixed: Option<i32>,
    vp: i32,
) -> (u32, i32) {
    // DIAGONALS order: (−1,−1), (1,−1), (−1,1), (1,1).
    let m01 = i32x8::from_i16x8(pair(app, q - s - 1, q - s + 1));
    let m23 = i32x8::from_i16x8(pair(app, q + s - 1, q + s + 1));
    let d01 = ns.ns01 - (m01 + m01 + m01);
    let d23 = ns.ns23 - (m23 + m23 + m23);
    let (a, b) = (d01.to_array(), d23.to_array());
    let (ma, mb) = (m01.to_array(), m23.to_array());
    let sum1 = a[0] + a[4] + b[0] + b[4];
    // Both priors have constant weights, so each closed form divides by a
    // constant (the branch picks one, never a run-time divisor).
    let flat = Prior { weight: P, v: vp }.for_candidate([ma[0], ma[4], mb[0], mb[4]]) == FLAT;
    let prior = if flat {
        FLAT
    } else {
        Prior { weight: P, v: vp }
    };
    let h = fixed.unwrap_or_else(|| {
        if flat {
            FLAT.optimal(sum1)
        } else {
            Prior { weight: P, v: vp }.optimal(sum1)
        }
    });
    let h3 = 3 * h;
    let off = i32x8::new([h3, 0, 0, 0, h3, 0, 0, 0]);
    // Clamping after the saturating narrowing equals clamping before it
    // (saturation is monotone and ±CLAMP lies inside i16), and i16 min/max
    // are single instructions where i32 ones are not (SSE2).
    let lo = i16x8::splat(-CLAMP as i16);
    let hi = i16x8::splat(CLAMP as i16);
    let r01 = i16x8::from_i32x8_saturate(d01 - off).max(lo).min(hi);
    let r23 = i16x8::from_i32x8_saturate(d23 - off).max(lo).min(hi);
    let sums = (r01.dot(r01) + r23.dot(r23)).to_array();
    let s = (sums[0] as u32)
        .wrapping_add(sums[1] as u32)
        .wrapping_add(sums[2] as u32)
        .wrapping_add(sums[3] as u32)
        .wrapping_add(prior.cost(h));
    (s * kappa, h)
}

/// N_S (eq. 5–6) of the pixel in grid column `c`: per diagonal δ,
/// g(p+δ, v) = A(S(p+δ+v) − v) + V(p+δ+v)·a for v ∈ {0, (δx, 0), (0, δy)}.
/// Two diagonals per vector, three texels each; V joins mode 1.
#[inline(always)]
pub(super) fn neighbourhood(app: &[u64], grid: &Grid, c: usize) -> Neighbourhood {
    let win = window(grid, c);
    Neighbourhood {
        ns01: diagonals(app, &win, 0),
        ns23: diagonals(app, &win, 2),
    }
}

/// Diagonals k and k + 1 of N_S, summed, as one vector.
#[inline(always)]
fn diagonals(app: &[u64], win: &Window<'_>, k: usize) -> i32x8 {
    let ((t0, v0), (t1, v1)) = (diagonal(app, win, k), diagonal(app, win, k + 1));
    let mut sum = i32x8::new([v0, 0, 0, 0, v1, 0, 0, 0]);
    for j in 0..3 {
        sum += i32x8::from_i16x8(wide::bytemuck::cast([t0[j], t1[j]]));
    }
    sum
}

/// Diagonal k of N_S: its three appearance texels and their ΣV.
#[inline(always)]
fn diagonal(app: &[u64], win: &Window<'_>, k: usize) -> ([u64; 3], i32) {
    let (dx, dy) = DIAGONALS[k];
    let a = at(win, dx, dy);
    let b = at(win, 2 * dx, dy);
    let cc = at(win, dx, 2 * dy);
    let texels = [
        app[a.idx as usize],
        app[(b.idx - dx) as usize],
        app[(cc.idx - dy * cc.stride) as usize],
    ];
    (texels, a.v + b.v + cc.v)
}

/// The best gathered candidate whose cost is below `bar`:
/// (cost, index, optimal offset), index `usize::MAX` if none is.
#[inline(always)]
pub(super) fn best_of<const P: u32>(
    app: &[u64],
    ns: &Neighbourhood,
    p: &Pending,
    bar: u32,
    vp: i32,
) -> (u32, usize, i32) {
    let mut best = (bar, usize::MAX, 0i32);
    for (i, c) in p.cands[..p.count].iter().enumerate() {
        let (sc, hh) = score::<P>(app, ns, c.idx, c.stride, c.kappa, vp);
        if sc < best.0 {
            best = (sc, i, hh);
        }
    }
    best
}
