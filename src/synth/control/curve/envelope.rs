//! Isocurve smoothing of the area-of-effect envelope (paper §5.1, Fig. 5).
//!
//! The reach at a pixel comes from the closest curve point, whose parameter
//! jumps across the medial axis (e.g. at the centre of an arc); where the
//! reach varies along the curve, the raw envelope {d ≤ reach(t(p))} then has
//! steps and spikes. As in the paper we extract the envelope's boundary
//! isocurve, smooth it, and let the smoothed boundary decide the extent.
//!
//! - `f = d − reach` on the field's lattice; its zero isocurve (marching
//!   squares, saddles split by the cell mean) gives closed loops.
//! - Each loop is resampled to unit spacing and low-passed along its arc
//!   length (a twiced Gaussian, σ = [`sigma`] of the largest reach), which
//!   removes steps without moving smooth parts of the boundary noticeably.
//! - The effective reach at a node is `d + s`, with `s` the signed distance
//!   to the smoothed loops (positive inside, even-odd rule) clamped to
//!   ±[`BAND`]. Inside ⇔ `d ≤ reach_eff`, and within the band (where the
//!   boundary is) `reach_eff ≈ reach(t)` away from the jumps; being the sum
//!   of two 1-Lipschitz functions it changes by at most 2 per pixel
//!   everywhere, so the extent has no discontinuity left. Deeper inside,
//!   `d + BAND` is a lower bound of the true extent: the overlap blend only
//!   asks whether `d ≤ min(reach, 4·2^i)`, which the bound answers exactly,
//!   and the clamp keeps the search local (envelope rebuild of a 1024-px
//!   meander, reach 60 px: 578 → 304 ms on 2 cores, `benches/curve.rs`).

use super::field::{DistanceField, NONE, TILE, tiles};
use super::segments::{Hit, Segments};
use glam::DVec2;
use rayon::prelude::*;
use std::collections::HashMap;

/// A curve's area of effect on its field's lattice. It depends on the
/// field and the reach along the curve alone (not on heights or slopes),
/// so [`super::FieldCache`] keeps it beside the field: changing a widget's
/// height rebuilt it for ~30 ms per edit of a 1024-px curve.
#[derive(Debug, Default)]
pub struct Envelope {
    /// Effective reach per field node (see [`effective_reach`]).
    pub reach_eff: Vec<f32>,
    /// The smoothed boundary (closed loops), output pixels.
    pub smoothed: Vec<Vec<DVec2>>,
    /// The boundary before smoothing, output pixels.
    pub raw: Vec<Vec<DVec2>>,
}

impl Envelope {
    /// Heap bytes held, about: the nodes' reach and the boundaries.
    pub fn bytes(&self) -> usize {
        let points = |v: &Vec<Vec<DVec2>>| v.iter().map(Vec::len).sum::<usize>();
        self.reach_eff.len() * 4 + (points(&self.smoothed) + points(&self.raw)) * size_of::<DVec2>()
    }

    /// Raw envelope `d − reach` per node of `f` (`reach` of a node's
    /// closest point), its isocurve, the isocurve smoothed with `sigma`,
    /// and the effective reach; rows in parallel.
    pub fn compute(
        f: &DistanceField,
        sigma: f64,
        reach: impl Fn(Hit, DVec2) -> f64 + Sync,
    ) -> Envelope {
        let (w, h) = (f.width, f.height);
        let mut d = vec![f64::INFINITY; w * h];
        let mut excess = vec![f64::INFINITY; w * h];
        d.par_chunks_mut(w)
            .zip(excess.par_chunks_mut(w))
            .enumerate()
            .for_each(|(j, (drow, erow))| {
                for i in 0..w {
                    let s = f.node(i as i64, j as i64);
                    if s == NONE {
                        continue;
                    }
                    let p = DVec2::new((f.x0 + i as i64) as f64, (f.y0 + j as i64) as f64);
                    let hit = f.segments.project(s, p);
                    drow[i] = hit.dist;
                    erow[i] = hit.dist - reach(hit, p);
                }
            });
        let origin = DVec2::new(f.x0 as f64, f.y0 as f64);
        let raw = isocurves(&excess, w, h);
        let smoothed: Vec<Vec<DVec2>> = raw.iter().map(|l| smooth_loop(l, sigma)).collect();
        let reach_eff = effective_reach(&smoothed, &d, w, h);
        let shift = |ls: &[Vec<DVec2>]| -> Vec<Vec<DVec2>> {
            ls.iter()
                .map(|l| l.iter().map(|p| *p + origin).collect())
                .collect()
        };
        Envelope {
            reach_eff,
            smoothed: shift(&smoothed),
            raw: shift(&raw),
        }
    }
}

/// Gaussian σ along the boundary, output pixels, for a curve whose largest
/// reach is `max_reach`: 0.4 of it, within 1..=48. Steps at the medial
/// axis are as tall as the reach difference between the two curve points
/// meeting there, so the smoothing scale follows the reach.
pub fn sigma(max_reach: f64) -> f64 {
    (0.4 * max_reach).clamp(1.0, 48.0)
}

