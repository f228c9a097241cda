//! How many correction passes the start level takes: more where the
//! exemplars are smooth at the scale of a pixel.
//!
//! The start is a mosaic of pieces whose seams correction heals, level L
//! first. What a seam leaves after the start level's passes is relief at
//! the scale of a few texels, which the finer levels keep and dress with
//! detail. On an exemplar rough at that scale it is lost among the
//! exemplar's own; on one whose relief lives at coarser scales (granite
//! domes and glacial troughs, smooth hillslopes at 30 m) it is relief the
//! exemplar does not have: yosemite's synthesized slopes were 1.2× its
//! DEM's at every quantile and its detail 1.2–1.5× at every scale from 3
//! to 33 px, where the 92-m DEMs' slopes were within 8 %.
//!
//! How smooth an exemplar is at the pixel scale is measured by
//! [`coarse_share`]: the median gradient at level 2 (4 × 4 block means)
//! over the median gradient at level 0, both per metre — how much of the
//! exemplar's slope survives a 4× coarser view. On the 8 shared DEMs it
//! is 0.47 (the north German plain) to 0.61 for the 92-m hills and
//! coasts, 0.71 for the Pyrenees, 0.76 for the Olympic coast and 0.88 for
//! Yosemite.
//!
//! Measured (single-exemplar databases, seeds 11–13, exemplar size; start
//! level passes / median slope against the DEM's): Yosemite 2 / 120 %,
//! 4 / 109 %, 6 / 104 %, 8 / 101 % (copies 12 → 24 %, its halves 21 %);
//! the Olympic coast 2 / 116 %, 4 / 104 %; but the hills lose slope they
//! need (thuringia and the Franconian Jura 95 → 90 % at 4, 86–87 % at 6;
//! catalan 105 → 93 → 85 %), and at 3× the exemplar's side more so
//! (catalan 84 % and 10 % copied at 4). So the passes follow the measure
//! ([`factor`]) rather than one count for all: ×3 for Yosemite (104 %;
//! worlds 3× its side 117 → 99 %), ×2 for the Olympic coast (104 %) and
//! the Pyrenees (98 → 96 %), ×1 for the other five, whose outputs are
//! unchanged — as are the embedded database's, pooled at 0.64.

use crate::database::Database;

/// The share of an exemplar's slope at level 2 from which the start level
/// takes twice the passes (three times from `FROM + STEP`, …).
const FROM: f64 = 0.7;
const STEP: f64 = 0.1;
/// The most a start level's passes are multiplied by.
const MAX_FACTOR: u32 = 4;

/// The start level's passes are the other levels' times this, for the
/// pieces of `start_exemplar` (all exemplars pooled when None).
pub fn factor(db: &Database, start_exemplar: Option<usize>) -> u32 {
    let rects = &db.level(0).layout.rects;
    let heights = db.heights();
    let grids: Vec<Grid<'_>> = match start_exemplar {
        Some(e) => vec![e],
        None => (0..rects.len()).collect(),
    }
    .into_iter()
    .map(|e| {
        let r = rects[e];
        let start = r.offset as usize;
        let texels = &heights[start..start + r.texels() as usize];
        (texels, r.width as usize, r.height as usize)
    })
    .collect();
    factor_of(coarse_share(&grids))
}

/// The factor for a [`coarse_share`]: 1 below [`FROM`], 2 from it, one
/// more every [`STEP`] above, at most [`MAX_FACTOR`].
fn factor_of(share: f64) -> u32 {
    let steps = ((share - FROM) / STEP).floor();
    if steps.is_nan() || steps < 0.0 {
        1
    } else {
        // `as` saturates, so a huge share cannot overflow.
        (steps as u32).saturating_add(2).min(MAX_FACTOR)
    }
}

/// Row-major heights (any linear unit: the share is a ratio), width and
/// height.
type Grid<'a> = (&'a [u16], usize, usize);

