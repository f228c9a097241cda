//! Local roughness: how much the heights vary within a cell's immediate
//! neighbourhood, whatever the slope direction.

use super::interior;
use crate::heightfield::Heightfield;

/// Standard deviation (population) of the 3 × 3 heights around each interior
/// cell, metres.
pub fn roughness(hf: &Heightfield) -> Vec<f32> {
    interior(hf, 1, |n| {
        let c = n.at(0, 0); // centred on the middle cell for precision
        let (mut s, mut s2) = (0.0, 0.0);
        for dy in -1..=1 {
            for dx in -1..=1 {
                let d = n.at(dx, dy) - c;
                s += d;
                s2 += d * d;
            }
        }
        let mean = s / 9.0;
        (s2 / 9.0 - mean * mean).max(0.0).sqrt() as f32
    })
}