/// Zero isocurve of `f` (row-major `w × h` lattice; non-finite = far
/// outside) as closed loops in lattice coordinates. Values ≤ 0 are inside.
pub fn isocurves(f: &[f64], w: usize, h: usize) -> Vec<Vec<DVec2>> {
    // Pad with an outside ring so every loop closes.
    let at = |i: i64, j: i64| -> f64 {
        if i < 0 || j < 0 || i >= w as i64 || j >= h as i64 {
            return 1.0;
        }
        let v = f[j as usize * w + i as usize];
        if v.is_finite() { v } else { 1.0 }
    };
    // Edge ids: horizontal edge (i, j)→(i+1, j) = 2·n, vertical = 2·n + 1,
    // with n indexing the padded lattice.
    let pw = w as i64 + 2;
    let hid = |i: i64, j: i64| (((j + 1) * pw + (i + 1)) * 2) as u64;
    let vid = |i: i64, j: i64| (((j + 1) * pw + (i + 1)) * 2 + 1) as u64;
    let cross = |a: f64, b: f64| -> f64 {
        let t = a / (a - b);
        if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.5
        }
    };
    let point = |id: u64| -> DVec2 {
        let n = (id / 2) as i64;
        let (i, j) = (n % pw - 1, n / pw - 1);
        if id % 2 == 0 {
            DVec2::new(i as f64 + cross(at(i, j), at(i + 1, j)), j as f64)
        } else {
            DVec2::new(i as f64, j as f64 + cross(at(i, j), at(i, j + 1)))
        }
    };
    // Directed segments with the inside on their left (in y-down lattice
    // coordinates: cross(dir, inside − start) < 0), chained into loops.
    let mut next: HashMap<u64, u64> = HashMap::new();
    for j in -1..h as i64 {
        for i in -1..w as i64 {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            let code = (a <= 0.0) as u8
                | ((b <= 0.0) as u8) << 1
                | ((c <= 0.0) as u8) << 2
                | ((d <= 0.0) as u8) << 3;
            let (top, right, bottom, left) = (hid(i, j), vid(i + 1, j), hid(i, j + 1), vid(i, j));
            let centre_in = (a + b + c + d) / 4.0 <= 0.0;
            let segs: &[(u64, u64)] = match code {
                0 | 15 => &[],
                1 => &[(left, top)],
                2 => &[(top, right)],
                3 => &[(left, right)],
                4 => &[(right, bottom)],
                5 if centre_in => &[(left, bottom), (right, top)],
                5 => &[(left, top), (right, bottom)],
                6 => &[(top, bottom)],
                7 => &[(left, bottom)],
                8 => &[(bottom, left)],
                9 => &[(bottom, top)],
                10 if centre_in => &[(top, left), (bottom, right)],
                10 => &[(top, right), (bottom, left)],
                11 => &[(bottom, right)],
                12 => &[(right, left)],
                13 => &[(right, top)],
                14 => &[(top, left)],
                _ => unreachable!("4-bit code"),
            };
            for &(s, e) in segs {
                next.insert(s, e);
            }
        }
    }
    let mut starts: Vec<u64> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut loops = Vec::new();
    for s in starts {
        if !next.contains_key(&s) {
            continue;
        }
        let mut lp = Vec::new();
        let mut cur = s;
        while let Some(n) = next.remove(&cur) {
            lp.push(point(cur));
            cur = n;
        }
        if lp.len() >= 3 {
            loops.push(lp);
        }
    }
    loops
}

/// Resamples a closed loop to unit spacing and low-passes it with a
/// Gaussian of `sigma` samples (circularly), "twiced": `2·G∗x − G∗G∗x`.
/// Plain Gaussian smoothing shrinks a loop by ≈ σ²κ/2 (1.5 px on a 25 px
/// arc at σ = 8.75), pulling the whole envelope in; twicing cancels that
/// second-order term while still removing steps shorter than σ.
pub fn smooth_loop(lp: &[DVec2], sigma: f64) -> Vec<DVec2> {
    let mut closed = lp.to_vec();
    closed.push(lp[0]);
    let Some(mut r) = super::smooth::resample(&closed) else {
        return lp.to_vec();
    };
    r.pop();
    let once = gaussian(&r, sigma);
    let twice = gaussian(&once, sigma);
    once.iter()
        .zip(&twice)
        .map(|(a, b)| *a * 2.0 - *b)
        .collect()
}

fn gaussian(r: &[DVec2], sigma: f64) -> Vec<DVec2> {
    let n = r.len();
    let half = ((3.0 * sigma).ceil() as usize).min(n / 2);
    let w: Vec<f64> = (0..=half)
        .map(|k| (-((k * k) as f64) / (2.0 * sigma * sigma)).exp())
        .collect();
    let total: f64 = w[0] + 2.0 * w[1..].iter().sum::<f64>();
    (0..n)
        .map(|i| {
            let mut acc = r[i] * w[0];
            for (k, &wk) in w.iter().enumerate().skip(1) {
                acc += (r[(i + k) % n] + r[(i + n - k % n) % n]) * wk;
            }
            acc / total
        })
        .collect()
}