/// Median gradient of level 2 (4 × 4 block means) over that of level 0,
/// both per unit of distance, of `grids` pooled; 0 when none has interior
/// level-2 pixels. In integers: a level-0 central difference is
/// `d₀ / 2`, a level-2 one `(d_S / 16) / (2 · 4)` with `d_S` a
/// difference of block sums, so the share is `√(med d_S² / med d₀²) / 64`
/// with both medians exact.
pub fn coarse_share(grids: &[Grid<'_>]) -> f64 {
    let (mut fine, mut coarse) = (Vec::new(), Vec::new());
    for &(heights, w, h) in grids {
        squared_differences(heights, w, h, &mut fine);
        let (w2, h2) = (w / 4, h / 4);
        let sums: Vec<u32> = (0..w2 * h2)
            .map(|k| {
                let (x, y) = (4 * (k % w2), 4 * (k / w2));
                (0..16)
                    .map(|i| u32::from(heights[(y + i / 4) * w + x + i % 4]))
                    .sum()
            })
            .collect();
        squared_differences(&sums, w2, h2, &mut coarse);
    }
    match (median(&mut fine), median(&mut coarse)) {
        (Some(f), Some(c)) if f > 0 => (c as f64 / f as f64).sqrt() / 64.0,
        _ => 0.0,
    }
}

/// Appends `dx² + dy²` of the central differences (`v[x+1] − v[x−1]`,
/// likewise in y) of every interior pixel of a `w × h` grid.
fn squared_differences<T: Copy + Into<i64>>(v: &[T], w: usize, h: usize, out: &mut Vec<u64>) {
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let k = y * w + x;
            let dx = v[k + 1].into() - v[k - 1].into();
            let dy = v[k + w].into() - v[k - w].into();
            out.push((dx * dx + dy * dy) as u64);
        }
    }
}

/// The lower median (None when empty).
fn median(v: &mut [u64]) -> Option<u64> {
    if v.is_empty() {
        return None;
    }
    let mid = (v.len() - 1) / 2;
    Some(*v.select_nth_unstable(mid).1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_median_is_the_lower_middle_value() {
        assert_eq!(median(&mut []), None);
        assert_eq!(median(&mut [3, 1, 2]), Some(2));
        assert_eq!(median(&mut [4, 1, 3, 2]), Some(2));
    }

    /// A grid of `w × h` pixels with heights `f(x, y)`.
    fn grid(w: usize, h: usize, f: impl Fn(f64, f64) -> f64) -> (Vec<u16>, usize, usize) {
        let v = (0..w * h)
            .map(|k| f((k % w) as f64, (k / w) as f64).round() as u16)
            .collect();
        (v, w, h)
    }

    fn share(grids: &[&(Vec<u16>, usize, usize)]) -> f64 {
        let g: Vec<Grid<'_>> = grids.iter().map(|(v, w, h)| (&v[..], *w, *h)).collect();
        coarse_share(&g)
    }

    #[test]
    fn a_plane_keeps_all_its_slope_at_level_2() {
        let s = share(&[&grid(64, 48, |x, y| 300.0 + 3.0 * x + 4.0 * y)]);
        assert!((s - 1.0).abs() < 1e-12, "{s}");
    }

    #[test]
    fn pixel_noise_keeps_little_and_a_long_wave_most() {
        let noise = grid(128, 128, |x, y| {
            (crate::hash::hash4(7, x as u32, y as u32, 0) % 1000) as f64
        });
        let wave = grid(128, 128, |x, y| {
            2000.0 + (x / 40.0).sin() * 500.0 + (y / 30.0).cos() * 400.0
        });
        let (n, l) = (share(&[&noise]), share(&[&wave]));
        assert!(n < 0.3, "noise {n}");
        assert!(l > 0.9, "wave {l}");
        // Pooled, the share lies between the two.
        let both = share(&[&noise, &wave]);
        assert!(both > n && both < l, "{n} < {both} < {l}");
    }

    #[test]
    fn the_factor_steps_up_from_0_7_every_0_1() {
        let f: Vec<u32> = [
            0.0,
            0.47,
            0.699,
            0.7,
            0.76,
            0.8,
            0.88,
            0.95,
            1.0,
            1.3,
            f64::NAN,
        ]
        .iter()
        .map(|&s| factor_of(s))
        .collect();
        assert_eq!(f, [1, 1, 1, 2, 2, 3, 3, 4, 4, 4, 1]);
    }
}
