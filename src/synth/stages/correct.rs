//! Stage `correct`: one subpass of the correction (paper eq. 3–7, DESIGN §5).
//!
//! For every pixel p of one parity class `(x mod 2, y mod 2)`:
//! 1. the synthesis neighbourhood N_S (eq. 5–6): for each diagonal δ, the sum
//!    over v ∈ {0, (δx,0), (0,δy)} of `A(S(p+δ+v) − v) + V(p+δ+v)·a`;
//! 2. the candidates Q (eq. 3): for Δ ∈ {−1,0,1}², u = S(p+Δ) − Δ and its
//!    k = 2 similarity entries C₁(u) = u, C₂(u); identical u are evaluated
//!    once (in coherent patches most of the nine coincide);
//! 3. the score of each candidate q (eq. 7): `κ·min_h ‖N_S − N_E(q, h)‖²`
//!    with N_E the four diagonal appearance texels of q plus `h` on mode 1,
//!    κ = 1 for C₁ and 2 for C₂ (the "κ = 1/2");
//! 4. the best candidate and its optimal h become S(p) and V(p).
//!
//! Integer arithmetic (DESIGN §6), identical in the WGSL mirror:
//! - N_S is kept as the *sum* of its three vectors (×3) so no division is
//!   needed; N_E is scaled by 3 to match.
//! - h minimises Σ_δ (d₁(δ) − 3h)² where d₁ = N_S₁ − 3·A₁(q+δ):
//!   h = ⌊(Σ d₁ + 6) / 12⌋ (nearest, ties up), a floor division.
//! - Each residual is clamped to ±[`CLAMP`] before squaring: 16 terms × κ ≤ 2
//!   then stay below 2³² in a u32 (2·16·11584² = 4 294 049 792). Clamping
//!   only flattens the scores of very bad candidates.
//! - Ties keep the earlier candidate: Δ in [`DELTAS`] order (Δ = 0 first, so
//!   a pixel keeps its own coordinate on a tie), C₁ before C₂.
//!
//! Scoring reads the nearest texel of each coordinate; the candidate keeps
//! the fractional part of the S(p+Δ) it came from, so sub-texel jitter
//! survives correction (see [`crate::synth::fixed`]).
//!
//! Reads never touch another pixel of the same subpass (neighbours at odd
//! offsets, or at (±2, ±1)/(±1, ±2)), and borders reflect by 2 so parity is
//! kept: subpasses run in place, in parallel, deterministically. Outside
//! the level, coordinates are extrapolated from the reflected pixel (see
//! [`neighbour`]).

use crate::database::appearance::unpack_texel;
use crate::synth::atlas::AtlasLevel;
use crate::synth::fixed::{Coord, FRAC_BITS, div_floor, round};
use crate::synth::state::State;
use rayon::prelude::*;

/// Residual clamp (in ×3 height units), see the module docs.
pub const CLAMP: i32 = 11_584;

