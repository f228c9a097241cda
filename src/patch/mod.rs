//! Sketch-driven patch synthesis (seeds 001 and 004): a ridge/valley sketch
//! becomes a terrain assembled from patches of many real DEMs.
//!
//! Pipeline ([`synthesize`]), one module per stage:
//! 1. [`sketch`] → signed field; [`ppa`] ridges and valleys on it (and, once
//!    per source, on every DEM: [`candidates::PreparedSource`]);
//! 2. [`graph`]: key nodes and paths; breadth-first patch centres along
//!    the sketch's features, control points on a circle of radius patch/4;
//! 3. [`candidates`] × [`costs`]: per user patch, round one scores every
//!    source feature node of the same kind and degree under 10 transforms
//!    (integer feature-profile + angle cost, data-parallel) and keeps the best
//!    5 per source; round two warps those by a thin-plate spline onto the
//!    sketch's control points and adds bending energy, SSD against what is
//!    already placed, noise-variance difference and a repetition penalty;
//!    the best 5 of that get a graph-cut seam cost, and the cheapest wins;
//! 4. [`merge`]: graph-cut seam ([`graphcut`]; finalists ranked by a
//!    half-resolution cut, the winner cut coarse to fine in bands),
//!    Shepard-interpolated gradient correction and a multigrid-preconditioned
//!    Poisson solve;
//! 5. [`fill`]: the rest, by priority order, from non-feature candidates
//!    under 6 transforms (integer SSD + noise on an 8× reduced grid through
//!    an explicit-SIMD kernel, then the same second round and merge);
//! 6. the broad drift of the merge is removed ([`remove_drift`]), the
//!    sketch's broad shape added ([`deform_by_sketch`]) and the lowest point
//!    put at the sources' typical lowest level.
//!
//! Sources are prepared once per [`Library`] and their features kept on
//! disk between processes ([`cache`]).
//!
//! Everything is deterministic: no randomness; parallel loops write
//! per-candidate results that are reduced in index order with ties broken
//! by index, so the bytes do not depend on the thread count.

pub mod cache;
pub mod candidates;
pub mod costs;
pub mod fill;
pub mod fill_cost;
pub mod graph;
pub mod graphcut;
pub mod merge;
pub mod ppa;
pub mod sketch;

use crate::Heightfield;
use crate::poisson::SolveOptions;
use crate::progress::Progress;
use candidates::{ACROSS, ALONG, FeatureNode, PreparedSource, UNIT};
use costs::{
    FEATURE_TRANSFORMS as FEATURE_TRANSFORMS_COUNT, Tps, feature_cost, noise_levels,
    transform_angle,
};
use graph::FeatureGraph;
use merge::{Canvas, Window};
use rayon::prelude::*;
use sketch::{Kind, Sketch};
use std::collections::BTreeMap;
use std::time::{Duration, Instant};
use thiserror::Error;

/// Why a synthesis could not run.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum PatchError {
    #[error("patch size {0} is invalid: expected a multiple of 8 in 16..=256")]
    PatchSize(usize),
    #[error(
        "output size {width}x{height} is invalid: each side must be at least the patch size {patch} and at most 16384"
    )]
    OutputSize {
        width: usize,
        height: usize,
        patch: usize,
    },
    #[error("no source DEM was given: at least one is needed")]
    NoSources,
    #[error(
        "source {name} is {width}x{height}: each side must be at least 2x the patch size {patch}"
    )]
    SourceSize {
        name: String,
        width: usize,
        height: usize,
        patch: usize,
    },
    #[error("source {name} was prepared for patch size {found}, not {expected}")]
    PreparedFor {
        name: String,
        found: usize,
        expected: usize,
    },
    #[error(transparent)]
    Backend(#[from] crate::backend::BackendError),
    #[error(transparent)]
    Other(#[from] crate::Error),
}

/// Weights of the second-round costs (all terms are made dimensionless
/// first; see [`select`]). Seed 001 uses λ_d = 1000, λ_g = 1, λ_f = 3 on
/// unnormalised terms; seed 004's values were lost. Ours were set by looking
/// at the terms' typical sizes on the shared DEMs so that none dominates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    pub feature: f64,
    pub deform: f64,
    pub ssd: f64,
    pub noise: f64,
    pub cut: f64,
    pub repeat: f64,
    /// Weight of the detail cost: `Σ_l ln((σ_c,l + 1 m) / (σ_ref,l + 1 m))²`
    /// between a candidate's wavelet noise levels and the library's
    /// typical ones ([`Library::noise_ref`]). Not in the seeds: with many
    /// sources of different character (plains next to alpine ranges), the
    /// relief-normalised profile costs cannot tell a faint ridge of a plain
    /// from a real one, and whole sketched features came out as smooth,
    /// detail-free bands (or single rough masses); this keeps every patch
    /// near the library's typical roughness. With one source it only
    /// prefers that source's typical patches.
    pub detail: f64,
    /// Weight of the noise cost against the SSD in the integer first round
    /// of hole filling.
    pub fill_noise: u64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            feature: 1.0,
            deform: 0.5,
            ssd: 1.0,
            noise: 0.5,
            cut: 0.5,
            repeat: 0.5,
            detail: 1.0,
            fill_noise: 4,
        }
    }
}

