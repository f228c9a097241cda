//! Overlapping geometric constraints (paper §5.1, last paragraph): the
//! per-pixel targets of the non-linear height nudge φ_d (eq. 8–9), which
//! itself is the `correct` stage's (`stages::correct::nudge`).
//!
//! # Running sums
//! Every synthesis pixel of every level keeps Σb·a, Σb·h_t and Σb over the
//! constraints that reach it, b = 1 / (1 + d) the inverse distance to each
//! constraint's site (the 1 keeps b finite at the site and gives a
//! pixel-sized core). A constraint changes by subtracting it, altering it
//! and adding it back, without re-evaluating the others.
//!
//! **What "a" is.** The paper blends "h_t and a" and then recomputes t and c
//! from eq. 8, so a is the quantity t is made of: the distance d to the
//! site. The blended tolerance is therefore `t = s · Σb·d / Σb`. Near one
//! constraint's site its own tiny d dominates the weighted mean (b ~ 1/d),
//! so overlapping constraints do not loosen each other's sites.
//!
//! **Units of t = s·d.** The paper does not say; we take the literal,
//! physical reading: d is horizontal distance in metres (output pixels ×
//! cell size), so with a point's s = ¼ ([`S`]) the terrain may leave the
//! target by a quarter of its distance to the site — a 1:4 tolerance cone
//! around the site, the same at every level (a curve's s is 0.1, see *Curves hold their profile*).
//! A pixel far from the site is nudged only where its error exceeds that
//! cone (eq. 9's cubic leaves smaller errors almost
//! alone), so the constraint pins the site and lets the exemplar decide the
//! shape around it: a lowered point becomes a valley head or basin shaped
//! by the candidates, a raised one a textured massif. (An earlier reading,
//! d in pixels of the level being corrected at ¼ cell of height per pixel,
//! made t 16–256× tighter, pulled the whole disc within the reach onto the
//! flat target plane, and turned a lowered point into a flat-bottomed pit
//! ringed by terraces where the per-level reach stepped.)
//!
//! **d from a pixel's footprint.** A pixel of level i stands for the
//! 2^i × 2^i output pixels it covers, and its centre may lie 0.7·2^i pixels
//! from a site inside it. Measured from the centre, the site's own coarse
//! pixels would get a tolerance of up to 0.35·2^i cells of height and stay
//! that far off. So d in t is measured from the footprint, approximated by
//! its inscribed disc: `d_t = max(0, d − 2^(i−1))`. Every pixel a site or a
//! curve passes through is held hard (t = 0: φ = x, the whole error; see
//! `stages::correct::nudge::phi`) at every level. The
//! blend weight b keeps the centre distance.
//!
//! **Detail on a shape, exact heights at a site.** The sums also count
//! the reaching constraints that ask for exact heights (points, sculpt
//! strokes: [`super::Hold::keeps_detail`] false). Where none does — a
//! curve's reach alone — the target carries
//! [`KEEP_DETAIL`], and the nudge moves the winner's smooth height (the
//! mean of nine texels over its 5×5 neighbourhood) to the profile at the
//! finest two levels, so the exemplar's texture stays on the feature
//! (`stages::correct::nudge::own_detail`).
//!
//! **Exactness.** Each sample's b, b·h_t and b·d_t are quantized to
//! integers on the CPU and the sums are i64, so subtract → modify → add
//! gives the same sums as evaluation from scratch, bit for bit (tested
//! below).
//!
//! # Levels and reach
//! At level i a point's sample counts if d ≤ min(reach, 4·2^i) (eq. 9's
//! text: "min(radius, 4 × 2^d)", with d the level), so points act ever more
//! locally as synthesis gets finer.
//!
//! **Curves hold their profile** ([`super::Hold`]): a curve's widgets give
//! the cross-section the artist wants — height, a slope and a reach on each
//! side — so a curve acts over its whole reach at every level, with the
//! tighter tolerance slope [`S_CURVE`] = 0.1. With the paper's loose hold
//! (s = ½ and the 4·2^i cap) a one-sided cliff (flat on one side, −45° over
//! 10 px on the other, Pyrenees, 92.6 m cells) came out as a ramp of
//! 0.42 m/m where 1.0 was asked: beyond 4 px of the curve at level 0 (8 at
//! level 1) the finest levels were free to smooth the face, and the 1:2
//! cone let the face sit half its distance high. Held over the reach with
//! s = 0.1 the face is 0.85 m/m and the top edge within 2 % of relief
//! (`tests/synth/scene_session.rs`); the curve profile test's mean error went
//! 1.24 → 1.17 % of relief and the fine relief within 2 px of the curve
//! stays 79 % of the unconstrained terrain's (80 % before). A sloped point
//! holds its plane over its reach the same way (with s = ¼); a flat point
//! keeps the loose hold: it pins a site and lets the exemplar shape its
//! surroundings ([`super::point`]).
//!
//! **All levels, the finest two included.** The paper disables geometric
//! constraints on the two finest levels because they "locally
//! overconstrain curves". With the tolerance cone above that does not
//! happen, and without them the finest levels' free detail moves a
//! constrained height far off its target: on the Pyrenees test DEM (relief
//! 2245 m, 92.6 m cells) a curve's profile is followed to 1.9 % of relief
//! by level 2's (smoothed) heights but to 4.7 % (mean along the curve)
//! after level 0, and points set 500–700 m above or below the terrain end
//! 2.5–11 % off. Enforced on every level (reach 4 px at level 0, 8 px at
//! level 1), the profile is met to 1.0 % and those point sites to
//! 0.8–1.6 %, while the fine relief along the curve keeps its texture: the
//! RMS of the 3×3 high-pass within 2 px of the curve is 93 % of the
//! unconstrained terrain's (within 6 px, 99 %). Type constraints stay off
//! on the finest two levels ([`super::FIRST_LEVEL`]).

