//! Stage `correct`: one subpass of the correction (paper eq. 3–7, DESIGN §5).
//!
//! For every pixel p of one parity class `(x mod 2, y mod 2)`:
//! 1. the synthesis neighbourhood N_S (eq. 5–6): for each diagonal δ, the sum
//!    over v ∈ {0, (δx,0), (0,δy)} of `A(S(p+δ+v) − v) + V(p+δ+v)·a`;
//! 2. the candidates Q (eq. 3): for Δ ∈ {−1,0,1}², u = S(p+Δ) − Δ and its
//!    k = 2 similarity entries C₁(u) = u, C₂(u) (k = 1, C₁ alone, where
//!    [`CorrectParams::similar`] is off); identical u are evaluated once
//!    (in coherent patches most of the nine coincide);
//! 3. the score of each candidate q (eq. 7): `κ·min_h ‖N_S − N_E(q, h)‖²`
//!    with N_E the four diagonal appearance texels of q plus `h` on mode 1,
//!    κ = 1 for C₁ and 2 for C₂ (the "κ = 1/2");
//! 4. the best candidate and its optimal h become S(p) and V(p).
//!
//! Beyond the paper, a **height prior** (weight P, [`CorrectParams::prior`])
//! adds `P·(3(h − V_parent))²` to every score, where `V_parent` is the
//! offset the level above chose around the pixel, interpolated to it
//! ([`parent_v`]). The paper's h is free — a
//! candidate from any altitude matches at the mean height of its
//! neighbourhood — so heights are fitted relative to the neighbours only,
//! and every join between patches pulls both sides towards their mean,
//! subpass after subpass and level after level: measured on real DEMs, the
//! output kept 55–70 % of the exemplar's relief, and flat texels (plains,
//! the sea) spread because a flat candidate fits any mean. With the prior,
//! the coarse levels decide the heights (candidates come at their own
//! altitude plus the parent's offset) and finer levels add the exemplar's
//! detail around them; an offset is still taken where it pays, e.g. under
//! a geometric constraint, whose nudges the children inherit as their
//! anchor. P = 0 is the paper's pure relative matching. With it the closed
//! form becomes `h = ⌊(Σ d₁ + 3P·V_parent + ⌊(12 + 3P)/2⌋) / (12 + 3P)⌋`.
//!
//! **Flat candidates** (the four diagonal texels at one height: the sea, a
//! lake, a salt flat) keep close to their own altitude: their offset is
//! fitted as if their prior weighed 44 towards offset 0 ([`FLAT_FIT`]), a
//! twelfth of the free fit's lift, and priced at weight 8 ([`FLAT`]). A
//! flat candidate fits any height equally well, so next to land it was
//! lifted to the land's mean, and the parent anchor carried that lift down
//! level after level: on the coastal DEMs the sea came out as a green plain
//! 5–130 m up (median +41 m on riviera). With weight 8 for both (the most
//! the u32 score bound allows for the price, see [`CLAMP`]) the sea beside
//! the shore still rose by a third of the land's height above it, a ramp
//! all along every coast that took 2.5–5 points of sea from the coastal
//! DEMs (olympic: 22 % sea, exemplar 25 %), made their median slope
//! 111–123 % of the exemplar's, and gave catalan most of its copied
//! windows (shore ramps are alike everywhere: 9 %, its halves 4 %). Taken
//! exactly at its own altitude (offset 0), the sea kept its share but its
//! shores froze where the start put them: straight, axis-aligned cliffs
//! 100–150 px long. A twelfth keeps the shore mobile and the sea at sea
//! level (seeds 11–13, exemplar size, with the coarse start's Voronoi
//! pieces: median slope olympic 123 → 116 %, riviera 120 → 108 %, catalan
//! 107 → 105 % with 9 → 5 % of its windows copied). Where a geometric
//! constraint reaches ([`Prior::held`]) a flat candidate is any candidate,
//! fitted and priced by the pixel's own prior: the constraint's nudge is
//! in the parent's offset, and both flat priors pull towards offset 0, so
//! the sea under a raised point stayed down — at a twelfth, the 576-px
//! exemplars' point test's least slope fell to 10.5° with 12° asked; with
//! [`FLAT`]'s weight a point raised 633 m over the sea got 371 m (10.3 %
//! of relief off; with the pixel's prior 604 m, 1.2 %, and that test's
//! mean error 1.42 → 0.95 %, least slope 12.0 → 13.7°). (P = 0 keeps the
//! paper's rule for every candidate.)
//!
//! Integer arithmetic (DESIGN §6), identical in the WGSL mirror:
//! - N_S is kept as the *sum* of its three vectors (×3) so no division is
//!   needed; N_E is scaled by 3 to match.
//! - h minimises Σ_δ (d₁(δ) − 3h)² where d₁ = N_S₁ − 3·A₁(q+δ):
//!   h = ⌊(Σ d₁ + 6) / 12⌋ (nearest, ties up), a floor division.
//! - Each residual, and the prior's `3(h − V_parent)`, is clamped to
//!   ±[`CLAMP`] before squaring: 16 terms plus the prior's P ≤ 8, times
//!   κ ≤ 2, stay below 2³² in a u32 (2·24·9459² = 4 294 688 688). Clamping
//!   only flattens the scores of very bad candidates.
//! - Ties keep the earlier candidate: Δ in [`crate::stages::common::DELTAS`] order (Δ = 0 first, so
//!   a pixel keeps its own coordinate on a tie), C₁ before C₂.
//!
//! Scoring reads the nearest texel of each coordinate; the candidate keeps
//! the fractional part of the S(p+Δ) it came from, so sub-texel jitter
//! survives correction (see [`crate::level::fixed`]).
//!
//! Two implementations produce the same bytes: [`scalar`], the readable
//! reference that the WGSL kernel mirrors line by line and the oracle of the
//! tests, and [`simd`], the fast path for every pixel (the level's border
//! included: its neighbours outside the level take the scalar path's
//! reflection), which addresses texels by index arithmetic instead of
//! coordinates and scores with `wide` vectors.
//!
//! Reads never touch another pixel of the same subpass (neighbours at odd
//! offsets, or at (±2, ±1)/(±1, ±2)), and borders reflect by 2 so parity is
//! kept: subpasses run in place, in parallel, deterministically. Outside
//! the level, coordinates are extrapolated from the reflected pixel (see
//! `scalar::neighbour`).