/// Synthesis parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Patch side in pixels (multiple of 8, 16..=256).
    pub patch: usize,
    /// PPA dip threshold on sources, as a fraction of their 2–98 % relief.
    pub source_dip: f32,
    /// Weakest source feature kept, as a fraction of relief.
    pub source_min_prominence: f32,
    /// At most this many feature nodes per kind and source (strongest kept).
    pub max_source_nodes: usize,
    /// Best-set size per source (seed 004 §6.3.1: 5).
    pub best_per_source: usize,
    /// Candidates that get a graph-cut cost (seed 004: 5).
    pub finalists: usize,
    /// Amplitude of the final sketch deformation, as a fraction of the
    /// synthesized relief (0 = off); see [`deform_by_sketch`].
    pub sketch_relief: f32,
    pub weights: Weights,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            patch: 64,
            source_dip: 0.02,
            source_min_prominence: 0.01,
            max_source_nodes: 2500,
            best_per_source: 5,
            finalists: 5,
            sketch_relief: 1.0,
            weights: Weights::default(),
        }
    }
}

impl Params {
    fn check(&self) -> Result<(), PatchError> {
        if !(16..=256).contains(&self.patch) || self.patch % 8 != 0 {
            return Err(PatchError::PatchSize(self.patch));
        }
        Ok(())
    }
}

/// Prepared sources, reusable across sketches (the cache of seed 004 §5.4).
#[derive(Debug, Clone)]
pub struct Library {
    pub sources: Vec<PreparedSource>,
    pub params: Params,
    /// The library's typical roughness: per wavelet level, the median
    /// noise statistic ([`costs::noise_levels`], decimetres) of every
    /// source's non-feature candidates; see [`Weights::detail`].
    pub noise_ref: [u32; 3],
}

impl Library {
    /// Prepares every source (features, candidates) once.
    pub fn prepare(
        sources: &[(String, Heightfield)],
        params: &Params,
        progress: &dyn Progress,
    ) -> Result<Library, PatchError> {
        Ok(Self::prepare_in(sources, params, None, progress)?.0)
    }

    /// [`Self::prepare`] through the disk cache in `dir` ([`cache`]): each
    /// source's features are read from there when an intact entry for the
    /// same DEM, parameters and code exists, and computed and stored
    /// otherwise. Returns the library and how many sources were read.
    pub fn prepare_cached(
        sources: &[(String, Heightfield)],
        params: &Params,
        dir: &std::path::Path,
        progress: &dyn Progress,
    ) -> Result<(Library, usize), PatchError> {
        Self::prepare_in(sources, params, Some(dir), progress)
    }

