//! Drainage: D8 flow accumulation and pits, on the raw surface (no pit
//! filling — real DEMs drain almost everywhere, and the pits a synthesis
//! makes are exactly what this should see).

use super::interior;
use crate::heightfield::Heightfield;
use rayon::prelude::*;

/// The 8 neighbour offsets in the fixed order ties are broken by (the first
/// steepest wins), with their distances in cells.
const NEIGHBOURS: [(isize, isize, f64); 8] = [
    (-1, -1, std::f64::consts::SQRT_2),
    (0, -1, 1.0),
    (1, -1, std::f64::consts::SQRT_2),
    (-1, 0, 1.0),
    (1, 0, 1.0),
    (-1, 1, std::f64::consts::SQRT_2),
    (0, 1, 1.0),
    (1, 1, std::f64::consts::SQRT_2),
];

/// No downslope neighbour: the flow ends here.
const SINK: u32 = u32::MAX;

/// D8 drainage area in cells (the cell itself included) of every cell: each
/// cell sends everything it collects to the neighbour of steepest descent
/// (drop over distance, diagonals at √2), or nowhere when no neighbour is
/// lower (a pit or a flat). Cells on the edge are outlets: they collect
/// but pass nothing on, as if the terrain went on beyond them (otherwise
/// every edge would become a channel running along the border, collecting a
/// quarter of a cone at each corner).
pub fn d8_area(hf: &Heightfield) -> Vec<u32> {
    let (w, h) = (hf.width(), hf.height());
    let data = hf.data();
    let mut receiver = vec![SINK; w * h];
    receiver.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        if y == 0 || y == h - 1 {
            return;
        }
        for (x, r) in row.iter_mut().enumerate().take(w - 1).skip(1) {
            let c = data[y * w + x] as f64;
            let mut best = 0.0;
            for &(dx, dy, dist) in &NEIGHBOURS {
                let k = ((y as isize + dy) * w as isize + x as isize + dx) as usize;
                let drop = (c - data[k] as f64) / dist;
                if drop > best {
                    best = drop;
                    *r = k as u32;
                }
            }
        }
    });
    // Accumulate in topological order: a cell passes its area on once every
    // donor has passed theirs (heights strictly fall along the flow, so
    // there are no cycles).
    let mut donors = vec![0u8; w * h];
    for &r in &receiver {
        if r != SINK {
            donors[r as usize] += 1;
        }
    }
    let mut area = vec![1u32; w * h];
    let mut ready: Vec<u32> = (0..(w * h) as u32)
        .filter(|&i| donors[i as usize] == 0)
        .collect();
    while let Some(i) = ready.pop() {
        let r = receiver[i as usize];
        if r != SINK {
            area[r as usize] += area[i as usize];
            donors[r as usize] -= 1;
            if donors[r as usize] == 0 {
                ready.push(r);
            }
        }
    }
    area
}

/// log₁₀ of [`d8_area`], the form its distribution is compared in.
pub fn log_area(hf: &Heightfield) -> Vec<f32> {
    d8_area(hf)
        .par_iter()
        .map(|&a| (a as f32).log10())
        .collect()
}

/// Fraction of the interior cells (one in from each edge) that are strict
/// local minima: lower than all 8 neighbours.
pub fn pit_fraction(hf: &Heightfield) -> f64 {
    let pits = interior(hf, 1, |n| {
        let c = n.at(0, 0);
        let pit = NEIGHBOURS.iter().all(|&(dx, dy, _)| n.at(dx, dy) > c);
        pit as u8 as f32
    });
    if pits.is_empty() {
        0.0
    } else {
        pits.iter().filter(|&&p| p > 0.0).count() as f64 / pits.len() as f64
    }
}
