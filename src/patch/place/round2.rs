//! Round two, shared by feature and fill candidates: the cost of a sampled
//! patch against what the canvas already holds, and the choice of the
//! winner among the finalists by their graph-cut seam cost.

use crate::patch::merge::graphcut;
use crate::patch::merge::{self, Canvas, Window};
use crate::patch::place::costs::{self, noise_levels};
use crate::patch::{Params, Weights};
use rayon::prelude::*;

/// Second-round scoring shared by feature and fill candidates.
pub(crate) struct Scored {
    pub cost: f64,
    pub patch: Vec<f32>,
    pub key: (usize, u8, u32),
}

/// What the canvas holds in a window: heights (dm), validity, and noise.
pub(crate) struct UserWindow {
    pub dm: Vec<i32>,
    pub valid: Vec<bool>,
    pub noise: [u32; 3],
    pub overlap: usize,
    pub var_m2: f64,
}

pub(crate) fn user_window(c: &Canvas, win: Window) -> UserWindow {
    let n = win.n;
    let mut dm = vec![0i32; n * n];
    let mut valid = vec![false; n * n];
    let (mut s, mut s2, mut k) = (0.0f64, 0.0f64, 0usize);
    for y in 0..n {
        for x in 0..n {
            let i = (win.y0 + y) * c.width + win.x0 + x;
            if c.filled[i] {
                let v = c.heights[i];
                dm[y * n + x] = (v * 10.0).round() as i32;
                valid[y * n + x] = true;
                s += v as f64;
                s2 += (v as f64) * (v as f64);
                k += 1;
            }
        }
    }
    let var = if k > 0 {
        (s2 / k as f64 - (s / k as f64).powi(2)).max(0.0)
    } else {
        0.0
    };
    UserWindow {
        noise: noise_levels(n, &dm, &valid),
        dm,
        valid,
        overlap: k,
        var_m2: var,
    }
}

/// Round-two cost of a sampled candidate patch against the canvas window:
/// `w_ssd · SSD_dc / (σ²_user + σ²_cand + 1 m²) + w_noise · Σ(σu − σc)² /
/// (Σσu² + Σσc² + 1 m²) + w_repeat · uses + w_detail · detail` (SSD and
/// noise only where something is placed; variances over the overlap;
/// detail as at [`Weights::detail`]). Normalising the SSD by
/// both variances (not the user's alone) keeps a smooth neighbourhood from
/// admitting only smooth patches, which otherwise chains into long
/// featureless bands.
pub(crate) fn round2_cost(
    u: &UserWindow,
    patch: &[f32],
    weights: &Weights,
    noise_ref: &[u32; 3],
    uses: u32,
) -> f64 {
    let pdm: Vec<i32> = patch.iter().map(|v| (v * 10.0).round() as i32).collect();
    let all = vec![true; patch.len()];
    let cn = noise_levels(u.dm.len().isqrt(), &pdm, &all);
    let detail: f64 = cn
        .iter()
        .zip(noise_ref)
        .map(|(&c, &r)| ((c as f64 + 10.0) / (r as f64 + 10.0)).ln().powi(2))
        .sum();
    let mut cost = weights.repeat * uses as f64 + weights.detail * detail;
    if u.overlap == 0 {
        return cost;
    }
    let (ssd, _) = costs::ssd_dc(&u.dm, &pdm, &u.valid);
    let (mut s, mut s2) = (0.0f64, 0.0f64);
    for (&v, &ok) in patch.iter().zip(&u.valid) {
        if ok {
            s += v as f64;
            s2 += (v as f64) * (v as f64);
        }
    }
    let k = u.overlap as f64;
    let var_c = (s2 / k - (s / k).powi(2)).max(0.0);
    cost += weights.ssd * (ssd as f64 / 100.0) / (u.var_m2 + var_c + 1.0);
    let num = costs::noise_cost(&u.noise, &cn) as f64;
    let den: f64 = u
        .noise
        .iter()
        .chain(cn.iter())
        .map(|&s| (s as f64).powi(2))
        .sum::<f64>()
        + 100.0;
    cost + weights.noise * num / den
}