use super::{Centres, Constraint, Hold};
use crate::database::Quantization;
use crate::synth::cone::Rect;
use crate::synth::union;
use crate::synth::window::row_bounds;
use rayon::prelude::*;
use std::ops::Range;

use crate::stages::correct::nudge::{KEEP_DETAIL, MAX_TOL, Target};

/// The tolerance slope s (eq. 8) of points: ¼ where the paper has ½.
///
/// Why: since synthesis starts at level 3 or finer (`coarse::MAX_START_LEVEL`;
/// 3 when this was measured), fewer levels shape a point's surroundings,
/// and with ½ its site missed by 2.25 % of relief on average where it had
/// missed by 1.68 % (12 seeds × 12 points, Pyrenees, 512²); with ¼, 1.73 %. Points keep the
/// level cap, so a lowered point still opens into a valley, not a pit.
pub const S: f64 = 0.25;
/// The tolerance slope of curves, which also act over their whole reach at
/// every level (module docs, *Curves hold their profile*).
pub const S_CURVE: f64 = 0.1;
/// Fixed-point scale of the blend weight b = 1/(1 + d).
const B_ONE: f64 = (1u64 << 20) as f64;
/// Scale of quantized heights (1/16 unit) and tolerances (1/1024 pixel of
/// height: a step of cell/1024, 3 cm at 30 m cells) in the sums.
const H_FRAC: f64 = 16.0;
const D_FRAC: f64 = 1024.0;
/// Side of the tiles, in level pixels, that [`Blend`] skips at once where a
/// constraint cannot reach (most of its bounds at the finest levels, whose
/// reach cap is 4 and 8 output pixels).
const TILE: usize = 8;
/// The integer raster the `correct` stage reads at one level.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Targets {
    pub width: usize,
    pub height: usize,
    pub cells: Vec<Target>,
}

/// Running sums of one pixel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
struct Sums {
    b: i64,
    bh: i64,
    bd: i64,
    /// Reaching constraints that do not keep detail ([`Hold::keeps_detail`]).
    exact: i64,
}

/// Running sums of one level, over its pixels `[x0, x0 + width) ×
/// [y0, y0 + height)` (the whole level, or a window's cone region).
#[derive(Debug)]
struct LevelSums {
    x0: usize,
    y0: usize,
    width: usize,
    height: usize,
    /// Allocated by the first constraint added (24 B per pixel: level 0
    /// of a 4096² output would hold 400 MB for a session that never
    /// places one); empty means all zero.
    sums: Vec<Sums>,
    /// How many pixels some constraint reaches (b ≠ 0): whether the level
    /// has targets at all, without reading 24 B per pixel.
    reached: usize,
    /// Bounds `[x0, y0, x1, y1)` (region-relative) of the pixels whose sums
    /// changed since [`Blend::take_touched`], so an editing session
    /// re-derives only their targets.
    touched: Option<[usize; 4]>,
}

impl Clone for LevelSums {
    fn clone(&self) -> LevelSums {
        let mut c = LevelSums {
            sums: Vec::new(),
            ..*self
        };
        c.sums.clone_from(&self.sums);
        c
    }

