//! Curvature-like descriptors: the Laplacian (convex ridges negative,
//! concave valleys positive) and the topographic position index (how far a
//! cell stands above or below its surroundings).

use super::interior;
use crate::heightfield::Heightfield;
use rayon::prelude::*;

/// Half-width of the TPI window: 11 × 11 cells.
pub const TPI_RADIUS: usize = 5;

/// The 5-point Laplacian (N + S + E + W − 4·centre) / cell², in 1/m, at
/// every interior cell.
pub fn laplacian(hf: &Heightfield) -> Vec<f32> {
    let inv = 1.0 / (hf.cell_size() * hf.cell_size());
    interior(hf, 1, |n| {
        ((n.at(1, 0) + n.at(-1, 0) + n.at(0, 1) + n.at(0, -1) - 4.0 * n.at(0, 0)) * inv) as f32
    })
}

/// Topographic position index, metres: the height minus the mean of the
/// 11 × 11 window around it (the cell included), at every cell whose window
/// lies inside the terrain. Window sums come from a summed-area table.
pub fn tpi(hf: &Heightfield) -> Vec<f32> {
    let (w, h) = (hf.width(), hf.height());
    let r = TPI_RADIUS;
    if w <= 2 * r || h <= 2 * r {
        return Vec::new();
    }
    // sat[(y)(w+1) + x] = sum of heights above and left of (x, y).
    let mut sat = vec![0.0f64; (w + 1) * (h + 1)];
    for y in 0..h {
        let mut run = 0.0;
        for x in 0..w {
            run += hf.get(x, y) as f64;
            sat[(y + 1) * (w + 1) + x + 1] = sat[y * (w + 1) + x + 1] + run;
        }
    }
    let side = 2 * r + 1;
    let inv = 1.0 / (side * side) as f64;
    let iw = w - 2 * r;
    let mut out = vec![0.0f32; iw * (h - 2 * r)];
    out.par_chunks_mut(iw).enumerate().for_each(|(j, row)| {
        let y = j + r;
        for (i, o) in row.iter_mut().enumerate() {
            let x = i + r;
            let (x0, y0, x1, y1) = (x - r, y - r, x + r + 1, y + r + 1);
            let s = sat[y1 * (w + 1) + x1] - sat[y0 * (w + 1) + x1] - sat[y1 * (w + 1) + x0]
                + sat[y0 * (w + 1) + x0];
            *o = (hf.get(x, y) as f64 - s * inv) as f32;
        }
    });
    out
}
