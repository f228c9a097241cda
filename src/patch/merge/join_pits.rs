//! Pits made by the joins between patches, taken out once the terrain is
//! whole (the last step of [`crate::patch::synthesize`]).
//!
//! Why: every patch is a piece of a real DEM, but where a graph-cut seam
//! runs, a pixel's eight neighbours come partly from another piece, and
//! that neighbourhood exists in no source. The gradient-domain merge
//! matches the two pieces' slopes, not their small hollows, so such
//! pixels end up lower than all their neighbours far more often than the
//! sources' own ground: in a one-source synthesis from the Pyrenees
//! (y_branch, 512²) 0.62 % of the pixels within two of a seam were strict
//! pits against 0.42 % elsewhere and 0.38 % in the DEM, which put the
//! output's pit density, and its realism ratio's pits descriptor, well off
//! its source's. A pit away from every seam is the source's own and stays.

use crate::procedural::grid::MOORE;
use rayon::prelude::*;

/// Raises every strict pit whose 3×3 neighbourhood spans two placements
/// (`placement`: the [`Canvas::placement`] of each pixel) to its lowest
/// neighbour, so that it drains through it. Returns how many were raised.
///
/// One pass is exact: two strict pits are never neighbours, and a pit
/// raised to its lowest neighbour makes no new one (every other neighbour
/// is at least that high), so the pits are found on the old heights and
/// raised together, in parallel, with the same bytes on any thread count.
///
/// [`Canvas::placement`]: super::Canvas::placement
pub fn repair(heights: &mut [f32], placement: &[u32], w: usize, h: usize) -> usize {
    if w < 3 || h < 3 {
        return 0;
    }
    let raised: Vec<(usize, f32)> = (1..h - 1)
        .into_par_iter()
        .flat_map_iter(|y| {
            let heights = &*heights;
            (1..w - 1).filter_map(move |x| {
                let i = y * w + x;
                let at = |(dx, dy): (isize, isize)| (i as isize + dy * w as isize + dx) as usize;
                let c = heights[i];
                let mut low = f32::INFINITY;
                let mut join = false;
                for &(dx, dy, _) in &MOORE {
                    let j = at((dx, dy));
                    if heights[j] <= c {
                        return None;
                    }
                    low = low.min(heights[j]);
                    join |= placement[j] != placement[i];
                }
                join.then_some((i, low))
            })
        })
        .collect();
    for &(i, low) in &raised {
        heights[i] = low;
    }
    raised.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tilted plane with a one-pixel dimple at `at`.
    fn dimpled(w: usize, h: usize, at: (usize, usize)) -> Vec<f32> {
        let mut v: Vec<f32> = (0..w * h)
            .map(|i| (i % w) as f32 * 2.0 + (i / w) as f32 * 0.5)
            .collect();
        v[at.1 * w + at.0] -= 10.0;
        v
    }

    #[test]
    fn a_pit_on_a_join_is_raised_to_its_lowest_neighbour_and_one_inside_a_piece_stays() {
        let (w, h) = (12, 8);
        // Two placements side by side: columns 0..6 and 6..12.
        let placement: Vec<u32> = (0..w * h).map(|i| (i % w >= 6) as u32).collect();
        let mut on_join = dimpled(w, h, (6, 4));
        let lowest = on_join[3 * w + 5];
        assert_eq!(repair(&mut on_join, &placement, w, h), 1);
        assert_eq!(on_join[4 * w + 6], lowest);
        let mut inside = dimpled(w, h, (3, 4));
        let before = inside.clone();
        assert_eq!(repair(&mut inside, &placement, w, h), 0);
        assert_eq!(inside, before);
    }

    #[test]
    fn no_strict_pit_is_left_on_a_join_and_none_is_made() {
        // A rough field (a hash of the position) cut into 3-px placements:
        // every pixel is near a join.
        let (w, h) = (40, 30);
        let v: Vec<f32> = (0..w * h)
            .map(|i| ((i as u32).wrapping_mul(2_654_435_761) >> 22) as f32)
            .collect();
        let placement: Vec<u32> = (0..w * h).map(|i| ((i % w) / 3) as u32).collect();
        let pits = |v: &[f32]| -> Vec<usize> {
            (0..w * h)
                .filter(|&i| {
                    let (x, y) = (i % w, i / w);
                    x > 0
                        && y > 0
                        && x < w - 1
                        && y < h - 1
                        && (0..9)
                            .filter(|&k| k != 4)
                            .all(|k| v[(y + k / 3 - 1) * w + x + k % 3 - 1] > v[i])
                })
                .collect()
        };
        let before = pits(&v);
        assert!(before.len() > 20, "{}", before.len());
        let mut after = v.clone();
        let n = repair(&mut after, &placement, w, h);
        // Every pit whose neighbourhood spans two 3-px columns is gone;
        // what is left lies in a column's middle, with both sides its own.
        let left = pits(&after);
        assert!(left.iter().all(|&i| i % w % 3 == 1), "{left:?}");
        assert_eq!(n + left.len(), before.len());
        assert!(left.iter().all(|i| before.contains(i)), "a new pit");
        // Only the raised pixels changed, and only upwards.
        let changed = (0..w * h).filter(|&i| after[i] != v[i]).count();
        assert_eq!(changed, n);
        assert!((0..w * h).all(|i| after[i] >= v[i]));
    }
}