/// Candidate offsets Δ, in evaluation (and tie-break) order.
pub const DELTAS: [(i32, i32); 9] = [
    (0, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// The four diagonals δ of the neighbourhoods.
pub const DIAGONALS: [(i32, i32); 4] = [(-1, -1), (1, -1), (-1, 1), (1, 1)];

/// Parameters of one subpass.
#[derive(Debug, Clone, Copy)]
pub struct CorrectParams {
    /// Parity class: pixels with `x % 2 == px && y % 2 == py`.
    pub px: u32,
    pub py: u32,
}

/// Subpass order within a pass (the four parity classes).
pub const SUBPASSES: [(u32, u32); 4] = [(0, 0), (1, 0), (0, 1), (1, 1)];

/// Reflects a coordinate at the level border by 2 (keeps parity); the
/// level is at least 2 wide and offsets are at most ±2.
#[inline(always)]
fn reflect(c: i32, n: i32) -> i32 {
    if c < 0 {
        c + 2
    } else if c >= n {
        c - 2
    } else {
        c
    }
}

/// N_S: per diagonal, the 4 modes (×3), mode 1 including V.
type Neighbourhood = [[i32; 4]; 4];

#[inline(always)]
fn add_texel(acc: &mut [i32; 4], t: u64, v: i32) {
    let m = unpack_texel(t);
    acc[0] += m[0] as i32 + v;
    acc[1] += m[1] as i32;
    acc[2] += m[2] as i32;
    acc[3] += m[3] as i32;
}

/// Score (×κ) and optimal offset of candidate texel (qx, qy).
#[inline(always)]
fn score(atlas: &AtlasLevel<'_>, ns: &Neighbourhood, qx: i32, qy: i32, kappa: u32) -> (u32, i32) {
    let mut d = [[0i32; 4]; 4];
    let mut sum1 = 0;
    for (k, &(dx, dy)) in DIAGONALS.iter().enumerate() {
        let m = unpack_texel(atlas.appearance(qx + dx, qy + dy));
        for j in 0..4 {
            d[k][j] = ns[k][j] - 3 * m[j] as i32;
        }
        sum1 += d[k][0];
    }
    let h = div_floor(sum1 + 6, 12);
    let mut s = 0u32;
    for dk in &d {
        let r1 = (dk[0] - 3 * h).clamp(-CLAMP, CLAMP);
        s += (r1 * r1) as u32;
        for &dj in &dk[1..] {
            let r = dj.clamp(-CLAMP, CLAMP);
            s += (r * r) as u32;
        }
    }
    (s * kappa, h)
}

/// What a neighbour contributes: the texel its coordinate points at (as
/// seen from where the neighbour should be), the fraction of that
/// coordinate, and its offset V.
struct Neighbour {
    tx: i32,
    ty: i32,
    frac: (i32, i32),
    v: i32,
}

/// Reads the neighbour at (x, y), which may lie outside the level.
///
/// Outside pixels read their parity-preserving reflection r (so a subpass
/// still never reads its own class) and *extrapolate* its coordinate back to
/// where the missing pixel would be: `round(S(r)) + ((x, y) − r)`, clamped to
/// stay one texel inside the exemplar. A coherent patch thus continues past
/// the border instead of folding back on itself, which would make border
/// pixels mismatch and seed offsets V that diffuse inward level after level.
#[inline(always)]
fn neighbour(atlas: &AtlasLevel<'_>, st: &State, x: i32, y: i32) -> Neighbour {
    let (w, h) = (st.width as i32, st.height as i32);
    let (rx, ry) = (reflect(x, w), reflect(y, h));
    let i = (ry * w + rx) as usize;
    let s = st.s(i);
    let (sx, sy) = (round(s.x), round(s.y));
    let frac = (s.x - (sx << FRAC_BITS), s.y - (sy << FRAC_BITS));
    let (mut tx, mut ty) = (sx, sy);
    if (rx, ry) != (x, y) {
        let col = &atlas.columns[sx as usize];
        // Interior bounds widened by one: lookups at ±1 stay in the exemplar.
        tx = (sx + x - rx).clamp(col.min_x - 1, col.max_x + 1);
        ty = (sy + y - ry).clamp(1, col.max_y + 1);
    }
    Neighbour {
        tx,
        ty,
        frac,
        v: st.v(i),
    }
}

/// Corrects one pixel; returns its new coordinate and offset.
#[inline(always)]
fn correct_pixel(atlas: &AtlasLevel<'_>, st: &State, x: i32, y: i32) -> (Coord, i32) {
    let mut ns: Neighbourhood = [[0; 4]; 4];
    for (k, &(dx, dy)) in DIAGONALS.iter().enumerate() {
        for (vx, vy) in [(0, 0), (dx, 0), (0, dy)] {
            let n = neighbour(atlas, st, x + dx + vx, y + dy + vy);
            add_texel(&mut ns[k], atlas.appearance(n.tx - vx, n.ty - vy), n.v);
        }
    }

    let mut best = (u32::MAX, Coord::default(), 0i32);
    let mut seen = [(i32::MIN, i32::MIN); 9];
    for (k, &(dx, dy)) in DELTAS.iter().enumerate() {
        let n = neighbour(atlas, st, x + dx, y + dy);
        let u = (n.tx - dx, n.ty - dy);
        if seen[..k].contains(&u) {
            continue;
        }
        seen[k] = u;
        let place = |(qx, qy): (i32, i32)| Coord {
            x: (qx << FRAC_BITS) + n.frac.0,
            y: (qy << FRAC_BITS) + n.frac.1,
        };
        let c1 = atlas.clamp_interior(u.0, u.1);
        let (sc, hh) = score(atlas, &ns, c1.0, c1.1, 1);
        if sc < best.0 {
            best = (sc, place(c1), hh);
        }
        let c2 = atlas.level.similar[atlas.index(u.0, u.1)];
        let c2 = ((c2 & 0xFFFF) as i32, (c2 >> 16) as i32);
        let (sc, hh) = score(atlas, &ns, c2.0, c2.1, 2);
        if sc < best.0 {
            best = (sc, place(c2), hh);
        }
    }
    debug_assert!(best.0 < u32::MAX);
    (best.1, best.2)
}

/// Runs one subpass in place over the level.
pub fn correct(atlas: &AtlasLevel<'_>, st: &State, p: &CorrectParams) {
    let (w, h) = (st.width, st.height);
    (p.py as usize..h).into_par_iter().step_by(2).for_each(|y| {
        for x in (p.px as usize..w).step_by(2) {
            let (s, v) = correct_pixel(atlas, st, x as i32, y as i32);
            st.set(y * w + x, s, v);
        }
    });
}