pub mod nudge;
pub mod scalar;
pub mod simd;
mod uniform;

use crate::isa::Isa;
use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, div_floor};
use crate::level::state::State;
use nudge::Target;
use rayon::prelude::*;
use std::sync::atomic::{AtomicI32, Ordering::Relaxed};

pub use uniform::{CORRECT_ALLOWED, CORRECT_COHERENCE, CORRECT_TARGETS, CorrectUniform, GuideCell};

/// Residual clamp (in ×3 height units), see the module docs.
pub const CLAMP: i32 = 9_459;

/// The height prior weights the stage supports (each has its own
/// compiled SIMD path: the closed form divides by the constant 12 + 3P).
pub const PRIORS: [u32; 5] = [0, 1, 2, 4, 8];

/// The default height prior: P = 4, the weight of four more observations
/// of the parent's offset next to the four diagonals' (measured on the
/// shared DEMs: relief 75–95 % of the exemplar's instead of 55–70 %).
pub const DEFAULT_PRIOR: u32 = 4;

/// The parent's offset at child pixel (x, y), interpolated bilinearly
/// (weights 9, 3, 3, 1 of 16 from the parent under it and the three nearest
/// it, clamped at the level's edges; rounded to nearest, ties up).
///
/// Why not the parent under the pixel: V is piecewise constant per parent,
/// so in flat regions — where every candidate fits and the prior alone sets
/// h — a nearest-parent anchor carries the coarse level's steps down to
/// level 0 as faint squares (seen in the sea of the shared DEMs).
#[inline(always)]
pub fn parent_v(pa: &State, x: usize, y: usize) -> i32 {
    ParentRow::new(pa, y).v(x)
}

/// The two rows of the level above that [`parent_v`] reads for one child
/// row, looked up once: kernels that walk a row take each pixel's anchor
/// from here (per pixel, the row lookups and clamps cost as much as the
/// interpolation).
pub struct ParentRow<'a> {
    /// The parent row under the child row, and the nearest other one.
    under: &'a [AtomicI32],
    other: &'a [AtomicI32],
}

/// `c`'s neighbour on the side of the child (`odd`), clamped to `0..n`.
#[inline(always)]
fn nearest(c: usize, odd: bool, n: usize) -> usize {
    if odd {
        (c + 1).min(n - 1)
    } else {
        c.saturating_sub(1)
    }
}

