//! How high a paste lands: on the ground under its lasso, or at its
//! source's own altitude.
//!
//! Why the ground is the default (scene version 2): a paste that kept its
//! source's absolute heights dropped a piece of plateau onto a lowland as a
//! cookie-cutter mesa — 83–87° walls, steps of up to 1.1 km along the lasso
//! (issue 40) — and left the user guessing δ by hand. Lifted by the median
//! step between the ground under the lasso and the source along it (or
//! more, so that its floor does not sink below the ground's), the paste
//! meets the terrain where it is put, and δ raises or lowers it from
//! there. The lift is one constant, so the pasted relief is the source's,
//! exactly, all the way to the lasso: one constant cannot match a whole
//! rim, though (a massif's rim rises and falls by hundreds of metres where
//! a lowland's does not), so the paste reaches [`SEAM`] px beyond its
//! lasso, where the source's own terrain beyond the lasso bends from the
//! paste's heights to the ground's and takes up what is left of the step.
//!
//! Why the seam lies outside the lasso (it lay inside until stop 72): the
//! user lassoes what they want copied, and a seam inside bent the lasso's
//! outer 3 px (5 px with the blends) to the ground — 8–15 % of a 92-px
//! lasso, so only 85–92 % of the pasted pixels were within 0.5 % of relief
//! of source + lift where issue 40 asks 95 %. Outside, the paste is exact
//! from 2 px inside its lasso, and the bend has room to be a slope.

use crate::level::atlas::AtlasLevel;
use crate::level::fixed::{Coord, round};
use crate::stages::common::texel_height;

/// What a paste's δ is added to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lift {
    /// The source's own heights; δ rises from 0 at the lasso over
    /// [`super::PASTE_FEATHER`] (scene version 1, which had nothing else).
    Source,
    /// The ground under the lasso: the source lifted by [`ground_offset`],
    /// then by δ, everywhere inside the lasso, and bent to the ground in a
    /// [`SEAM`] outside it.
    Ground,
}

/// Width of a ground paste's seam outside its lasso, output pixels: the
/// paste writes the source pixels whose centre lies less than this outside
/// the lasso ([`super::Paste::covers`]), their smooth heights bent from
/// the paste's (at the lasso) to the ground's (held over the outer
/// [`SEAM_HOLD`]). Heights reach 2 px further in (`reconstruct` blends the
/// 3×3, `repair_extrema` reads the blends of the 3×3), so a ground paste
/// is its source + lift + δ, exactly, from 2 px inside its lasso.
///
/// Why 16 px: the bend is as steep as the rim's mismatch over this width,
/// and the mismatch is large where a massif lands on a plain — up to a
/// kilometre once the floor rule ([`ground_offset`]) lifts it. Over 2 px it
/// stood as a wall; over 6 px the floor-lifted massif stood as a mesa;
/// over 16 px its flanks run down to the plain at a median 30° (90th
/// percentile 55°, the massif's own slopes 23°; 512², 92.6-m cells).
pub const SEAM: f64 = 16.0;

/// How far (output pixels) the seam keeps the ground's smooth height whole
/// at its outer edge before bending to the paste's.
///
/// Why: the pixel at the seam's edge is what meets the ground, and
/// `reconstruct` blends its height with its 3×3 neighbours' predictions.
/// A bend starting at the edge itself left that pixel a few per cent of
/// the rim's mismatch off the ground, plus half its neighbour's bend:
/// with a massif pasted on a plain at 1024² the median step across the
/// edge was 43 m, 2.3× the terrain's own 3-px step; held over the first
/// pixel it was 17 m (0.93×).
pub const SEAM_HOLD: f64 = 1.0;

/// Where a paste lies, level-0 source pixels, row-major: those inside its
/// lasso, and its rim — the pixels it writes (the seam included) with a
/// 4-neighbour it does not write.
pub struct Footprint {
    pub inner: Vec<(usize, usize)>,
    pub rim: Vec<(usize, usize)>,
}

