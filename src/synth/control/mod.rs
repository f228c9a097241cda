//! User control inside the correction (paper §5, DESIGN §5): geometric
//! constraints (points here, curves in `curve`), their overlap blend, and
//! the per-level integer rasters the `correct` stage reads.
//!
//! Everything in this module is CPU-side preparation (DESIGN §6 rule 5):
//! constraint geometry may use floats, but what reaches a kernel is
//! quantized once, here, into integers — so the scalar, SIMD and WGSL
//! corrections see the same numbers.
//!
//! Coordinates are *output pixels*: pixel (i, j) of the finest level has its
//! centre at (i + 0.5, j + 0.5). A pixel (x, y) of level i is centred at
//! ((x + 0.5)·2^i, (y + 0.5)·2^i).

pub mod blend;
pub mod centres;
pub mod curve;
pub mod lift;
pub mod point;
pub mod sculpt;

pub use blend::{Blend, Targets};
pub use centres::Centres;
pub use lift::Lift;
pub use point::PointConstraint;
pub use sculpt::SculptLayer;

use thiserror::Error;

/// Type constraints act on levels ≥ this one (paper §5.2: "disabling type
/// constraints when synthesizing the finest two levels"). Geometric
/// constraints act on every level: see [`blend`] for why this departs from
/// §5.1.
pub const FIRST_LEVEL: usize = 2;

/// What one geometric constraint asks of one output position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Target height h_t at this position, metres.
    pub target_m: f64,
    /// Distance d from the position to the constraint site (the point, or the
    /// closest curve point), in output (finest-level) pixels.
    pub distance: f64,
    /// The constraint's reach (area of effect) here, output pixels
    /// (side-dependent for curves, after envelope smoothing).
    pub reach: f64,
}

/// A geometric constraint (point or curve), evaluated in output pixel
/// coordinates (pixel (i, j) has its centre at (i + 0.5, j + 0.5)).
pub trait Constraint: Send + Sync + std::fmt::Debug {
    /// Bounds [x0, y0, x1, y1) of everything it can influence, output pixels.
    fn bounds(&self) -> [f64; 4];
    /// The sample at output position (x, y); None outside its reach.
    fn sample(&self, x: f64, y: f64) -> Option<Sample>;
    /// A lower bound ℓ on the site distance around (x, y): wherever
    /// `sample(p)` is Some, `sample(p).distance ≥ ℓ − |p − (x, y)|`. The
    /// blend skips whole tiles of a level beyond its reach cap with it, so
    /// the finest levels cost a band around the constraint, not its bounds.
    fn distance_bound(&self, x: f64, y: f64) -> f64;
    /// How tightly it holds the terrain around its site ([`blend`]).
    fn hold(&self) -> Hold;
    /// Its samples at the finest level's pixel centres, where it keeps
    /// them (a curve, whose samples are costly): an editing session reads
    /// them to take it out of the blend again. Not to be called from
    /// within a parallel loop that may sample the same constraint (the
    /// first call takes them, in parallel).
    fn centres(&self) -> Option<&Centres> {
        None
    }
    /// Heap bytes it holds, about (its kept samples, a curve's distance
    /// field and envelope): what a session state keeping it costs beyond
    /// its rasters. Shared buffers count in full for every holder, so the
    /// sum over states bounds what they hold.
    fn bytes(&self) -> usize {
        0
    }
}

/// How tightly a geometric constraint holds the terrain (see [`blend`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hold {
    /// s of the tolerance cone t = s·d: the terrain may leave the target by
    /// s metres per metre of distance from the site.
    pub tolerance_slope: f64,
    /// At level i the constraint acts within `min(reach, cap·2^i)` output
    /// pixels (the paper's "min(radius, 4 × 2^d)" with cap 4), or over its
    /// whole reach at every level (`None`).
    pub level_cap: Option<f64>,
    /// No sample reaches farther than this, output pixels (lets the blend
    /// skip tiles without sampling them).
    pub max_reach: f64,
    /// The terrain keeps the exemplar's own detail on the constraint's
    /// shape (a curve's profile) rather than meeting its heights exactly
    /// (a point's site, a sculpt stroke): see
    /// [`own_detail`](crate::stages::correct::nudge::own_detail).
    pub keeps_detail: bool,
}

/// Invalid control inputs. Messages name the field and the allowed range.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ControlError {
    #[error("{field} {value} is invalid: expected {expected}")]
    Value {
        field: &'static str,
        value: f64,
        expected: &'static str,
    },
}