/// How far from the smoothed boundary the effective reach is exact, pixels.
pub const BAND: f64 = 16.0;

/// Effective reach per node: `d + s`, `s` the signed distance to `loops`
/// (lattice coordinates; positive inside by the even-odd rule) clamped to
/// ±[`BAND`]; tile rows in parallel, each node comparing its tile's
/// candidate segments ([`Segments::tile_candidates`]; tiles all farther
/// than [`BAND`] from the loops take ±[`BAND`] without a query).
pub fn effective_reach(loops: &[Vec<DVec2>], d: &[f64], w: usize, h: usize) -> Vec<f32> {
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for lp in loops {
        for k in 0..lp.len() {
            a.push(lp[k]);
            b.push(lp[(k + 1) % lp.len()]);
        }
    }
    let segs = Segments::new(a, b);
    let mut out = vec![0f32; w * h];
    out.par_chunks_mut(TILE * w)
        .enumerate()
        .for_each(|(t, rows)| {
            let (j0, n) = (t * TILE, rows.len() / w);
            // Each tile's candidate segments; none for tiles all farther
            // than BAND from the boundary: s = ±BAND.
            let near: Vec<Option<Vec<(f64, u32)>>> = tiles(w)
                .map(|(i0, i1)| {
                    let mut c = Vec::new();
                    let corner = DVec2::new(i0 as f64, j0 as f64);
                    segs.tile_candidates(corner, (i1 - i0, n), BAND, &mut c)
                        .then_some(c)
                })
                .collect();
            for (dj, row) in rows.chunks_mut(w).enumerate() {
                let j = j0 + dj;
                let y = j as f64;
                // Even-odd crossings of this row (half-open in y).
                let mut xs: Vec<f64> = Vec::new();
                for k in 0..segs.len() {
                    let (p, q) = (segs.a[k], segs.b[k]);
                    if (p.y <= y) != (q.y <= y) {
                        xs.push(p.x + (y - p.y) / (q.y - p.y) * (q.x - p.x));
                    }
                }
                xs.sort_by(f64::total_cmp);
                for (i, slot) in row.iter_mut().enumerate() {
                    let x = i as f64;
                    let di = d[j * w + i];
                    if !di.is_finite() {
                        *slot = -1.0;
                        continue;
                    }
                    let inside = xs.partition_point(|&c| c <= x) % 2 == 1;
                    let s = match &near[i / TILE] {
                        None => BAND,
                        Some(c) => segs
                            .closest_among(c, DVec2::new(x, y), BAND)
                            .map_or(BAND, |h| h.dist),
                    };
                    *slot = (di + if inside { s } else { -s }) as f32;
                }
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The signed distance to a circle of radius `r` centred at (c, c), at
    /// the nodes of an n² lattice.
    fn disc(n: usize, c: f64, r: f64) -> Vec<f64> {
        (0..n * n)
            .map(|k| DVec2::new((k % n) as f64, (k / n) as f64).distance(DVec2::splat(c)) - r)
            .collect()
    }

    #[test]
    fn disc_isocurve_is_one_loop_near_the_circle() {
        let (w, h) = (41, 41);
        let loops = isocurves(&disc(w, 20.0, 12.0), w, h);
        assert_eq!(loops.len(), 1);
        for p in &loops[0] {
            assert!((p.distance(DVec2::splat(20.0)) - 12.0).abs() < 0.1, "{p}");
        }
        // Smoothing a circle barely moves it (twicing cancels the σ²/2r shrinkage).
        for p in smooth_loop(&loops[0], 3.0) {
            assert!((p.distance(DVec2::splat(20.0)) - 12.0).abs() < 0.15, "{p}");
        }
        let d: Vec<f64> = vec![0.0; w * h];
        let r = effective_reach(&loops, &d, w, h);
        assert!(r[20 * w + 20] > 11.5 && r[20 * w + 20] < 12.5);
        assert!(r[0] < 0.0);
    }

    #[test]
    fn effective_reach_is_the_clamped_signed_distance_at_every_node() {
        // A disc of radius 30 in an 81² lattice: nodes deep inside and
        // far outside (skipped tiles) and near the boundary.
        let (w, h) = (81, 81);
        let loops = isocurves(&disc(w, 40.0, 30.0), w, h);
        let d: Vec<f64> = (0..w * h).map(|k| (k % 7) as f64).collect();
        let r = effective_reach(&loops, &d, w, h);
        let mut a = Vec::new();
        let mut b = Vec::new();
        for lp in &loops {
            for k in 0..lp.len() {
                a.push(lp[k]);
                b.push(lp[(k + 1) % lp.len()]);
            }
        }
        let segs = Segments::new(a, b);
        for j in 0..h {
            for i in 0..w {
                let p = DVec2::new(i as f64, j as f64);
                let s = segs.closest(p, BAND).map_or(BAND, |h| h.dist);
                let inside = p.distance(DVec2::splat(40.0)) < 30.0;
                let want = (d[j * w + i] + if inside { s } else { -s }) as f32;
                assert_eq!(r[j * w + i].to_bits(), want.to_bits(), "({i}, {j})");
            }
        }
    }
}
