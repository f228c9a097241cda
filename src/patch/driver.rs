//! The driver ([`synthesize`]): checks the request, places the feature
//! patches (round one, round two, merge), hands the rest to hole filling,
//! and gives the result its broad shape and level.

use super::fill::{fill_ssd, hole_fill};
use super::input::control_point::{ACROSS, ALONG, UNIT};
use super::input::graph;
use super::input::sketch::{Kind, Sketch};
use super::merge::{self, Canvas, Window, join_pits};
use super::place::costs::{FEATURE_TRANSFORMS as FEATURE_TRANSFORMS_COUNT, feature_cost};
use super::{
    Library, PatchError, Scored, Stats, Synthesis, Timings, deform_by_sketch, detrend,
    feature_warp, remove_drift, round2_cost, sample_warped, select, sketch_field, user_patches,
    user_window,
};
use crate::Heightfield;
use crate::poisson::SolveOptions;
use crate::progress::Progress;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::time::Instant;

pub(crate) fn solve_opts() -> SolveOptions {
    SolveOptions {
        tolerance: 1e-5,
        max_iterations: 2000,
    }
}

/// Synthesizes a `w × h` terrain for `sketch` from the library's sources.
pub fn synthesize(
    lib: &Library,
    sketch: &Sketch,
    w: usize,
    h: usize,
    progress: &dyn Progress,
) -> Result<Synthesis, PatchError> {
    synthesize_with(lib, sketch, w, h, &fill_ssd::FillCost::Cpu, progress)
}