/// Picks the winner among scored candidates: add the coherence cost
/// ([`Weights::coherence`]), sort by cost (ties by key),
/// add the graph-cut cost for the best `finalists` (estimated at half
/// resolution, [`merge::seam_coarse`]), take the minimum (ties by rank),
/// and cut the winner at full resolution in a band around its half-
/// resolution seam ([`merge::seam_banded`]). Returns the winning patch
/// (offset to the overlap) and its seam.
pub(crate) fn select(
    c: &Canvas,
    win: Window,
    mut scored: Vec<Scored>,
    core: Option<&[bool]>,
    params: &Params,
) -> Option<(Scored, graphcut::Seam)> {
    let coherence = coherence_costs(c, win);
    for s in &mut scored {
        s.cost += params.weights.coherence * coherence(s.key.0);
    }
    scored.sort_by(|a, b| a.cost.total_cmp(&b.cost).then(a.key.cmp(&b.key)));
    scored.truncate(params.finalists.max(1));
    let n = win.n as f64;
    // A patch that overlaps nothing (the first of a sketch component) is
    // put at the mean level of what is placed so far, not at its source's
    // absolute level: otherwise separate components (Zhou's λ inside its
    // circle) start hundreds of metres apart and the fill between them
    // turns that into basins and plateaus the sketch never asked for.
    let overlaps =
        (0..win.n * win.n).any(|i| c.filled[(win.y0 + i / win.n) * c.width + win.x0 + i % win.n]);
    let level = if overlaps {
        None
    } else {
        let (s, k) = c
            .heights
            .iter()
            .zip(&c.filled)
            .filter(|(_, f)| **f)
            .fold((0.0f64, 0usize), |(s, k), (&v, _)| (s + v as f64, k + 1));
        (k > 0).then(|| s / k as f64)
    };
    let results: Vec<(f64, Vec<f32>, graphcut::Seam)> = scored
        .par_iter()
        .map(|s| {
            let off = match level {
                Some(l) => {
                    let m = s.patch.iter().map(|&v| v as f64).sum::<f64>() / s.patch.len() as f64;
                    (l - m) as f32
                }
                None => merge::offset(c, win, &s.patch),
            };
            let p: Vec<f32> = s.patch.iter().map(|v| v + off).collect();
            let coarse = merge::seam_coarse(c, win, &p, core);
            let cut = coarse.cost as f64 / 256.0 / n;
            (s.cost + params.weights.cut * cut, p, coarse)
        })
        .collect();
    let best = (0..results.len()).min_by(|&a, &b| results[a].0.total_cmp(&results[b].0))?;
    let (_, p, coarse) = results.into_iter().nth(best)?;
    let seam = merge::seam_banded(c, win, &p, core, &coarse);
    let mut win_s = scored.swap_remove(best);
    win_s.patch = p;
    Some((win_s, seam))
}

/// The coherence cost of a candidate from each source in `win`: the share
/// of the already placed pixels of the window that came from another
/// source (0 where nothing is placed). See [`Weights::coherence`].
fn coherence_costs(c: &Canvas, win: Window) -> impl Fn(usize) -> f64 {
    let mut counts: Vec<(u32, usize)> = Vec::new();
    let mut placed = 0usize;
    for y in 0..win.n {
        let row = (win.y0 + y) * c.width + win.x0;
        for &s in &c.source[row..row + win.n] {
            if s == Canvas::NO_SOURCE {
                continue;
            }
            placed += 1;
            match counts.iter_mut().find(|(k, _)| *k == s) {
                Some((_, n)) => *n += 1,
                None => counts.push((s, 1)),
            }
        }
    }
    move |source: usize| {
        if placed == 0 {
            return 0.0;
        }
        let same = counts
            .iter()
            .find(|(k, _)| *k as usize == source)
            .map_or(0, |(_, n)| *n);
        1.0 - same as f64 / placed as f64
    }
}
