//! The similarity table's second column, C₂ (paper §4): for every texel of a
//! level, the best *other* 5×5 neighbourhood among all exemplars of that
//! level, found with PatchMatch (Barnes et al. 2009), multi-threaded.
//!
//! Distance: the Gaussian-weighted SSD of mean-removed 5×5 neighbourhoods,
//! i.e. `‖y_u − y_v‖²` of the residual vectors of [`super::appearance`]. It is
//! offset-invariant on purpose: synthesis matches *relative* height (eq. 7
//! optimises a height offset), so a good alternative is one with the same
//! shape at any altitude.
//!
//! Excluded: targets within [`EXCLUSION`] texels (Chebyshev) of the source in
//! the same exemplar — their windows overlap the source's, so they would be
//! "matches" that add no variety (the coherent candidate C₁ and its ±1
//! shifts already cover them) — and targets within [`MARGIN`] of an edge.
//!
//! Determinism for any thread count: iterations alternate row sweeps and
//! column sweeps. A sweep walks its line sequentially (propagating along it,
//! alternating direction), reads the other axis' neighbours from the
//! *previous* iteration's table, and draws its random samples from a
//! stateless hash of (seed, level, texel, iteration, step). Lines are
//! independent, so rayon may run them in any order.

use super::appearance::FEATURE_LANES;
use super::kdtree::{KdTree, Key};
use super::layout::{LevelLayout, MARGIN, pack, unpack};
use crate::hash::{below, hash4};
use rayon::prelude::*;
use wide::i16x16;

/// Chebyshev radius (texels) of the trivial-match exclusion zone: 5 makes
/// the source's and target's 5×5 windows disjoint.
pub const EXCLUSION: u32 = 5;

/// Rows per scanline band: bands run in parallel, so the band layout (not
/// the thread count) fixes the result.
const BAND: u32 = 32;
/// Seed candidates per texel that get a full distance evaluation.
const SHORTLIST: usize = 8;

/// One residual feature (25 lanes used, zero-padded).
pub type Feature = [i16; FEATURE_LANES];

/// Exact squared distance of two features, in 16-bit SIMD: components are
/// within ±8191 (`appearance::FEATURE_MAX`), so differences fit i16, each
/// multiply-add lane (d₀² + d₁² ≤ 2·16382²) fits i32, two of them still do,
/// and only the final 8-lane sum needs 64 bits.
#[inline(always)]
pub fn distance(a: &Feature, b: &Feature) -> u64 {
    let lo = i16x16::new(a[..16].try_into().expect("16 lanes"))
        - i16x16::new(b[..16].try_into().expect("16 lanes"));
    let hi = i16x16::new(a[16..].try_into().expect("16 lanes"))
        - i16x16::new(b[16..].try_into().expect("16 lanes"));
    let s = lo.dot(lo) + hi.dot(hi);
    s.to_array().iter().map(|&v| v as u32 as u64).sum()
}

/// PatchMatch settings.
#[derive(Debug, Clone, Copy)]
pub struct Params {
    /// Alternating row/column sweeps.
    pub iterations: u32,
    /// Random initial guesses per texel (the best is kept).
    pub initial_samples: u32,
    /// Leaves of the PCA-space tree visited per texel to seed the search.
    pub search_leaves: usize,
    pub seed: u32,
    pub level: u32,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            iterations: 2,
            initial_samples: 2,
            search_leaves: 4,
            seed: 0x7e55,
            level: 0,
        }
    }
}

/// Static facts about the level that every evaluation needs.
struct Ctx<'a> {
    layout: &'a LevelLayout,
    columns: Vec<u8>,
    features: &'a [Feature],
    /// Cumulative interior texel counts, for uniform global sampling.
    cumulative: Vec<u64>,
}