impl<'a> ParentRow<'a> {
    /// The rows for child row `y`.
    #[inline(always)]
    pub fn new(pa: &'a State, y: usize) -> ParentRow<'a> {
        let (py, w) = (y / 2, pa.width);
        let qy = nearest(py, y % 2 == 1, pa.height);
        ParentRow {
            under: pa.run(py * w, w).1,
            other: pa.run(qy * w, w).1,
        }
    }

    /// [`parent_v`] of child column `x`.
    #[inline(always)]
    pub fn v(&self, x: usize) -> i32 {
        let px = x / 2;
        let qx = nearest(px, x % 2 == 1, self.under.len());
        let (a, b) = (self.under, self.other);
        let v = |r: &[AtomicI32], i: usize| r[i].load(Relaxed);
        (9 * v(a, px) + 3 * v(a, qx) + 3 * v(b, px) + v(b, qx) + 8) >> 4
    }

    /// [`ParentRow::v`] of child columns `x0, x0 + 2, …`, one per element of
    /// `out` (a subpass's pixels in a row). Their parent columns are
    /// consecutive and their neighbours too (all on one side), so away
    /// from the row's ends the interpolation is four shifted slices that
    /// vectorise (8 pixels per few AVX2 instructions in the span's AVX2
    /// copy) instead of ~20 instructions per pixel.
    ///
    /// # Safety
    /// No thread may write the parent rows while this runs (they are read
    /// as plain integers): the level above is never written while its
    /// child is corrected.
    #[inline(always)]
    pub unsafe fn fill(&self, x0: usize, out: &mut [i32]) {
        let (n, m) = (out.len(), self.under.len());
        let (p0, odd) = (x0 / 2, x0 % 2 == 1);
        // Pixels k in lo..hi have their neighbour column p0 + k ± 1 inside
        // the row: no clamp.
        let lo = usize::from(!odd && p0 == 0).min(n);
        let hi = match odd {
            true => n.min((m - 1).saturating_sub(p0)),
            false => n,
        }
        .max(lo);
        // SAFETY: AtomicI32 has the layout of i32; the caller guarantees
        // no concurrent writer, so plain reads do not race.
        let plain = |r: &[AtomicI32]| unsafe {
            std::slice::from_raw_parts(r.as_ptr().cast::<i32>(), r.len())
        };
        if lo < hi {
            let (a, b) = (plain(self.under), plain(self.other));
            let (p, len) = (p0 + lo, hi - lo);
            let q = if odd { p + 1 } else { p - 1 };
            let (ap, aq) = (&a[p..][..len], &a[q..][..len]);
            let (bp, bq) = (&b[p..][..len], &b[q..][..len]);
            let rows = ap.iter().zip(aq).zip(bp).zip(bq);
            for (o, (((&ap, &aq), &bp), &bq)) in out[lo..hi].iter_mut().zip(rows) {
                *o = (9 * ap + 3 * aq + 3 * bp + bq + 8) >> 4;
            }
        }
        for k in (0..lo).chain(hi..n) {
            out[k] = self.v(x0 + 2 * k);
        }
    }
}

/// One pixel's height prior: its weight P and the parent's offset V it
/// pulls the optimal h towards (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Prior {
    pub weight: u32,
    pub v: i32,
    /// Whether a geometric constraint reaches the pixel (its target's
    /// tolerance ≥ 0): there a flat candidate is any candidate (this
    /// prior fits and prices it), so the sea can be lifted (or lowered) to
    /// a constraint's target.
    pub held: bool,
}

impl Prior {
    /// The prior of pixel (x, y) under `parent` (the level above; none at
    /// the coarsest corrected level, whose start has V = 0).
    #[inline(always)]
    pub fn at(weight: u32, parent: Option<&State>, x: usize, y: usize, held: bool) -> Prior {
        // A `match`, not `Option::map_or`: the profile found `map_or` left
        // out of line in the SIMD span (a call per pixel, 3.7 % of the
        // time at 1024²).
        let v = match parent {
            Some(pa) => parent_v(pa, x, y),
            None => 0,
        };
        Prior { weight, v, held }
    }

    /// The optimal offset for `sum1 = Σ_δ d₁(δ)` (nearest, ties up).
    #[inline(always)]
    pub fn optimal(self, sum1: i32) -> i32 {
        let den = 12 + 3 * self.weight as i32;
        div_floor(sum1 + 3 * self.weight as i32 * self.v + den / 2, den)
    }

