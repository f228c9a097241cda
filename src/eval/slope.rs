//! Slope (Horn 1981, the 3×3 gradient GDAL and the preview shading use) and
//! what is derived from it: the median slope and Olsen's erosion score.

use super::distance::Sample;
use super::interior;
use crate::heightfield::Heightfield;

/// Slope in degrees at every interior cell (one cell in from each edge):
/// Horn's weighted 3×3 differences, divided by 8 cells, with the true cell
/// size.
pub fn slope_degrees(hf: &Heightfield) -> Vec<f32> {
    let inv = 1.0 / (8.0 * hf.cell_size());
    interior(hf, 1, |n| {
        // n.at(dx, dy): the neighbour at that offset.
        let gx = (n.at(1, -1) + 2.0 * n.at(1, 0) + n.at(1, 1))
            - (n.at(-1, -1) + 2.0 * n.at(-1, 0) + n.at(-1, 1));
        let gy = (n.at(-1, 1) + 2.0 * n.at(0, 1) + n.at(1, 1))
            - (n.at(-1, -1) + 2.0 * n.at(0, -1) + n.at(1, -1));
        let g = (gx * gx + gy * gy).sqrt() * inv;
        g.atan().to_degrees() as f32
    })
}

/// Olsen's erosion score ε = σ / μ of the slope (Olsen 2004, as used by
/// terrain-synthesis papers to tell eroded from noise terrain): here of the
/// Horn slope in degrees. 0 for a flat terrain.
pub fn olsen_epsilon(slope: &Sample) -> f64 {
    let (mean, std) = slope.mean_std();
    if mean > 0.0 { std / mean } else { 0.0 }
}