/// Checks that `value` is finite and in `range`, naming `field` otherwise.
pub(crate) fn check(
    field: &'static str,
    value: f64,
    ok: bool,
    expected: &'static str,
) -> Result<f64, ControlError> {
    if value.is_finite() && ok {
        Ok(value)
    } else {
        Err(ControlError::Value {
            field,
            value,
            expected,
        })
    }
}

/// A constraint's stable identity across edits (chosen by the caller, e.g.
/// its index in a scene file), so an edit can replace or remove it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ConstraintId(pub u64);

/// "No type painted here" in a type map.
pub const UNCONSTRAINED: u8 = u8::MAX;

/// Where a pasted region comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum PasteSource {
    /// The session's current terrain (its S and V at every level and pass).
    Terrain,
    /// An exemplar of the database, by index (its own coordinates, V = 0).
    Exemplar(usize),
}

/// A copy-paste (paper §5.3, Fig. 8): the region inside `lasso` (a closed
/// polygon, in output pixels for the terrain or level-0 exemplar pixels for
/// an exemplar) moved by `offset` output pixels and raised by `delta_m`
/// from where `lift` says.
#[derive(Debug, Clone, PartialEq)]
pub struct Paste {
    pub source: PasteSource,
    pub lasso: Vec<(f64, f64)>,
    pub offset: (i64, i64),
    pub delta_m: f64,
    pub lift: Lift,
}

/// Everything the user controls, in memory (a scene file converts to this).
#[derive(Debug, Clone, Default)]
pub struct Controls {
    /// Geometric constraints, by id (sorted, so order never depends on edits).
    pub constraints: std::collections::BTreeMap<ConstraintId, std::sync::Arc<dyn Constraint>>,
    /// R⁰: a type id of the database per output pixel (row-major) or
    /// [`UNCONSTRAINED`]; None = nothing painted.
    pub types: Option<Vec<u8>>,
    /// The freezing brush: true = locked (W⁰ = 0), per output pixel.
    pub freeze: Option<Vec<bool>>,
    /// Pastes applied so far, in order (each stays frozen).
    pub pastes: Vec<Paste>,
    /// The sculpt brushes' strokes ([`sculpt`]); None = nothing sculpted.
    pub sculpt: Option<std::sync::Arc<SculptLayer>>,
}

/// Width of a [`Lift::Source`] paste's height feather, output pixels: δ
/// rises from 0 at the lasso to its full value this far inside
/// ([`Paste::delta_at`]). A [`Lift::Ground`] paste has none.
pub const PASTE_FEATHER: f64 = 16.0;

impl Paste {
    /// The height offset (database units; `delta` is δ in units, with the
    /// ground lift for [`Lift::Ground`]) that the paste adds at source
    /// pixel (x, y) of level `level`: for [`Lift::Ground`], `delta` at every
    /// pixel it writes; for [`Lift::Source`], δ·w with w a
    /// smoothstep of the pixel centre's distance inside the lasso over
    /// [`PASTE_FEATHER`] (0 outside it — coarse levels' masks take any
    /// pixel with a child inside).
    ///
    /// Why: a region raised or lowered by δ all the way to its lasso stood
    /// on a straight wall δ high along it — the unweighted margin around a
    /// paste is a few pixels, too narrow for correction to bridge a large
    /// step (issue 14). Feathered, the paste keeps its source's relief and
    /// the offset comes in over a slope like a real rise. Host-side f64,
    /// one function for sessions and windows, so both write the same V.
    pub fn delta_at(&self, delta: i32, level: usize, x: usize, y: usize) -> i32 {
        if self.lift == Lift::Ground {
            return delta;
        }
        if delta == 0 {
            return 0;
        }
        let t = (self.depth(level, x, y).max(0.0) / PASTE_FEATHER).min(1.0);
        (f64::from(delta) * t * t * (3.0 - 2.0 * t)).round() as i32
    }

    /// How far inside the lasso the centre of level-`level` source pixel
    /// (x, y) lies, output pixels; negative outside it.
    pub fn depth(&self, level: usize, x: usize, y: usize) -> f64 {
        let s = (1u64 << level) as f64;
        let (px, py) = ((x as f64 + 0.5) * s, (y as f64 + 0.5) * s);
        let d = distance_to_polygon(&self.lasso, px, py);
        if inside(&self.lasso, px, py) { d } else { -d }
    }

    /// How far beyond its lasso the paste writes, output pixels: a
    /// [`Lift::Ground`] paste's seam ([`lift::SEAM`]), nothing for a
    /// [`Lift::Source`] one.
    pub fn reach(&self) -> f64 {
        match self.lift {
            Lift::Ground => lift::SEAM,
            Lift::Source => 0.0,
        }
    }