    /// The prior's cost of offset `h`.
    #[inline(always)]
    pub fn cost(self, h: i32) -> u32 {
        let r = (3 * (h - self.v)).clamp(-CLAMP, CLAMP);
        self.weight * (r * r) as u32
    }
}

/// The prior that prices a flat candidate's offset (module docs): weight 8
/// towards offset 0, the most the u32 score bound allows (see [`CLAMP`]);
/// 2 and 4 left dimples in the sea (pits ×2.6–15 on riviera).
pub const FLAT: Prior = Prior {
    weight: 8,
    v: 0,
    held: false,
};

/// The prior a flat candidate's offset is fitted with (module docs): as if
/// weighing 44, a twelfth of the free fit's lift (Σ d₁ / 144 where the free
/// fit is Σ d₁ / 12), where [`FLAT`]'s 8 gave a third. Only the fit: its
/// cost is [`FLAT`]'s, which the score bound caps.
pub const FLAT_FIT: Prior = Prior {
    weight: 44,
    v: 0,
    held: false,
};

impl Prior {
    /// Whether a candidate whose four diagonal texels have mode-1 heights
    /// `m` is flat: all four equal, and the stage has a prior at all.
    #[inline(always)]
    pub fn is_flat(self, m: [i32; 4]) -> bool {
        self.weight > 0 && m[0] == m[1] && m[0] == m[2] && m[0] == m[3]
    }

    /// The prior that scores a candidate (`flat` from [`Prior::is_flat`])
    /// and its offset: the one `fixed` by a constraint, else the closed
    /// form [`Prior::optimal`] — [`FLAT_FIT`]'s for a flat candidate where
    /// no constraint holds the pixel.
    #[inline(always)]
    pub fn fit(self, flat: bool, fixed: Option<i32>, sum1: i32) -> (Prior, i32) {
        if flat && !self.held {
            (FLAT, fixed.unwrap_or_else(|| FLAT_FIT.optimal(sum1)))
        } else {
            (self, fixed.unwrap_or_else(|| self.optimal(sum1)))
        }
    }
}

/// The four diagonals δ of the neighbourhoods.
pub const DIAGONALS: [(i32, i32); 4] = [(-1, -1), (1, -1), (-1, 1), (1, 1)];

/// Parameters of one subpass.
#[derive(Debug, Clone, Copy)]
pub struct CorrectParams {
    /// Parity class: pixels with `x % 2 == px && y % 2 == py`.
    pub px: u32,
    pub py: u32,
    /// Height prior weight P, one of [`PRIORS`] (0: the paper's relative
    /// matching).
    pub prior: u32,
    /// Whether each source u also offers its most similar texel C₂ (the
    /// paper's k = 2); without, C₁ alone (k = 1). See [`crate::synth::Params::similar_from`].
    pub similar: bool,
}

/// Subpass order within a pass (the four parity classes).
pub const SUBPASSES: [(u32, u32); 4] = [(0, 0), (1, 0), (0, 1), (1, 1)];

/// Control inputs of one subpass at one level (paper §5), all optional;
/// [`Guide::NONE`] is plain synthesis. Rasters are level-sized, row-major.
#[derive(Debug, Clone, Copy)]
pub struct Guide<'a> {
    /// The level index (salts the type-seeding hash; the finest levels
    /// keep a curve's detail, [`nudge::own_detail`]).
    pub level: u32,
    /// Geometric constraints: blended target and tolerance per pixel; the
    /// winner's height is nudged by φ_d (eq. 8–9).
    pub targets: Option<&'a [Target]>,
    /// Type constraints: the target set R^i(p) as a bit mask of type ids
    /// ([`crate::stages::common::ALL_TYPES`] = unconstrained).
    pub allowed: Option<&'a [u32]>,
    /// Coherence: the previous frame's result of this level and pass, one
    /// more candidate per pixel with its cost × W/4.
    pub coherence: Option<Coherence<'a>>,
    /// Only pixels inside `[x0, y0, x1, y1)` are corrected. The rest are
    /// known to reproduce the previous frame's result (see
    /// `synth::Guides::restrict`): with [`Guide::coherence`] they take it
    /// (its S and V as they are), without it they keep their state.
    pub window: Option<[usize; 4]>,
    /// Absolute position, in this level, of the state's pixel (0, 0):
    /// `[0, 0]` for a whole level, a window's corner for windowed
    /// synthesis. Type seeding hashes absolute coordinates (DESIGN §6), so
    /// a window seeds what the whole level seeds there.
    pub origin: [u32; 2],
}