    fn prepare_in(
        sources: &[(String, Heightfield)],
        params: &Params,
        dir: Option<&std::path::Path>,
        progress: &dyn Progress,
    ) -> Result<(Library, usize), PatchError> {
        params.check()?;
        if sources.is_empty() {
            return Err(PatchError::NoSources);
        }
        for (name, hf) in sources {
            if hf.width() < 2 * params.patch || hf.height() < 2 * params.patch {
                return Err(PatchError::SourceSize {
                    name: name.clone(),
                    width: hf.width(),
                    height: hf.height(),
                    patch: params.patch,
                });
            }
        }
        // Sources are brought to one relief, the median of their 2–98 %
        // reliefs: patches of an alpine DEM and of a plain then sit side by
        // side as one style instead of a patchwork of scales (seed 004 mixes
        // sources without saying how; with our 8 DEMs spanning 345 m to
        // 2.7 km of relief the unscaled result is dominated by whichever
        // source the first patch came from).
        let reliefs: Vec<f32> = sources
            .iter()
            .map(|(_, hf)| candidates::relief(hf.data()).max(1.0))
            .collect();
        let mut sorted = reliefs.clone();
        sorted.sort_by(f32::total_cmp);
        let target = sorted[sorted.len() / 2];
        progress.start("preparing sources", sources.len() as u64);
        let mut out = Vec::with_capacity(sources.len());
        let mut hits = 0;
        for ((name, hf), rel) in sources.iter().zip(&reliefs) {
            let scale = target / rel;
            out.push(match dir {
                Some(d) => {
                    let (s, o) = cache::prepare(d, name, hf, params, scale)?;
                    hits += (o == cache::Outcome::Hit) as usize;
                    s
                }
                None => PreparedSource::prepare(name, hf, params, scale)?,
            });
            progress.advance(1);
        }
        progress.finish();
        let mut noise_ref = [0u32; 3];
        for (l, r) in noise_ref.iter_mut().enumerate() {
            let mut v: Vec<u32> = out
                .iter()
                .flat_map(|s| s.fill.iter().map(move |c| c.noise[l]))
                .collect();
            v.sort_unstable();
            *r = v.get(v.len() / 2).copied().unwrap_or(0);
        }
        Ok((
            Library {
                sources: out,
                params: *params,
                noise_ref,
            },
            hits,
        ))
    }
}

/// Wall time per stage.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timings {
    /// Sketch rasterisation, PPA and feature graph.
    pub sketch: Duration,
    /// Round one of feature candidates (integer, data-parallel).
    pub feature_round1: Duration,
    /// Round two: TPS warp, SSD, noise, graph-cut costs.
    pub feature_round2: Duration,
    /// Seams, Shepard and Poisson for feature patches.
    pub feature_merge: Duration,
    /// Priority and round one of hole filling.
    pub fill_round1: Duration,
    pub fill_round2: Duration,
    pub fill_merge: Duration,
    pub total: Duration,
}

/// Counts that describe a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    pub user_patches: usize,
    pub feature_patches: usize,
    pub fill_patches: usize,
    /// Candidates scored in round one (feature, fill).
    pub round1_feature: u64,
    pub round1_fill: u64,
    /// Worst relative residual of the Poisson solves.
    pub worst_residual: f64,
}

/// A finished synthesis.
#[derive(Debug, Clone)]
pub struct Synthesis {
    pub heightfield: Heightfield,
    pub ridges: FeatureGraph,
    pub valleys: FeatureGraph,
    pub timings: Timings,
    pub stats: Stats,
}

/// A user patch: where, what kind, and its description on the sketch.
#[derive(Debug, Clone)]
pub struct UserPatch {
    pub kind: Kind,
    pub node: FeatureNode,
}

/// The signed sketch field at output size, lightly blurred (three box passes
/// of radius patch/16) so that flat image strokes get a crest for PPA.
pub fn sketch_field(sketch: &Sketch, w: usize, h: usize, patch: usize) -> Vec<f32> {
    let mut f = sketch.raster(w, h);
    let r = (patch / 16).max(1);
    for _ in 0..3 {
        f = box_blur(&f, w, h, r);
    }
    f
}

fn box_blur(v: &[f32], w: usize, h: usize, r: usize) -> Vec<f32> {
    let pass = |src: &[f32], w: usize, h: usize| -> Vec<f32> {
        // Horizontal box of radius r with clamped ends, then transpose. Each
        // row's prefix sums (f64, so the differences stay exact enough) make
        // a box O(1) per pixel: the drift removal's radius of two patches
        // summed 257 samples per pixel and pass otherwise.
        let mut out = vec![0.0f32; w * h];
        let prefix: Vec<Vec<f64>> = src
            .par_chunks(w)
            .map(|row| {
                let mut p = Vec::with_capacity(w + 1);
                p.push(0.0f64);
                let mut acc = 0.0f64;
                for &v in row {
                    acc += v as f64;
                    p.push(acc);
                }
                p
            })
            .collect();
        out.par_chunks_mut(h).enumerate().for_each(|(x, col)| {
            let (lo, hi) = (x.saturating_sub(r), (x + r).min(w - 1));
            for (o, p) in col.iter_mut().zip(&prefix) {
                *o = ((p[hi + 1] - p[lo]) / (hi - lo + 1) as f64) as f32;
            }
        });
        out
    };
    let t = pass(v, w, h);
    pass(&t, h, w)
}

