//! How high a paste lands: on the ground under its lasso, or at its
//! source's own altitude.
//!
//! Why the ground is the default (scene version 2): a paste that kept its
//! source's absolute heights dropped a piece of plateau onto a lowland as a
//! cookie-cutter mesa — 83–87° walls, steps of up to 1.1 km along the lasso
//! (issue 40) — and left the user guessing δ by hand. Lifted by the median
//! step between the ground under the lasso and the source along it, the
//! paste meets the terrain where it is put, and δ raises or lowers it from
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
//! from 2 px inside its lasso, and the bend has twice the room.

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
/// Why 6 px: the bend is as steep as the rim's mismatch over this width,
/// and the mismatch left after the lift is large where a massif lands on
/// a plain (median 582 m along the rim at 1024²); over 2 px it stood as a
/// wall.
pub const SEAM: f64 = 6.0;

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

/// The level-0 source pixels of a paste's rim, row-major: those it writes
/// (`writes`, over `[x0, x1) × [y0, y1)`) with a 4-neighbour it does not.
pub fn rim(
    (x0, y0, x1, y1): (usize, usize, usize, usize),
    writes: impl Fn(usize, usize) -> bool,
) -> Vec<(usize, usize)> {
    let out = |x: usize, y: usize, dx: isize, dy: isize| {
        let (u, v) = (x.checked_add_signed(dx), y.checked_add_signed(dy));
        !matches!((u, v), (Some(u), Some(v)) if writes(u, v))
    };
    (y0..y1)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .filter(|&(x, y)| writes(x, y))
        .filter(|&(x, y)| {
            [(1, 0), (-1, 0), (0, 1), (0, -1)]
                .iter()
                .any(|&(dx, dy)| out(x, y, dx, dy))
        })
        .collect()
}

/// The lift (database units) that puts a paste on the ground: the median
/// over its `rim` of the target's height minus the source's, each the
/// smooth height of its level-0 texel plus its offset — what the previous
/// frame holds at the target, what the paste would write there at δ = 0.
/// 0 for an empty rim (a paste wholly outside the world).
///
/// Why the median of the steps: it is the lift that makes the typical step
/// along the rim zero, whatever a few pixels on a cliff or in a river do.
/// The rim is the seam's outer edge ([`SEAM`] beyond the lasso), where the
/// seam hands over to the ground.
/// Why smooth heights: they are what the correction matches; the detail
/// of both sides is unrelated and would only add noise.
pub fn ground_offset(
    atlas: &AtlasLevel<'_>,
    rim: &[(usize, usize)],
    source: impl Fn(usize, usize) -> (Coord, i32),
    target: impl Fn(usize, usize) -> (Coord, i32),
) -> i32 {
    let height = |(c, v): (Coord, i32)| texel_height(atlas.appearance(round(c.x), round(c.y))) + v;
    let mut steps: Vec<i32> = rim
        .iter()
        .map(|&(x, y)| height(target(x, y)) - height(source(x, y)))
        .collect();
    if steps.is_empty() {
        return 0;
    }
    let mid = steps.len() / 2;
    *steps.select_nth_unstable(mid).1
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

/// How far (level-`level` pixels, Chebyshev) [`near_seam`] looks for a
/// pixel not written.
pub fn seam_reach(level: usize) -> usize {
    (SEAM / (1u64 << level) as f64).ceil() as usize + 1
}

/// Whether level-`level` source pixel (x, y) may lie in the seam: some
/// pixel within `SEAM` output px (and one more pixel) is not written
/// (`writes`). A cheap test before the exact distance to the lasso.
pub fn near_seam(level: usize, x: usize, y: usize, writes: impl Fn(i64, i64) -> bool) -> bool {
    let r = seam_reach(level) as i64;
    let (x, y) = (x as i64, y as i64);
    (-r..=r).any(|dy| (-r..=r).any(|dx| !writes(x + dx, y + dy)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rim_is_the_written_pixels_beside_unwritten_ones() {
        // A 4×3 block at (2, 1) inside a 10×10 source: its 10 outer pixels.
        let block = |x: usize, y: usize| (2..6).contains(&x) && (1..4).contains(&y);
        let r = rim((0, 0, 10, 10), block);
        assert_eq!(r.len(), 10);
        assert!(!r.contains(&(3, 2)) && !r.contains(&(4, 2)));
        assert!(r.contains(&(2, 1)) && r.contains(&(5, 3)));
        // A pixel on the source's edge is on the rim.
        assert_eq!(rim((0, 0, 2, 1), |_, _| true).len(), 2);
    }
}
