//! The reference correction: one pixel at a time, coordinates throughout,
//! exactly the arithmetic of `kernels/correct.wgsl`. It handles every pixel
//! (borders included) and is the oracle the [`super::simd`] path is tested
//! against.

use super::nudge::{nudge, own_detail};
use super::{
    CLAMP, CorrectParams, DIAGONALS, Guide, Prior, SEED_SALT, SEEDS_PER_ALLOWED_TYPE, W_FREE, weigh,
};
use crate::database::appearance::unpack_texel;
use crate::database::types::SEEDS_PER_TYPE;
use crate::hash::{below, hash4};
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, FRAC_BITS, round};
use crate::level::state::State;
use crate::stages::common::{ALL_TYPES, DELTAS, texel_height};
use rayon::prelude::*;

/// Reflects a coordinate at the level border by 2 (keeps parity); the
/// level is at least 2 wide and offsets are at most ±2.
#[inline(always)]
pub(super) fn reflect(c: i32, n: i32) -> i32 {
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
fn score(
    atlas: &AtlasLevel<'_>,
    ns: &Neighbourhood,
    qx: i32,
    qy: i32,
    kappa: u32,
    prior: Prior,
) -> (u32, i32) {
    score_with(atlas, ns, qx, qy, kappa, None, prior)
}

/// [`score`] with the offset fixed to `fixed` when given (a coherent
/// previous result keeps its own offset).
#[inline(always)]
fn score_with(
    atlas: &AtlasLevel<'_>,
    ns: &Neighbourhood,
    qx: i32,
    qy: i32,
    kappa: u32,
    fixed: Option<i32>,
    prior: Prior,
) -> (u32, i32) {
    let mut d = [[0i32; 4]; 4];
    let mut heights = [0i32; 4];
    let mut sum1 = 0;
    for (k, &(dx, dy)) in DIAGONALS.iter().enumerate() {
        let m = unpack_texel(atlas.appearance(qx + dx, qy + dy));
        for j in 0..4 {
            d[k][j] = ns[k][j] - 3 * m[j] as i32;
        }
        heights[k] = m[0] as i32;
        sum1 += d[k][0];
    }
    let (prior, h) = prior.fit(prior.is_flat(heights), fixed, sum1);
    let mut s = prior.cost(h);
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
pub(super) struct Neighbour {
    pub tx: i32,
    pub ty: i32,
    pub frac: (i32, i32),
    pub v: i32,
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
pub(super) fn neighbour(atlas: &AtlasLevel<'_>, st: &State, x: i32, y: i32) -> Neighbour {
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

/// The best candidate so far: cost, coordinate, offset, and its texel
/// (None for a frozen previous result, which is taken as is).
type Best = (u32, Coord, i32, Option<(i32, i32)>);

/// Corrects one pixel under control inputs (paper §5):
/// 1. the coherence candidate, first so that a tie keeps it, cost × W/4:
///    where unweighted (W = 1) the previous coordinate, scored like C₁ with
///    its optimal offset; where coherent (0 < W < 1) the previous S and V
///    as they are, scored with that offset; where frozen (W = 0) the
///    previous S and V at cost 0;
/// 2. the k-coherence candidates (C₂ only if `similar`), those of a type
///    outside R^i(p) rejected;
/// 3. if a type constraint rejected them all, 9 hash-chosen seeds per
///    allowed type, scored like C₁;
/// 4. the winner's offset nudged by φ_d towards the blended target
///    (eq. 8–9), unless it is a previous result taken as is — at the
///    finest two levels of a curve's reach, by the winner's smooth height
///    rather than its own, so its detail stays (`nudge::own_detail`).
///
/// Why two forms of the previous result: inside an edit's influence a kept
/// coordinate must still follow the new target (so its offset is re-fitted
/// and nudged), while elsewhere keeping the previous *height* is what stops
/// an edit's offsets from diffusing outwards level after level. Both forms
/// make the result a function of the neighbourhood, the candidates and the
/// target, so an unchanged frame repeats bit for bit.
#[inline(always)]
pub fn correct_pixel_guided(
    atlas: &AtlasLevel<'_>,
    st: &State,
    (x, y): (i32, i32),
    similar: bool,
    g: &Guide<'_>,
    prior: Prior,
) -> (Coord, i32) {
    let mut ns: Neighbourhood = [[0; 4]; 4];
    for (k, &(dx, dy)) in DIAGONALS.iter().enumerate() {
        for (vx, vy) in [(0, 0), (dx, 0), (0, dy)] {
            let n = neighbour(atlas, st, x + dx + vx, y + dy + vy);
            add_texel(&mut ns[k], atlas.appearance(n.tx - vx, n.ty - vy), n.v);
        }
    }
    let i = y as usize * st.width + x as usize;

    // (cost, coordinate, offset, texel of the winner; None = coherence).
    let mut best: Best = (u32::MAX, Coord::default(), 0i32, None);
    let allowed = g.allowed.map_or(ALL_TYPES, |a| a[i]);
    if let Some(c) = &g.coherence {
        let (s, v) = (c.coords[i], c.offsets[i]);
        let q = (round(s.x), round(s.y));
        // A previous result of a type no longer allowed is no candidate,
        // unless frozen (freezing dominates).
        let ok = allowed == ALL_TYPES
            || c.weights[i] == 0
            || allowed >> atlas.level.types[atlas.index(q.0, q.1)] & 1 == 1;
        if ok {
            let w = c.weights[i];
            best = if w == 0 {
                // Frozen: the previous result as is (offset and all).
                (0, s, v, None)
            } else if w >= W_FREE {
                // Unweighted: the coordinate, re-fitted and nudged.
                let (sc, hh) = score(atlas, &ns, q.0, q.1, 1, prior);
                (weigh(sc, w), s, hh, Some(q))
            } else {
                // Coherent: the previous result as is, at a discount.
                let (sc, _) = score_with(atlas, &ns, q.0, q.1, 1, Some(v), prior);
                (weigh(sc, w), s, v, None)
            };
        }
    }
    // Scores the k-coherence candidates admitted by `filter`; whether any was.
    let candidates = |filter: u32, best: &mut Best| -> bool {
        let mut any = false;
        let admits = |q: (i32, i32)| {
            filter == ALL_TYPES || filter >> atlas.level.types[atlas.index(q.0, q.1)] & 1 == 1
        };
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
            if admits(c1) {
                any = true;
                let (sc, hh) = score(atlas, &ns, c1.0, c1.1, 1, prior);
                if sc < best.0 {
                    *best = (sc, place(c1), hh, Some(c1));
                }
            }
            if !similar {
                continue;
            }
            let c2 = atlas.level.similar[atlas.index(u.0, u.1)];
            let c2 = ((c2 & 0xFFFF) as i32, (c2 >> 16) as i32);
            if admits(c2) {
                any = true;
                let (sc, hh) = score(atlas, &ns, c2.0, c2.1, 2, prior);
                if sc < best.0 {
                    *best = (sc, place(c2), hh, Some(c2));
                }
            }
        }
        any
    };
    if !candidates(allowed, &mut best) {
        let mut seeded = false;
        for t in 0..atlas.seed_counts.len() as u32 {
            let count = atlas.seed_counts[t as usize];
            if allowed >> t & 1 == 0 || count == 0 {
                continue;
            }
            seeded = true;
            let list = &atlas.level.seeds[t as usize * SEEDS_PER_TYPE..];
            for k in 0..SEEDS_PER_ALLOWED_TYPE {
                let salt = t * SEEDS_PER_ALLOWED_TYPE + k;
                let (ax, ay) = (g.origin[0] + x as u32, g.origin[1] + y as u32);
                let hash = hash4(SEED_SALT | g.level, salt, ax, ay);
                let c = list[below(hash, count) as usize];
                let q = ((c & 0xFFFF) as i32, (c >> 16) as i32);
                let (sc, hh) = score(atlas, &ns, q.0, q.1, 1, prior);
                if sc < best.0 {
                    best = (sc, Coord::from_texel(q.0, q.1), hh, Some(q));
                }
            }
        }
        if !seeded {
            // No exemplar texel of any allowed type at this level: the
            // constraint cannot be met, so the pixel synthesizes freely.
            candidates(ALL_TYPES, &mut best);
        }
    }
    debug_assert!(best.0 < u32::MAX);
    let (_, s, mut v, texel) = best;
    if let (Some(q), Some(t)) = (texel, g.targets) {
        let h = texel_height(atlas.appearance(q.0, q.1));
        let d = own_detail(g.level, t[i], h, |dx, dy| {
            texel_height(atlas.appearance(q.0 + dx, q.1 + dy))
        });
        v = nudge(v, h + v - d, t[i]);
    }
    (s, v)
}

/// Runs one subpass in place with the reference path only.
pub fn correct(atlas: &AtlasLevel<'_>, st: &State, parent: Option<&State>, p: &CorrectParams) {
    correct_guided(atlas, st, parent, p, &Guide::NONE)
}

/// [`correct`] with control inputs (the oracle of `super::correct_guided`).
pub fn correct_guided(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    p: &CorrectParams,
    g: &Guide<'_>,
) {
    super::keep_outside(st, p, g);
    let (w, h) = (st.width, st.height);
    let [x0, y0, x1, y1] = g.window.unwrap_or([0, 0, w, h]);
    (p.py as usize..y1.min(h))
        .into_par_iter()
        .step_by(2)
        .filter(|&y| y >= y0)
        .for_each(|y| {
            for x in (p.px as usize..x1.min(w)).step_by(2).filter(|&x| x >= x0) {
                let held = g.targets.is_some_and(|t| t[y * w + x].tol >= 0);
                let prior = Prior::at(p.prior, parent, x, y, held);
                let at = (x as i32, y as i32);
                let (s, v) = correct_pixel_guided(atlas, st, at, p.similar, g, prior);
                st.set(y * w + x, s, v);
            }
        });
}