/// PPA parameters for the sketch field (values in `[-1, 1]`): a dip of 0.1,
/// profiles of patch/4, and side branches shorter than patch/2 removed —
/// longer than on DEMs because a thick stroke's junction is a small plateau
/// on which the spanning tree grows spurs up to a stroke width long, while
/// every intended sketch line is far longer than half a patch.
pub fn sketch_ppa_params(patch: usize) -> ppa::PpaParams {
    ppa::PpaParams {
        min_branch: patch as f32 / 2.0,
        passes: 8,
        ..candidates::ppa_params(patch, 1.0, 0.1)
    }
}

/// Junctions of the sketch closer than this (along their path) are one
/// (thick strokes meeting at a point give two or three close junctions).
pub fn sketch_merge_len(patch: usize) -> f32 {
    patch as f32 / 4.0
}

/// PPA and the feature graph of one kind on the sketch field.
pub fn sketch_graph(
    field: &[f32],
    w: usize,
    h: usize,
    patch: usize,
    kind: Kind,
) -> (ppa::Tree, FeatureGraph) {
    let f: Vec<f32> = match kind {
        Kind::Ridge => field.to_vec(),
        Kind::Valley => field.iter().map(|v| -v).collect(),
    };
    let tree = ppa::extract(w, h, &f, &sketch_ppa_params(patch));
    let g = FeatureGraph::from_tree(&tree, sketch_merge_len(patch));
    (tree, g)
}

/// The sketch's feature graphs and user patches, in placement order
/// (ridges, then valleys).
pub fn user_patches(
    field: &[f32],
    w: usize,
    h: usize,
    patch: usize,
) -> (FeatureGraph, FeatureGraph, Vec<UserPatch>) {
    let r = patch as f32 / 4.0;
    let neg: Vec<f32> = field.iter().map(|v| -v).collect();
    let mut out = Vec::new();
    let mut graphs = Vec::new();
    for (kind, f) in [(Kind::Ridge, field), (Kind::Valley, &neg[..])] {
        let (_, g) = sketch_graph(field, w, h, patch, kind);
        let idx = g.exit_index();
        for c in g.placements(patch as f32 / 2.0, patch as f32 / 4.0) {
            if let Some(node) = candidates::describe(f, w, h, c, &g.exits_in(&idx, c, r), r, 0.02) {
                out.push(UserPatch { kind, node });
            }
        }
        graphs.push(g);
    }
    let valleys = graphs.pop().expect("two graphs");
    let ridges = graphs.pop().expect("two graphs");
    (ridges, valleys, out)
}

/// Builds the warp of a feature candidate onto a user patch: a TPS from
/// output coordinates (relative to the user centre, in units of r) to
/// source coordinates, through the centres, the matched control points and
/// one extra point at distance r perpendicular to the first control
/// direction (mirrored with the candidate), which keeps the three points of
/// a straight path from being collinear. Returns the spline and its cost
/// `bending energy + stretch`.
pub fn feature_warp(
    user: &FeatureNode,
    cand: &FeatureNode,
    t: usize,
    shift: usize,
    r: f32,
) -> Option<(Tps, f64)> {
    let d = user.cps.len();
    let mirrored = transform_angle(0, t).1;
    let order = |j: usize| if mirrored { d - 1 - j } else { j };
    let (uc, sc) = (user.centre, cand.centre);
    let rr = r as f64;
    let rel = |p: [f32; 2], c: [f32; 2]| [(p[0] - c[0]) as f64 / rr, (p[1] - c[1]) as f64 / rr];
    let mut src = vec![[0.0, 0.0]];
    let mut dst = vec![[0.0, 0.0]];
    for (i, cu) in user.cps.iter().enumerate() {
        let cs = &cand.cps[order((i + shift) % d)];
        src.push(rel(cu.pos, uc));
        dst.push(rel(cs.pos, sc));
    }
    let unit = |v: [f64; 2]| {
        let l = (v[0] * v[0] + v[1] * v[1]).sqrt().max(1e-9);
        [v[0] / l, v[1] / l]
    };
    let du = unit(src[1]);
    let ds = unit(dst[1]);
    let sign = if mirrored { -1.0 } else { 1.0 };
    src.push([-du[1], du[0]]);
    dst.push([-ds[1] * sign, ds[0] * sign]);
    let tps = Tps::fit(&src, &dst)?;
    let cost = tps.bending_energy() + tps.stretch();
    Some((tps, cost))
}