    /// Into `self`'s sums (see [`Blend`]'s `clone_from`).
    fn clone_from(&mut self, source: &LevelSums) {
        self.sums.clone_from(&source.sums);
        *self = LevelSums {
            sums: std::mem::take(&mut self.sums),
            ..*source
        };
    }
}

impl PartialEq for LevelSums {
    /// Equal sums, an unallocated level counting as all zero.
    fn eq(&self, other: &LevelSums) -> bool {
        let zero = |s: &[Sums]| s.iter().all(|x| *x == Sums::default());
        (self.x0, self.y0, self.width, self.height)
            == (other.x0, other.y0, other.width, other.height)
            && match (self.sums.is_empty(), other.sums.is_empty()) {
                (false, false) => self.sums == other.sums,
                (true, _) => zero(&other.sums),
                (false, true) => zero(&self.sums),
            }
    }
}

/// The overlap blend of all geometric constraints of one output size.
#[derive(Debug, PartialEq)]
pub struct Blend {
    q: Quantization,
    /// Index = level.
    levels: Vec<LevelSums>,
}

impl Clone for Blend {
    fn clone(&self) -> Blend {
        Blend {
            q: self.q,
            levels: self.levels.clone(),
        }
    }

    /// Into `self`'s buffers where they are large enough (an editor's
    /// recycled [`crate::synth::session::Snapshot`]: level 0's sums are
    /// 24 MB at 1024²), without allocating or faulting in new pages.
    fn clone_from(&mut self, source: &Blend) {
        self.q = source.q;
        self.levels.clone_from(&source.levels);
    }
}

impl Blend {
    /// Empty sums for levels `0..=last` of an output of this size.
    pub fn new(width: usize, height: usize, last: usize, q: Quantization) -> Blend {
        let regions: Vec<Rect> = (0..=last)
            .map(|i| {
                let (w, h) = crate::level::state::level_size(width, height, i);
                Rect::new(0, 0, w, h)
            })
            .collect();
        Blend::over(&regions, q)
    }

    /// Empty sums over one region per level (index = level): a windowed
    /// synthesis blends only its cone. Every pixel's sums are those of the
    /// whole level, as samples are taken at absolute pixel centres.
    pub fn over(regions: &[Rect], q: Quantization) -> Blend {
        let levels = regions
            .iter()
            .map(|r| LevelSums {
                x0: r.x0,
                y0: r.y0,
                width: r.width(),
                height: r.height(),
                sums: Vec::new(),
                reached: 0,
                touched: None,
            })
            .collect();
        Blend { q, levels }
    }

    /// Adds a constraint's contribution.
    pub fn add(&mut self, c: &dyn Constraint) {
        self.apply(c, 1, None);
    }

    /// Removes a contribution added before (exactly).
    pub fn subtract(&mut self, c: &dyn Constraint) {
        self.apply(c, -1, None);
    }

    /// [`Blend::add`], the finest level's samples read from `kept` (`c`'s
    /// [`Constraint::centres`]): the same sums.
    pub fn add_kept(&mut self, c: &dyn Constraint, kept: &Centres) {
        self.apply(c, 1, Some(kept));
    }

    /// [`Blend::subtract`], the finest level's samples read from `kept`.
    pub fn subtract_kept(&mut self, c: &dyn Constraint, kept: &Centres) {
        self.apply(c, -1, Some(kept));
    }

    /// Whether no constraint contributes anywhere.
    pub fn is_empty(&self) -> bool {
        self.levels.iter().all(|l| l.reached == 0)
    }

    /// What the sums hold, in bytes (an editing session's snapshot
    /// reports what it keeps).
    pub fn bytes(&self) -> usize {
        self.levels
            .iter()
            .map(|l| l.sums.len() * size_of::<Sums>())
            .sum()
    }

    /// Per level (index = level), the bounds of the pixels whose sums
    /// changed since the last call (region-relative; None: none did).
    pub fn take_touched(&mut self) -> Vec<Option<[usize; 4]>> {
        self.levels.iter_mut().map(|l| l.touched.take()).collect()
    }