impl Ctx<'_> {
    /// Distance from source texel `k` (exemplar `e`, at `ux, uy`) to target
    /// `v`, or `None` if `v` is not an admissible target.
    #[inline(always)]
    fn eval(&self, k: usize, e: usize, ux: u32, uy: u32, vx: i64, vy: i64) -> Option<u64> {
        if vx < 0 || vy < 0 || vx >= self.layout.atlas_width as i64 {
            return None;
        }
        let (vx, vy) = (vx as u32, vy as u32);
        let ve = self.layout.exemplar_at(&self.columns, vx, vy)?;
        let r = &self.layout.rects[ve];
        if !r.is_interior(vx, vy) {
            return None;
        }
        if ve == e && vx.abs_diff(ux) < EXCLUSION && vy.abs_diff(uy) < EXCLUSION {
            return None;
        }
        Some(distance(&self.features[k], &self.features[r.index(vx, vy)]))
    }

    /// A uniformly random interior texel of the whole level.
    fn random_target(&self, h: u32) -> (u32, u32) {
        let total = *self.cumulative.last().expect("at least one exemplar");
        // Two hashes give a 64-bit draw so huge atlases stay uniform.
        let r = ((h as u64) << 32 | crate::hash::pcg(h) as u64) % total;
        let e = self.cumulative.partition_point(|&c| c <= r);
        let before = if e == 0 { 0 } else { self.cumulative[e - 1] };
        let rect = &self.layout.rects[e];
        let iw = (rect.width - 2 * MARGIN) as u64;
        let local = r - before;
        (
            rect.x0 + MARGIN + (local % iw) as u32,
            MARGIN + (local / iw) as u32,
        )
    }
}

