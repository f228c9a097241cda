//! The sea: cells at or below sea level that the open water reaches from
//! the border, 8-connected. A basin below sea level behind higher ground
//! (a polder, the Dead Sea) is not sea; the fill makes it a lake up to its
//! spill level.

use super::d8::CLOCKWISE;
use crate::procedural::grid::neighbour;

/// Which cells are sea at `level` metres.
pub fn mask(heights: &[f32], w: usize, h: usize, level: f32) -> Vec<bool> {
    let mut sea = vec![false; w * h];
    let mut stack: Vec<usize> = Vec::new();
    let border = (0..w)
        .flat_map(|x| [x, (h - 1) * w + x])
        .chain((0..h).flat_map(|y| [y * w, y * w + w - 1]));
    for i in border {
        if !sea[i] && heights[i] <= level {
            sea[i] = true;
            stack.push(i);
        }
    }
    while let Some(c) = stack.pop() {
        let (x, y) = (c % w, c / w);
        for &(dx, dy, _) in &CLOCKWISE {
            if let Some(k) = neighbour(x, y, dx, dy, w, h)
                && !sea[k]
                && heights[k] <= level
            {
                sea[k] = true;
                stack.push(k);
            }
        }
    }
    sea
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_low_ground_joined_to_the_border_is_sea() {
        // A 5×3 strip of land at 5 m: a low cell on the west border, and a
        // basin deeper than it inside the land.
        #[rustfmt::skip]
        let z = [
            5.0, 5.0, 5.0, 5.0, 5.0,
            -1.0, 5.0, -2.0, 5.0, 5.0,
            5.0, 5.0, 5.0, 5.0, 5.0f32,
        ];
        let m = mask(&z, 5, 3, 0.0);
        let sea: Vec<usize> = (0..15).filter(|&i| m[i]).collect();
        assert_eq!(sea, vec![5], "the basin is not sea");
        // At 5 m everything joins.
        assert!(mask(&z, 5, 3, 5.0).iter().all(|&s| s));
    }
}