    fn apply(&mut self, c: &dyn Constraint, sign: i64, kept: Option<&Centres>) {
        let q = self.q;
        let [x0, y0, x1, y1] = c.bounds();
        let hold = c.hold();
        for (i, level) in self.levels.iter_mut().enumerate() {
            let scale = (1u64 << i) as f64;
            let cap = hold.level_cap.map_or(f64::INFINITY, |k| k * scale);
            // Level pixels of the region whose centre lies in the bounds.
            let range = |a: f64, b: f64, from: usize, n: usize| {
                let lo = ((a / scale - 0.5).ceil().max(0.0) as usize).clamp(from, from + n);
                let hi = (((b / scale - 0.5).floor() + 1.0).max(0.0) as usize).min(from + n);
                lo..hi.max(lo)
            };
            let (w, h) = (level.width, level.height);
            if level.sums.is_empty() {
                level.sums = vec![Sums::default(); w * h];
            }
            let (ys, xs) = (range(y0, y1, level.y0, h), range(x0, x1, level.x0, w));
            let stamp = Stamp {
                c,
                kept: kept.filter(|_| i == 0),
                sign,
                q: &q,
                hold: &hold,
                scale,
                cap,
                xs,
                origin: (level.x0, level.y0),
                width: w,
            };
            // Tile rows in parallel, each owning its rows of sums (integer
            // sums: the order of the additions changes nothing). Moving a
            // point samples its footprint twice at every level; serially
            // that was ~8 % of an edit's CPU time, with the other core idle.
            let rows = &mut level.sums[(ys.start - level.y0) * w..(ys.end - level.y0) * w];
            let (reached, touched) = rows
                .par_chunks_mut(TILE * w)
                .enumerate()
                .map(|(k, rows)| {
                    let ty = ys.start + k * TILE;
                    stamp.tile_row(ty..(ty + TILE).min(ys.end), rows)
                })
                .reduce(|| (0, None), |a, b| (a.0 + b.0, union(a.1, b.1)));
            level.reached = level.reached.wrapping_add_signed(reached as isize);
            level.touched = union(level.touched, touched);
        }
    }

    /// The quantized raster of `level` (None past the last level, or where
    /// nothing reaches): per pixel the blended h_t and t = s·d in height
    /// units, d the footprint distance in metres (`cell_size_m` per output
    /// pixel; see the module docs).
    pub fn targets(&self, level: usize, cell_size_m: f64) -> Option<Targets> {
        let l = self.levels.get(level)?;
        if l.reached == 0 {
            return None;
        }
        let px_to_units = cell_size_m / self.q.scale_m;
        // In parallel: at 1024² level 0 is 24 MB of sums.
        let cells = l.sums.par_iter().map(|s| target(s, px_to_units)).collect();
        Some(Targets {
            width: l.width,
            height: l.height,
            cells,
        })
    }

    /// Whether some constraint reaches a pixel of `level` (else
    /// [`Blend::targets`] is None there).
    pub fn reaches(&self, level: usize) -> bool {
        self.levels.get(level).is_some_and(|l| l.reached > 0)
    }

    /// Brings `cells`, the level's [`Blend::targets`] before the sums
    /// changed, up to date within `rect` (the level's
    /// [`Blend::take_touched`] bounds, outside which no sum changed): an
    /// edit moves one constraint, and re-deriving every pixel's target
    /// took ~8 ms per edit at 1024². Returns the bounds of the cells that
    /// changed.
    pub fn retarget(
        &self,
        level: usize,
        cell_size_m: f64,
        cells: &mut [Target],
        rect: Option<[usize; 4]>,
    ) -> Option<[usize; 4]> {
        let (l, [x0, y0, x1, y1]) = (&self.levels[level], rect?);
        assert_eq!(cells.len(), l.sums.len(), "targets of another level");
        let px_to_units = cell_size_m / self.q.scale_m;
        let mut retarget = |k: usize| {
            let t = target(&l.sums[k], px_to_units);
            std::mem::replace(&mut cells[k], t) != t
        };
        (y0..y1)
            .map(|y| {
                row_bounds(
                    y,
                    x0,
                    (y * l.width + x0..y * l.width + x1).map(&mut retarget),
                )
            })
            .fold(None, union)
    }
}

/// The quantized target of a pixel's sums (`px_to_units`: height units
/// per level pixel of tolerance).
#[inline]
fn target(s: &Sums, px_to_units: f64) -> Target {
    if s.b <= 0 {
        return Target::NONE;
    }
    // Nearest integer, ties up, by floor division (exact i64).
    let one = H_FRAC as i64 * s.b;
    let height = (2 * s.bh + one).div_euclid(2 * one);
    let t_px = s.bd as f64 / s.b as f64 / D_FRAC;
    let tol = (t_px * px_to_units).round().min(MAX_TOL as f64) as i32;
    Target {
        height: height.clamp(i32::MIN as i64 / 2, i32::MAX as i64 / 2) as i32,
        tol: if s.exact == 0 { tol | KEEP_DETAIL } else { tol },
    }
}