/// Samples the warped candidate over window `win` (heights in metres);
/// `None` if any sample falls outside the source. The spline is evaluated
/// on an 8-pixel lattice and interpolated bilinearly in between.
pub fn sample_warped(
    src: &PreparedSource,
    tps: &Tps,
    user_centre: [f32; 2],
    cand_centre: [f32; 2],
    r: f32,
    win: Window,
) -> Option<Vec<f32>> {
    let n = win.n;
    let step = 8;
    let m = n / step + 1;
    let mut lat = vec![[0.0f32; 2]; m * m];
    for ly in 0..m {
        for lx in 0..m {
            let p = [
                (win.x0 + lx * step) as f32 + 0.5,
                (win.y0 + ly * step) as f32 + 0.5,
            ];
            let q = tps.map([
                ((p[0] - user_centre[0]) / r) as f64,
                ((p[1] - user_centre[1]) / r) as f64,
            ]);
            lat[ly * m + lx] = [
                cand_centre[0] + (q[0] * r as f64) as f32,
                cand_centre[1] + (q[1] * r as f64) as f32,
            ];
        }
    }
    let (w, h) = (src.width as f32, src.height as f32);
    let mut out = vec![0.0f32; n * n];
    for y in 0..n {
        let (ly, ty) = ((y / step).min(m - 2), (y % step) as f32 / step as f32);
        let ty = if y / step > m - 2 { 1.0 } else { ty };
        for x in 0..n {
            let (lx, tx) = ((x / step).min(m - 2), (x % step) as f32 / step as f32);
            let tx = if x / step > m - 2 { 1.0 } else { tx };
            let l = |i: usize, j: usize| lat[j * m + i];
            let mix = |a: [f32; 2], b: [f32; 2], t: f32| {
                [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
            };
            let top = mix(l(lx, ly), l(lx + 1, ly), tx);
            let bot = mix(l(lx, ly + 1), l(lx + 1, ly + 1), tx);
            let q = mix(top, bot, ty);
            if !(q[0] >= 0.5 && q[1] >= 0.5 && q[0] <= w - 0.5 && q[1] <= h - 0.5) {
                return None;
            }
            out[y * n + x] = candidates::sample(&src.heights, src.width, src.height, q);
        }
    }
    Some(out)
}

/// Removes the least-squares tilt (the `x` and `y` slopes of the best-fit
/// plane) from an `n × n` patch, keeping its mean. Gradient-domain merging
/// keeps every patch's slopes, so the regional tilt each patch brings from
/// its source (a ridge that runs downhill, a valley side) would add up from
/// patch to patch into a random walk of height across the output; the
/// broad shape is the sketch's to give ([`deform_by_sketch`]).
pub fn detrend(patch: &mut [f32], n: usize) {
    let c = (n as f64 - 1.0) / 2.0;
    let (mut sx, mut sy, mut sxx) = (0.0f64, 0.0f64, 0.0f64);
    for y in 0..n {
        for x in 0..n {
            let v = patch[y * n + x] as f64;
            sx += (x as f64 - c) * v;
            sy += (y as f64 - c) * v;
        }
    }
    for x in 0..n {
        sxx += (x as f64 - c).powi(2);
    }
    sxx *= n as f64;
    let (bx, by) = (sx / sxx, sy / sxx);
    for y in 0..n {
        for x in 0..n {
            patch[y * n + x] -= (bx * (x as f64 - c) + by * (y as f64 - c)) as f32;
        }
    }
}

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

/// Picks the winner among scored candidates: sort by cost (ties by key),
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
    synthesize_with(lib, sketch, w, h, &fill_cost::FillCost::Cpu, progress)
}

/// [`synthesize`] with stage `fill_ssd` on the backend `cost` (same bytes
/// on each; see [`fill_cost`]).
pub fn synthesize_with(
    lib: &Library,
    sketch: &Sketch,
    w: usize,
    h: usize,
    cost: &fill_cost::FillCost,
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
            if let Some(rep) = merge::apply(&mut canvas, win, &s.patch, &seam.take_new, &opts) {
                stats.worst_residual = stats.worst_residual.max(rep.relative_residual);
            }
            stats.feature_patches += 1;
            timings.feature_merge += t3.elapsed();
        }
        progress.advance(1);
    }
    progress.finish();
    fill::fill(
        lib,
        &mut canvas,
        &mut uses,
        (&mut timings, &mut stats),
        cost,
        progress,
    )?;
    remove_drift(&mut canvas.heights, w, h, n);
    deform_by_sketch(&mut canvas.heights, &field, w, h, n, params.sketch_relief);
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
    })
}