    /// Whether the paste writes the level-0 source pixel centred at
    /// (x, y): inside its lasso, or less than [`Paste::reach`] outside it.
    pub fn covers(&self, x: f64, y: f64) -> bool {
        inside(&self.lasso, x, y)
            || (self.lift == Lift::Ground && distance_to_polygon(&self.lasso, x, y) < self.reach())
    }
}

/// Distance from (x, y) to the nearest edge of the closed polygon.
fn distance_to_polygon(poly: &[(f64, f64)], x: f64, y: f64) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| {
            let ((ax, ay), (bx, by)) = (poly[i], poly[(i + 1) % n]);
            let (ex, ey) = (bx - ax, by - ay);
            let len2 = ex * ex + ey * ey;
            let t = if len2 > 0.0 {
                (((x - ax) * ex + (y - ay) * ey) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            (x - ax - t * ex).hypot(y - ay - t * ey)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Bounds `[x0, y0, x1, y1)` of a `w × h` grid's pixels whose centres may
/// lie inside `lasso` or less than `grow` outside it (a pixel beyond them
/// is farther): the lasso's bounding box widened by `grow` and a pixel
/// more, against rounding in [`inside`]'s crossings. The whole grid when a
/// vertex is not finite.
pub fn lasso_bounds(lasso: &[(f64, f64)], grow: f64, w: usize, h: usize) -> [usize; 4] {
    if lasso.iter().any(|&(x, y)| !x.is_finite() || !y.is_finite()) {
        return [0, 0, w, h];
    }
    let (mut x0, mut y0) = (f64::INFINITY, f64::INFINITY);
    let (mut x1, mut y1) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    for &(x, y) in lasso {
        (x0, x1) = (x0.min(x), x1.max(x));
        (y0, y1) = (y0.min(y), y1.max(y));
    }
    let lo = |v: f64, n: usize| ((v - grow - 1.5).floor().max(0.0) as usize).min(n);
    let hi = |v: f64, n: usize| ((v + grow + 1.5).ceil().max(0.0) as usize).min(n);
    [lo(x0, w), lo(y0, h), hi(x1, w), hi(y1, h)]
}

/// Whether (x, y) lies inside the closed polygon (even-odd rule).
pub fn inside(poly: &[(f64, f64)], x: f64, y: f64) -> bool {
    let mut odd = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + n - 1) % n]);
        if (a.1 > y) != (b.1 > y) && x < a.0 + (y - a.1) * (b.0 - a.0) / (b.1 - a.1) {
            odd = !odd;
        }
    }
    odd
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_pixel_beyond_the_lasso_bounds_is_inside() {
        let lasso = [(3.2, 4.0), (20.7, 5.5), (11.0, 15.9), (6.5, 9.0)];
        let (w, h) = (30, 25);
        let [x0, y0, x1, y1] = lasso_bounds(&lasso, 0.0, w, h);
        for k in 0..w * h {
            let (x, y) = (k % w, k / w);
            if inside(&lasso, x as f64 + 0.5, y as f64 + 0.5) {
                assert!((x0..x1).contains(&x) && (y0..y1).contains(&y), "({x}, {y})");
            }
        }
        assert_eq!(lasso_bounds(&[(f64::NAN, 0.0)], 0.0, w, h), [0, 0, w, h]);
    }

    /// Widened by a ground paste's seam (what the windowed mirror gathers),
    /// the bounds hold every pixel less than the seam outside the lasso.
    #[test]
    fn widened_bounds_hold_the_seam() {
        let lasso = [(40.2, 44.0), (60.7, 45.5), (51.0, 55.9), (46.5, 49.0)];
        let (w, h) = (110, 100);
        let grow = lift::SEAM;
        let [x0, y0, x1, y1] = lasso_bounds(&lasso, grow, w, h);
        let mut seam = 0;
        for k in 0..w * h {
            let (x, y) = (k % w, k / w);
            let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
            if inside(&lasso, cx, cy) || distance_to_polygon(&lasso, cx, cy) < grow {
                seam += usize::from(!inside(&lasso, cx, cy));
                assert!((x0..x1).contains(&x) && (y0..y1).contains(&y), "({x}, {y})");
            }
        }
        assert!(seam > 0, "the seam lies outside the lasso");
        // Clipped to the grid where the seam would run off it.
        assert_eq!(lasso_bounds(&lasso, 50.0, w, h), [0, 0, w, h]);
    }
}