/// One constraint's contribution to one level's sums ([`Blend`]'s apply),
/// added tile row by tile row.
struct Stamp<'a> {
    c: &'a dyn Constraint,
    /// `c`'s kept samples, at the finest level only (its pixel centres).
    kept: Option<&'a Centres>,
    /// +1 to add the constraint, −1 to take it away.
    sign: i64,
    q: &'a Quantization,
    hold: &'a Hold,
    /// Output pixels per level pixel.
    scale: f64,
    /// The level's reach cap, output pixels.
    cap: f64,
    /// Level columns whose centre lies in the constraint's bounds.
    xs: Range<usize>,
    /// The level region's corner and width (sums are region-relative).
    origin: (usize, usize),
    width: usize,
}

impl Stamp<'_> {
    /// Adds the constraint to level rows `ys` (at most one tile high),
    /// whose sums are `rows`; returns the change in reached pixels and the
    /// bounds of the sums it changed.
    fn tile_row(&self, ys: Range<usize>, rows: &mut [Sums]) -> (i64, Option<[usize; 4]>) {
        let (mut reached, mut touched) = (0, None);
        let (x0, y0) = self.origin;
        for tx in self.xs.clone().step_by(TILE) {
            let tx1 = (tx + TILE).min(self.xs.end);
            // Skip a tile whose every pixel centre is beyond the cap
            // (exact: see `Constraint::distance_bound`).
            let centre = |a: usize, b: usize| (a + b) as f64 / 2.0 * self.scale;
            let spread = ((tx1 - 1 - tx) as f64).hypot((ys.end - 1 - ys.start) as f64);
            let bound = self
                .c
                .distance_bound(centre(tx, tx1), centre(ys.start, ys.end));
            if bound - spread * self.scale / 2.0 > self.cap.min(self.hold.max_reach) {
                continue;
            }
            for y in ys.clone() {
                let row = &mut rows[(y - ys.start) * self.width..][..self.width];
                let mut hit = None;
                for x in tx..tx1 {
                    if let Some(change) = self.pixel(&mut row[x - x0], x, y) {
                        reached += change;
                        hit = Some((hit.map_or(x, |(a, _)| a), x + 1));
                    }
                }
                if let Some((a, b)) = hit {
                    touched = union(touched, Some([a - x0, y - y0, b - x0, y - y0 + 1]));
                }
            }
        }
        (reached, touched)
    }

    /// Adds the constraint to level pixel (x, y)'s sums `cell`; `None` where
    /// it does not reach the pixel, else the change in reached pixels.
    fn pixel(&self, cell: &mut Sums, x: usize, y: usize) -> Option<i64> {
        let at = |v: usize| (v as f64 + 0.5) * self.scale;
        let s = match self.kept {
            Some(k) => k.get(self.c, x, y)?,
            None => self.c.sample(at(x), at(y))?,
        };
        // NaN distances (a broken constraint) never count.
        let inside = s.distance <= s.reach.min(self.cap);
        if !inside {
            return None;
        }
        // Radius of the disc inscribed in a pixel's footprint.
        let d_tol = (s.distance - self.scale / 2.0).max(0.0);
        let t_px = self.hold.tolerance_slope * d_tol;
        let (b, bh, bd) = contribution(self.q, s.target_m, s.distance, t_px);
        let was = cell.b != 0;
        cell.b += self.sign * b;
        cell.bh += self.sign * bh;
        cell.bd += self.sign * bd;
        cell.exact += self.sign * !self.hold.keeps_detail as i64;
        Some((cell.b != 0) as i64 - was as i64)
    }
}

/// One sample's integer (b, b·h_t, b·t): b = 1/(1 + d) in 2^-20 from the
/// centre distance d, heights in 1/16 unit, the tolerance t = s·d_t in
/// 1/1024 pixel of height (converted to height units by the cell size).
fn contribution(q: &Quantization, target_m: f64, d: f64, t_px: f64) -> (i64, i64, i64) {
    let b = (B_ONE / (1.0 + d)).round() as i64;
    let h = (q.units(target_m) * H_FRAC).round().clamp(-1e12, 1e12) as i64;
    let dq = (t_px * D_FRAC).round() as i64;
    (b, b * h, b * dq)
}

#[cfg(test)]
mod tests;