/// The [`Footprint`] of a paste that writes the source pixels `writes`
/// accepts over `[x0, x1) × [y0, y1)`, those of them `inner` accepts
/// inside its lasso.
pub fn footprint(
    (x0, y0, x1, y1): (usize, usize, usize, usize),
    writes: impl Fn(usize, usize) -> bool,
    inner: impl Fn(usize, usize) -> bool,
) -> Footprint {
    let out = |x: usize, y: usize, dx: isize, dy: isize| {
        let (u, v) = (x.checked_add_signed(dx), y.checked_add_signed(dy));
        !matches!((u, v), (Some(u), Some(v)) if writes(u, v))
    };
    let all: Vec<(usize, usize)> = (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .filter(|&(x, y)| writes(x, y))
        .collect();
    let rim = (all.iter().copied())
        .filter(|&(x, y)| {
            [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(dx, dy)| out(x, y, dx, dy))
        })
        .collect();
    let inner = all.into_iter().filter(|&(x, y)| inner(x, y)).collect();
    Footprint { inner, rim }
}

/// The low quantile (per cent) [`ground_offset`] takes of the ground along
/// a paste's rim and of the paste itself: low enough to be the floor of
/// each, high enough that a few pixels in a river bed do not set it.
pub const FLOOR_PERCENT: usize = 2;

/// The lift (database units) that puts a paste on the ground: the median
/// over its rim of the target's height minus the source's, raised where
/// that would sink the paste's floor below the ground's — its
/// [`FLOOR_PERCENT`] quantile inside the lasso below that of the ground
/// along its rim.
/// Heights are the smooth height of a level-0 texel plus its offset: what
/// the previous frame holds at the target, what the paste would write
/// there at δ = 0. 0 for a paste that writes nothing inside its lasso
/// (wholly outside the world).
///
/// Why the median of the steps: it is the lift that makes the typical step
/// along the rim zero, whatever a few pixels on a cliff or in a river do.
/// Why the floor: a rim median alone landed a lasso drawn over ridges
/// around a valley with its ridges on the ground and its valley below it
/// — a 55-px disc of the Pyrenees exemplar on a plain at 102 m had its
/// median inside at −36 m, 55 % of it at or below 0 m, a sunken sea where
/// the user pasted mountains; a massif's lower flank sank the same way
/// into a lake. With the floor, the valley lands on the ground and the
/// ridges rise from it (median 793 m, 2 % at or below 0 m), the seam
/// bringing them down to the plain.
/// Why smooth heights: they are what the correction matches; the detail
/// of both sides is unrelated and would only add noise.
pub fn ground_offset(
    atlas: &AtlasLevel<'_>,
    footprint: &Footprint,
    source: impl Fn(usize, usize) -> (Coord, i32),
    target: impl Fn(usize, usize) -> (Coord, i32),
) -> i32 {
    let height = |(c, v): (Coord, i32)| texel_height(atlas.appearance(round(c.x), round(c.y))) + v;
    let rim = &footprint.rim;
    if rim.is_empty() || footprint.inner.is_empty() {
        return 0;
    }
    let quantile = |mut v: Vec<i32>, percent: usize| {
        let k = (v.len() * percent / 100).min(v.len() - 1);
        *v.select_nth_unstable(k).1
    };
    let ground: Vec<i32> = rim.iter().map(|&(x, y)| height(target(x, y))).collect();
    let steps = (rim.iter().zip(&ground)).map(|(&(x, y), g)| g - height(source(x, y)));
    let paste = (footprint.inner.iter()).map(|&(x, y)| height(source(x, y)));
    let median = quantile(steps.collect(), 50);
    median.max(quantile(ground, FLOOR_PERCENT) - quantile(paste.collect(), FLOOR_PERCENT))
}

/// Bends the values a ground paste writes at one pixel toward the ground
/// in the seam: `values` are the paste's (coordinate, offset) per pass,
/// `ground` what the pixel held in the last pass before the paste, `depth`
/// how far inside the lasso the pixel's source centre lies (output px,
/// [`super::Paste::depth`]: negative in the seam). Each pass's offset
/// moves by `(1 − smoothstep(t))` of the step from the paste's last-pass
/// smooth height to the ground's, with
/// `t = (SEAM + depth − SEAM_HOLD) / (SEAM − SEAM_HOLD)` clamped to [0, 1]:
/// none inside the lasso, all of it at the seam's outer edge.
pub fn seam(atlas: &AtlasLevel<'_>, values: &mut [(Coord, i32)], ground: (Coord, i32), depth: f64) {
    let Some(&last) = values.last() else { return };
    if depth >= 0.0 {
        return;
    }
    let height = |(c, v): (Coord, i32)| texel_height(atlas.appearance(round(c.x), round(c.y))) + v;
    let t = ((SEAM + depth - SEAM_HOLD) / (SEAM - SEAM_HOLD)).clamp(0.0, 1.0);
    let w = 1.0 - t * t * (3.0 - 2.0 * t);
    let step = (w * f64::from(height(ground) - height(last))).round() as i32;
    values.iter_mut().for_each(|v| v.1 += step);
}

/// How far (level-`level` pixels, Chebyshev) a pixel of the seam may lie
/// from a pixel the paste does not write: `SEAM` output px, and one more
/// pixel.
pub fn seam_reach(level: usize) -> usize {
    (SEAM / (1u64 << level) as f64).ceil() as usize + 1
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rim_is_the_written_pixels_beside_unwritten_ones() {
        // A 4×3 block at (2, 1) inside a 10×10 source: its 10 outer pixels.
        let block = |x: usize, y: usize| (2..6).contains(&x) && (1..4).contains(&y);
        let f = footprint((0, 0, 10, 10), block, |x, _| x < 4);
        assert_eq!((f.inner.len(), f.rim.len()), (6, 10));
        assert!(!f.rim.contains(&(3, 2)) && !f.rim.contains(&(4, 2)));
        assert!(f.rim.contains(&(2, 1)) && f.rim.contains(&(5, 3)));
        // A pixel on the source's edge is on the rim.
        assert_eq!(
            footprint((0, 0, 2, 1), |_, _| true, |_, _| true).rim.len(),
            2
        );
    }
}