/// The sketch's height profile deforms the merged terrain (seed 004 §4.1:
/// Tasse et al. use the sketched height profile "to deform the terrain
/// after it has undergone merging and matching"): a broad version of the
/// sketch field (three box passes of radius patch/2, so it only moves whole
/// ridges and valleys, never the detail) scaled to `amount` × the
/// synthesized 2–98 % relief is added. Patches put ridges *where* the
/// sketch says; this makes them stand *higher* than their surroundings at
/// the scale of the whole terrain, which the gradient-domain merge alone
/// does not control.
pub fn deform_by_sketch(
    heights: &mut [f32],
    field: &[f32],
    w: usize,
    h: usize,
    patch: usize,
    amount: f32,
) {
    if amount <= 0.0 {
        return;
    }
    let mut broad = field.to_vec();
    for _ in 0..3 {
        broad = box_blur(&broad, w, h, (patch / 2).max(1));
    }
    let peak = broad.iter().fold(0.0f32, |m, v| m.max(v.abs()));
    if peak <= 0.0 {
        return;
    }
    let amp = candidates::relief(heights) * amount / peak;
    for (v, b) in heights.iter_mut().zip(&broad) {
        *v += amp * b;
    }
}

/// Removes what the merge adds at scales far above a patch: the broad
/// component (three box passes of radius 2·patch, about a Gaussian of
/// σ = 2·patch) minus its mean. Each gradient-domain merge keeps its
/// patch's slopes and only pins it to its neighbours along the seam, so
/// small slope residues (after [`detrend`]) add up along the placement
/// order into a random walk of height across the output: with many
/// sources, half of a sketched circle came out a kilometre above the other
/// half as one smooth snowy mass, and the λ inside it was lost in that
/// tilt. Ridges and valleys are narrower than this scale and stay; the
/// broad shape is the sketch's to give ([`deform_by_sketch`]).
pub fn remove_drift(heights: &mut [f32], w: usize, h: usize, patch: usize) {
    let mut broad = heights.to_vec();
    for _ in 0..3 {
        broad = box_blur(&broad, w, h, (2 * patch).max(1));
    }
    let mean = broad.iter().map(|&v| v as f64).sum::<f64>() / broad.len().max(1) as f64;
    for (v, b) in heights.iter_mut().zip(&broad) {
        *v -= b - mean as f32;
    }
}

/// The output's cell size: the median of the sources' (patches are copied
/// pixel for pixel, without resampling to a common cell size).
fn median_cell(lib: &Library) -> f64 {
    let mut c: Vec<f64> = lib.sources.iter().map(|s| s.cell_size).collect();
    c.sort_by(f64::total_cmp);
    c[c.len() / 2]
}

/// Feature adherence (issue 7): mean output height within `radius` of the
/// sketched ridge strokes minus that near the valley strokes, divided by the
/// output's relief (max − min). A sketch with only ridges (Zhou's λ) is
/// measured against the background instead: pixels farther than
/// `4 · radius` from every stroke. `None` without ridge strokes.
pub fn adherence(hf: &Heightfield, sketch: &Sketch, radius: f32) -> Option<f64> {
    let (w, h) = (hf.width(), hf.height());
    let stats = hf.stats()?;
    let relief = (stats.max - stats.min) as f64;
    let mean = |m: &[bool]| {
        let (s, k) = m
            .iter()
            .zip(hf.data())
            .filter(|(m, _)| **m)
            .fold((0.0f64, 0usize), |(s, k), (_, &v)| (s + v as f64, k + 1));
        if k == 0 { None } else { Some(s / k as f64) }
    };
    let ridge = mean(&sketch::stroke_mask(sketch, Kind::Ridge, w, h, radius))?;
    let low = match mean(&sketch::stroke_mask(sketch, Kind::Valley, w, h, radius)) {
        Some(v) => v,
        None => {
            let near = sketch::stroke_mask(sketch, Kind::Ridge, w, h, 4.0 * radius);
            let far: Vec<bool> = near.iter().map(|n| !n).collect();
            mean(&far)?
        }
    };
    Some((ridge - low) / relief.max(1e-9))
}