impl Guide<'_> {
    /// No control: the paper's unconstrained synthesis.
    pub const NONE: Guide<'static> = Guide {
        level: 0,
        targets: None,
        allowed: None,
        coherence: None,
        window: None,
        origin: [0, 0],
    };
}

/// The previous frame's result of one level and pass, and the weights.
#[derive(Debug, Clone, Copy)]
pub struct Coherence<'a> {
    pub coords: &'a [Coord],
    pub offsets: &'a [i32],
    /// W^i in quarters: 0 frozen, 1 coherent (0.25), 4 unweighted (1).
    pub weights: &'a [u8],
}

/// The coherence weights W^i, in quarters (paper §5.3): 0 frozen,
/// 1 coherent (0.25), 4 unweighted (1).
pub const W_FROZEN: u8 = 0;
pub const W_COHERENT: u8 = 1;
pub const W_FREE: u8 = 4;

/// Coherence cost `⌊score · w / 4⌋` without leaving 32 bits (w ≤ 4).
#[inline(always)]
pub fn weigh(score: u32, w: u8) -> u32 {
    let w = w as u32;
    (score >> 2) * w + (((score & 3) * w) >> 2)
}

/// Type seeding (paper §5.2): candidates per allowed type when every
/// regular candidate is rejected.
pub const SEEDS_PER_ALLOWED_TYPE: u32 = 9;

/// Hash salt of type seeding.
pub const SEED_SALT: u32 = 0x7E5E_0000;

/// Runs one subpass in place over the level by the [`simd`] path, its copy
/// for `isa` (the same bytes at every level). `parent` is the level above
/// (the height prior's anchor; none at the coarsest corrected level).
pub fn correct(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    p: &CorrectParams,
    isa: Isa,
) {
    correct_guided(atlas, st, parent, p, &Guide::NONE, isa)
}

/// [`correct`] with control inputs. Pixels with a type constraint go
/// through the scalar path (seeding is rare and lives there); geometric and
/// coherence controls run in both paths with the same integer arithmetic.
pub fn correct_guided(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    p: &CorrectParams,
    g: &Guide<'_>,
    isa: Isa,
) {
    match p.prior {
        0 => guided::<0>(atlas, st, parent, p, g, isa),
        1 => guided::<1>(atlas, st, parent, p, g, isa),
        2 => guided::<2>(atlas, st, parent, p, g, isa),
        4 => guided::<4>(atlas, st, parent, p, g, isa),
        8 => guided::<8>(atlas, st, parent, p, g, isa),
        w => panic!("height prior {w} is not one of {PRIORS:?} (checked by Synthesizer::new)"),
    }
}

/// [`correct_guided`] with the prior weight as a constant.
fn guided<const P: u32>(
    atlas: &AtlasLevel<'_>,
    st: &State,
    parent: Option<&State>,
    p: &CorrectParams,
    g: &Guide<'_>,
    isa: Isa,
) {
    keep_outside(st, p, g);
    let (w, h) = (st.width, st.height);
    let [wx0, wy0, wx1, wy1] = g.window.unwrap_or([0, 0, w, h]);
    // First row/column of the class at or after a bound.
    let class_from = |start: usize, parity: usize| start + ((parity + 2 - start % 2) % 2);
    let (y_first, x_first) = (
        class_from(wy0, p.py as usize),
        class_from(wx0, p.px as usize),
    );
    let x_end = wx1.min(w);
    let rows = (wy1.min(h).saturating_sub(y_first)).div_ceil(2);
    if x_first >= x_end {
        return;
    }
    // Blocks of consecutive class rows per task: the SIMD span walks a
    // block's rows chunk by chunk and reuses grid rows between them.
    (0..rows.div_ceil(ROWS_PER_TASK))
        .into_par_iter()
        .for_each(|b| {
            let first = b * ROWS_PER_TASK;
            let ys: [usize; ROWS_PER_TASK] = std::array::from_fn(|j| y_first + 2 * (first + j));
            let ys = &ys[..ROWS_PER_TASK.min(rows - first)];
            let span = (ys, x_first, x_end);
            simd::correct_span::<P>(atlas, st, parent, span, p.similar, g, isa);
        });
}