/// Runs PatchMatch over one level. Returns C₂ (packed coordinates) and the
/// squared feature distance of each match. Every exemplar must have an interior large enough
/// to hold an admissible target for each of its texels (the builder ensures
/// exemplars are at least 16×16 at the coarsest level).
pub fn similar(
    layout: &LevelLayout,
    features: &[Feature],
    keys: &[Key],
    params: Params,
) -> (Vec<u32>, Vec<u64>) {
    let cumulative: Vec<u64> = layout
        .rects
        .iter()
        .scan(0u64, |acc, r| {
            *acc += (r.width - 2 * MARGIN) as u64 * (r.height - 2 * MARGIN) as u64;
            Some(*acc)
        })
        .collect();
    let ctx = Ctx {
        layout,
        columns: layout.column_table(),
        features,
        cumulative,
    };
    let n = features.len();
    // Texel → (exemplar, x, y), computed once.
    let owner: Vec<(u8, u32, u32)> = layout
        .rects
        .iter()
        .enumerate()
        .flat_map(|(e, r)| (0..r.texels()).map(move |k| (e as u8, r.coords(r.offset + k))))
        .map(|(e, (x, y))| (e, x, y))
        .collect();

    // Initialisation: the admissible texels of the nearest leaves in the
    // PCA search space (see `kdtree`), plus a few uniformly random ones.
    let tree = KdTree::build(keys, |k| {
        let (e, x, y) = owner[k];
        layout.rects[e as usize]
            .is_interior(x, y)
            .then(|| pack(x, y))
    });
    let (mut nnf, mut dist): (Vec<u32>, Vec<u64>) = (0..n)
        .into_par_iter()
        .map(|k| {
            let (e, ux, uy) = owner[k];
            let mut best = (u32::MAX, u64::MAX);
            let consider = |vx: u32, vy: u32, best: &mut (u32, u64)| {
                if let Some(d) = ctx.eval(k, e as usize, ux, uy, vx as i64, vy as i64)
                    && d < best.1
                {
                    *best = (pack(vx, vy), d);
                }
            };
            // Rank the visited points by key distance (contiguous, cheap)
            // and pay for full distances (random access) on the best few.
            let mut shortlist = [(f32::INFINITY, u32::MAX); SHORTLIST];
            tree.query(&keys[k], params.search_leaves, |c, kd| {
                if kd < shortlist[SHORTLIST - 1].0 {
                    let mut i = SHORTLIST - 1;
                    while i > 0 && shortlist[i - 1].0 > kd {
                        shortlist[i] = shortlist[i - 1];
                        i -= 1;
                    }
                    shortlist[i] = (kd, c);
                }
            });
            for &(_, c) in shortlist.iter().filter(|s| s.1 != u32::MAX) {
                let (vx, vy) = unpack(c);
                consider(vx, vy, &mut best);
            }
            let mut s = 0;
            while s < params.initial_samples || best.0 == u32::MAX {
                let (vx, vy) =
                    ctx.random_target(hash4(params.seed, params.level, k as u32, 0x1000 + s));
                consider(vx, vy, &mut best);
                s += 1;
                assert!(
                    s < 10_000,
                    "no admissible target: exemplar interior too small"
                );
            }
            best
        })
        .unzip();

    let search_radius = layout.atlas_width.max(layout.atlas_height) as i64;
    // Bands of BAND rows per exemplar: scanline PatchMatch inside a band,
    // previous-iteration values across band boundaries.
    let bands: Vec<(usize, u32)> = layout
        .rects
        .iter()
        .enumerate()
        .flat_map(|(e, r)| (0..r.height.div_ceil(BAND)).map(move |b| (e, b * BAND)))
        .collect();
    for it in 0..params.iterations {
        let forward = it % 2 == 0;
        let results: Vec<(usize, Vec<u32>, Vec<u64>)> = bands
            .par_iter()
            .map(|&(e, y0)| {
                let r = &layout.rects[e];
                let y1 = (y0 + BAND).min(r.height);
                let w = r.width;
                let base = r.index(r.x0, y0);
                let len = ((y1 - y0) * w) as usize;
                let mut bn = nnf[base..base + len].to_vec();
                let mut bd = dist[base..base + len].to_vec();
                let sgn: i64 = if forward { 1 } else { -1 };
                for step in 0..len {
                    let local = if forward { step } else { len - 1 - step };
                    let (lx, ly) = (local as u32 % w, y0 + local as u32 / w);
                    let (ux, uy) = (r.x0 + lx, ly);
                    let k = base + local;
                    let (mut bv, mut best) = (bn[local], bd[local]);
                    let try_target = |vx: i64, vy: i64, bv: &mut u32, best: &mut u64| {
                        if let Some(d) = ctx.eval(k, e, ux, uy, vx, vy)
                            && d < *best
                        {
                            *bv = pack(vx as u32, vy as u32);
                            *best = d;
                        }
                    };
                    // Propagation from the already-visited horizontal and
                    // vertical neighbours (this pass inside the band, the
                    // previous table across its edge).
                    let nx = lx as i64 - sgn;
                    if nx >= 0 && nx < w as i64 {
                        let (px, py) = unpack(bn[local - 1 + (1 - sgn) as usize]);
                        try_target(px as i64 + sgn, py as i64, &mut bv, &mut best);
                    }
                    let ny = ly as i64 - sgn;
                    if ny >= 0 && ny < r.height as i64 {
                        let c = if ny >= y0 as i64 && ny < y1 as i64 {
                            bn[(local as i64 - sgn * w as i64) as usize]
                        } else {
                            nnf[r.index(ux, ny as u32)]
                        };
                        let (px, py) = unpack(c);
                        try_target(px as i64, py as i64 + sgn, &mut bv, &mut best);
                    }
                    // Forward enrichment (Barnes et al. 2010): similarity
                    // is roughly transitive, and terrain's nearest-neighbour
                    // fields are not coherent enough for propagation alone.
                    let (cx, cy) = unpack(bv);
                    let ce = ctx
                        .layout
                        .exemplar_at(&ctx.columns, cx, cy)
                        .expect("admissible");
                    let (px, py) = unpack(nnf[layout.rects[ce].index(cx, cy)]);
                    try_target(px as i64, py as i64, &mut bv, &mut best);
                    // Random search around the current best, radius halving.
                    let mut radius = search_radius;
                    let mut step_no = 0u32;
                    while radius >= 1 {
                        let seed = params.seed ^ it.wrapping_mul(0x9E37_79B9);
                        let h = hash4(seed, params.level, k as u32, step_no);
                        let span = (2 * radius + 1) as u32;
                        let (cx, cy) = unpack(bv);
                        let vx = cx as i64 + below(h, span) as i64 - radius;
                        let vy = cy as i64 + below(crate::hash::pcg(h), span) as i64 - radius;
                        try_target(vx, vy, &mut bv, &mut best);
                        step_no += 1;
                        radius /= 2;
                    }
                    // A global sample keeps other exemplars in reach.
                    let g = hash4(params.seed, params.level, k as u32, 0x8000_0000 | it);
                    let (gx, gy) = ctx.random_target(g);
                    try_target(gx as i64, gy as i64, &mut bv, &mut best);
                    bn[local] = bv;
                    bd[local] = best;
                }
                (base, bn, bd)
            })
            .collect();
        for (base, bn, bd) in results {
            nnf[base..base + bn.len()].copy_from_slice(&bn);
            dist[base..base + bd.len()].copy_from_slice(&bd);
        }
    }
    (nnf, dist)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::database::appearance;
    use crate::database::layout::plan;
    use crate::database::pyramid::{Grid, Quantization};

    /// Terrain-like test exemplar: ridges at several scales plus hashed noise.
    fn exemplar(w: usize, h: usize, seed: u32) -> Grid {
        let data = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32, (i / w) as f32);
                let n = (crate::hash::hash4(seed, x as u32, y as u32, 0) % 1000) as f32 / 1000.0;
                200.0 * (x * 0.07 + (y * 0.05).sin()).sin().abs()
                    + 60.0 * ((x + 2.0 * y) * 0.19).cos()
                    + 15.0 * (x * 0.41 - y * 0.37).sin()
                    + 4.0 * n
            })
            .collect();
        Grid {
            width: w,
            height: h,
            data,
        }
    }

    fn project(g: &Grid) -> appearance::Projected {
        let q = Quantization::spanning(-300.0, 4000.0);
        appearance::project(&[g], &q, &appearance::pca(&[g], &q))
    }

    /// A 128² crop of a real DEM when ../shared is present, else synthetic.
    fn exemplar_128() -> Grid {
        match crate::shared_dem("pyrenees_andorra.png") {
            Some(p) => Grid {
                width: 128,
                height: 128,
                data: crate::io::read(&p, &Default::default())
                    .unwrap()
                    .crop(300, 300, 128, 128)
                    .unwrap()
                    .into_vec(),
            },
            None => exemplar(128, 128, 7),
        }
    }

    #[test]
    fn matches_are_admissible_and_close_to_exhaustive() {
        let g = exemplar_128();
        let p = project(&g);
        let feats = &p.features;
        let layout = &plan(&[(128, 128)], 0).unwrap()[0];
        let (nnf, dist) = similar(layout, feats, &p.keys, Params::default());
        let r = layout.rects[0];
        for (k, &c) in nnf.iter().enumerate() {
            let (vx, vy) = unpack(c);
            let (ux, uy) = r.coords(k as u64);
            assert!(r.is_interior(vx, vy), "C2 on an edge");
            assert!(
                vx.abs_diff(ux) >= EXCLUSION || vy.abs_diff(uy) >= EXCLUSION,
                "trivial match"
            );
            assert_eq!(dist[k], distance(&feats[k], &feats[r.index(vx, vy)]));
        }
        // Exhaustive search on a fixed sample of sources.
        let (mut pm, mut ex) = (0.0f64, 0.0f64);
        for k in (0..feats.len()).step_by(7) {
            let (ux, uy) = r.coords(k as u64);
            let mut best = u64::MAX;
            for vy in MARGIN..r.height - MARGIN {
                for vx in MARGIN..r.width - MARGIN {
                    if vx.abs_diff(ux) < EXCLUSION && vy.abs_diff(uy) < EXCLUSION {
                        continue;
                    }
                    best = best.min(distance(&feats[k], &feats[r.index(vx, vy)]));
                }
            }
            pm += (dist[k] as f64).sqrt();
            ex += (best as f64).sqrt();
        }
        let ratio = pm / ex;
        eprintln!("PatchMatch / exhaustive mean neighbourhood distance: {ratio:.4}");
        assert!(
            ratio <= 1.10,
            "PatchMatch is {ratio:.3}x the exhaustive distance"
        );
    }

    #[test]
    fn independent_of_thread_count() {
        let g = exemplar(96, 80, 3);
        let p = project(&g);
        let layout = &plan(&[(96, 80)], 0).unwrap()[0];
        let run = |t| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(t)
                .build()
                .unwrap()
                .install(|| similar(layout, &p.features, &p.keys, Params::default()).0)
        };
        assert_eq!(run(1), run(2));
    }
}
