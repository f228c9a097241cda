//! Descriptors of the height distribution itself: relief and hypsometry.

use super::distance::Sample;

/// Relief, metres: the 99th minus the 1st percentile of the heights, so a
/// single spike or pit (or a few synthesis outliers) does not define it.
pub fn relief(heights: &Sample) -> f64 {
    heights.quantile(0.99) - heights.quantile(0.01)
}

/// Hypsometric integral (Strahler 1952): (mean − min) / (max − min) of the
/// heights, in 0..=1 (high: plateaus and young uplands; low: eroded
/// lowlands with isolated peaks). 0.5 for a flat terrain.
pub fn hypsometric_integral(heights: &Sample) -> f64 {
    let v = heights.values();
    let (min, max) = (v[0] as f64, v[v.len() - 1] as f64);
    if max > min {
        (heights.mean_std().0 - min) / (max - min)
    } else {
        0.5
    }
}