/// [`synthesize`] with stage `fill_ssd` on the backend `cost` (same bytes
/// on each; see [`fill_ssd`]).
pub fn synthesize_with(
    lib: &Library,
    sketch: &Sketch,
    w: usize,
    h: usize,
    cost: &fill_ssd::FillCost,
    progress: &dyn Progress,
) -> Result<Synthesis, PatchError> {
    let params = &lib.params;
    params.check()?;
    let n = params.patch;
    if w < n || h < n || w > 16384 || h > 16384 {
        return Err(PatchError::OutputSize {
            width: w,
            height: h,
            patch: n,
        });
    }
    for s in &lib.sources {
        if s.patch != n {
            return Err(PatchError::PreparedFor {
                name: s.name.clone(),
                found: s.patch,
                expected: n,
            });
        }
    }
    let t_all = Instant::now();
    let mut timings = Timings::default();
    let mut stats = Stats::default();
    let t0 = Instant::now();
    let field = sketch_field(sketch, w, h, n);
    let (ridges, valleys, users) = user_patches(&field, w, h, n);
    timings.sketch = t0.elapsed();
    stats.user_patches = users.len();
    let mut canvas = Canvas::new(w, h);
    let mut uses: BTreeMap<(usize, u8, u32), u32> = BTreeMap::new();
    let r = n as f32 / 4.0;
    let opts = solve_opts();
    progress.start("feature patches", users.len() as u64);
    for up in &users {
        let d = up.node.cps.len();
        let kind_tag = match up.kind {
            Kind::Ridge => 0u8,
            Kind::Valley => 1u8,
        };
        // Round one: integer feature costs, best set per source.
        let t1 = Instant::now();
        let mut best: Vec<(usize, u32, u32, u8, u8)> = Vec::new(); // (src, node, cost, t, shift)
        for (si, src) in lib.sources.iter().enumerate() {
            let nodes = src.nodes(up.kind);
            let mut scored: Vec<(u32, u32, u8, u8)> = nodes
                .par_iter()
                .enumerate()
                .filter(|(_, c)| c.cps.len() == d)
                .map(|(k, c)| {
                    let mut b = (u32::MAX, 0u8, 0u8);
                    for t in 0..FEATURE_TRANSFORMS_COUNT {
                        let (cost, s) = feature_cost(&up.node.cps, &c.cps, t);
                        if cost < b.0 {
                            b = (cost, t as u8, s as u8);
                        }
                    }
                    (b.0, k as u32, b.1, b.2)
                })
                .collect();
            stats.round1_feature += scored.len() as u64 * FEATURE_TRANSFORMS_COUNT as u64;
            scored.sort_unstable();
            for &(cost, k, t, s) in scored.iter().take(params.best_per_source) {
                best.push((si, k, cost, t, s));
            }
        }
        timings.feature_round1 += t1.elapsed();
        if best.is_empty() {
            progress.advance(1);
            continue;
        }
        // Round two.
        let t2 = Instant::now();
        let win = Window::around(up.node.centre[0], up.node.centre[1], n, w, h);
        let uw = user_window(&canvas, win);
        let scored: Vec<Scored> = best
            .par_iter()
            .filter_map(|&(si, k, c1, t, s)| {
                let src = &lib.sources[si];
                let cand = &src.nodes(up.kind)[k as usize];
                let (tps, deform) = feature_warp(&up.node, cand, t as usize, s as usize, r)?;
                let mut patch = sample_warped(src, &tps, up.node.centre, cand.centre, r, win)?;
                detrend(&mut patch, n);
                let key = (si, kind_tag, k);
                let u = uses.get(&key).copied().unwrap_or(0);
                let feat = c1 as f64 / (d * (ALONG + ACROSS)) as f64 / (UNIT as f64 * UNIT as f64);
                let cost = params.weights.feature * feat
                    + params.weights.deform * deform
                    + round2_cost(&uw, &patch, &params.weights, &lib.noise_ref, u);
                Some(Scored { cost, patch, key })
            })
            .collect();
        let core: Vec<bool> = (0..n * n)
            .map(|i| {
                let (x, y) = ((win.x0 + i % n) as f32 + 0.5, (win.y0 + i / n) as f32 + 0.5);
                graph::dist([x, y], up.node.centre) <= n as f32 / 8.0
            })
            .collect();
        let chosen = select(&canvas, win, scored, Some(&core), params);
        timings.feature_round2 += t2.elapsed();
        if let Some((s, seam)) = chosen {
            let t3 = Instant::now();
            *uses.entry(s.key).or_insert(0) += 1;
            if let Some(rep) = merge::apply(
                &mut canvas,
                win,
                (&s.patch, s.key.0 as u32),
                &seam.take_new,
                &opts,
            ) {
                stats.worst_residual = stats.worst_residual.max(rep.relative_residual);
            }
            stats.feature_patches += 1;
            timings.feature_merge += t3.elapsed();
        }
        progress.advance(1);
    }
    progress.finish();
    hole_fill::fill(
        lib,
        &mut canvas,
        &mut uses,
        (&mut timings, &mut stats),
        cost,
        progress,
    )?;
    remove_drift(&mut canvas.heights, w, h, n);
    deform_by_sketch(&mut canvas.heights, &field, w, h, n, params.sketch_relief);
    stats.join_pits = join_pits::repair(&mut canvas.heights, &canvas.placement, w, h);
    // The merge fixes heights only up to a constant: put the lowest point
    // at the sources' typical lowest level (the median of their minima), so
    // that the output is not partly below sea level for no reason (the
    // renderer, like most tools, draws heights ≤ 0 as water).
    let mut lows: Vec<f32> = lib
        .sources
        .iter()
        .map(|s| s.heights.iter().copied().fold(f32::INFINITY, f32::min))
        .collect();
    lows.sort_by(f32::total_cmp);
    let low = canvas.heights.iter().copied().fold(f32::INFINITY, f32::min);
    let shift = lows[lows.len() / 2] - low;
    canvas.heights.iter_mut().for_each(|v| *v += shift);
    let cell = median_cell(lib);
    let hf = Heightfield::from_vec(w, h, cell, canvas.heights).map_err(crate::Error::from)?;
    timings.total = t_all.elapsed();
    Ok(Synthesis {
        heightfield: hf,
        ridges,
        valleys,
        timings,
        stats,
        sources: canvas.source,
    })
}

/// The output's cell size: the median of the sources' (patches are copied
/// pixel for pixel; the library has brought the sources to one cell size
/// within 1 %).
fn median_cell(lib: &Library) -> f64 {
    let mut c: Vec<f64> = lib.sources.iter().map(|s| s.cell_size).collect();
    c.sort_by(f64::total_cmp);
    c[c.len() / 2]
}