/// Class rows per parallel task of a subpass (see [`simd::correct_span`]).
const ROWS_PER_TASK: usize = 8;

/// The subpass's pixels outside [`Guide::window`] take the previous frame's
/// result of this pass (what a full subpass would compute there), so a
/// windowed subpass leaves the same state as a full one. Part of the stage
/// rather than of its caller so that every backend does it where the state
/// lives (the WGSL kernel's invocations outside the window do the same).
pub fn keep_outside(st: &State, p: &CorrectParams, g: &Guide<'_>) {
    let (Some([x0, y0, x1, y1]), Some(c)) = (g.window, g.coherence) else {
        return;
    };
    let w = st.width;
    (p.py as usize..st.height)
        .into_par_iter()
        .step_by(2)
        .for_each(|y| {
            let inside_row = (y0..y1).contains(&y);
            for x in (p.px as usize..w).step_by(2) {
                if !(inside_row && (x0..x1).contains(&x)) {
                    let i = y * w + x;
                    st.set(i, c.coords[i], c.offsets[i]);
                }
            }
        });
}

#[cfg(test)]
mod tests {
    use super::{FLAT, FLAT_FIT, ParentRow, Prior};
    use crate::level::fixed::Coord;
    use crate::level::state::State;

    #[test]
    fn a_flat_candidate_is_fitted_at_flat_fits_weight_unless_held() {
        let free = Prior {
            weight: 4,
            v: 300,
            held: false,
        };
        let held = Prior { held: true, ..free };
        let sum1 = 12_000; // the neighbours 1000 units above the candidate
        // Free: a twelfth of the free lift (1000 / 12 ≈ 83), priced as FLAT.
        assert_eq!(free.fit(true, None, sum1), (FLAT, FLAT_FIT.optimal(sum1)));
        assert_eq!(FLAT_FIT.optimal(sum1), 83);
        // Held by a constraint: any candidate, fitted and priced by the
        // pixel's own prior towards the parent's offset (which carries the
        // constraint's nudge): (12 000 + 12·300 + 12) / 24 = 650.
        assert_eq!(held.fit(true, None, sum1), (held, held.optimal(sum1)));
        assert_eq!(held.optimal(sum1), 650);
        // Not flat: the pixel's own prior; a fixed offset wins in every case.
        assert_eq!(free.fit(false, None, sum1), (free, free.optimal(sum1)));
        assert_eq!(held.fit(true, Some(-7), sum1), (held, -7));
        assert_eq!(free.fit(true, Some(-7), sum1), (FLAT, -7));
        assert_eq!(free.fit(false, Some(-7), sum1), (free, -7));
        assert!(free.is_flat([5, 5, 5, 5]) && !free.is_flat([5, 5, 5, 6]));
        assert!(!Prior { weight: 0, ..free }.is_flat([5, 5, 5, 5]));
    }

    #[test]
    fn a_row_of_anchors_is_each_pixels_anchor() {
        // Parents 1…9 wide (the clamps at both ends, rows too short for
        // the vector part), every child row, start column and length.
        let mut h = 0x1234_5677u32;
        for (pw, ph) in [(1, 1), (2, 3), (3, 2), (5, 4), (9, 3)] {
            let offsets: Vec<i32> = (0..pw * ph)
                .map(|_| {
                    h = h.wrapping_mul(0x9E37_79B9).wrapping_add(0x7F4A_7C15);
                    (h >> 8) as i32 - (1 << 23)
                })
                .collect();
            let pa = State::from_parts(pw, ph, &vec![Coord { x: 0, y: 0 }; pw * ph], &offsets);
            let (cw, ch) = (2 * pw, 2 * ph);
            for y in 0..ch {
                let row = ParentRow::new(&pa, y);
                for x0 in 0..cw {
                    for n in 0..=(cw - x0).div_ceil(2) {
                        let mut got = vec![i32::MIN; n];
                        // SAFETY: nothing writes `pa`.
                        unsafe { row.fill(x0, &mut got) };
                        let want: Vec<i32> = (0..n).map(|k| row.v(x0 + 2 * k)).collect();
                        assert_eq!(got, want, "parent {pw}x{ph}, row {y}, x0 {x0}, n {n}");
                    }
                }
            }
        }
    }
}
