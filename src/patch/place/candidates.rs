//! Sources and their candidates (seed 004 §4.2, §5.4, §6.1).
//!
//! A [`PreparedSource`] holds everything synthesis needs from one DEM:
//! ridge and valley feature nodes with control points and profiles, the
//! grid of non-feature candidates with their noise statistics, and a
//! 8×-reduced integer copy for the first round of hole-filling costs.
//! Preparing is the expensive part (PPA on the whole DEM); it is done once
//! per source and the value is kept by the caller — the [`crate::patch::Library`]
//! caches it in memory for as many sketches as are synthesized with it
//! (the bench and the CLI synthesize several sketches from one library),
//! and, as seed 004 §5.4 does, the expensive part ([`Features`]) is kept
//! on disk between processes by [`crate::patch::input::cache`] (about a second per 800²
//! source on 2 cores to compute, milliseconds to read).

use crate::patch::Params;
use crate::patch::input::control_point::{ACROSS, ALONG, Cp, TURN, UNIT};
use crate::patch::input::graph::{FeatureGraph, dist, point_at};
use crate::patch::input::ppa::{self, PpaParams};
use crate::patch::input::sketch::Kind;
use crate::patch::place::costs::noise_levels;
use crate::resample::bilinear;
use crate::stages::fill_ssd::centre_cells;
use rayon::prelude::*;

/// A feature patch centre with its control points (sorted by angle).
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureNode {
    pub centre: [f32; 2],
    pub cps: Vec<Cp>,
    /// Prominence in height units (metres for sources).
    pub prominence: f32,
}

/// Control points and profiles at `c` on `field` (ridges high). `None` when
/// there are no exits or more than 8, or the feature is weaker than `min_prom`.
pub fn describe(
    field: &[f32],
    w: usize,
    h: usize,
    c: [f32; 2],
    exits: &[[f32; 2]],
    r: f32,
    min_prom: f32,
) -> Option<FeatureNode> {
    if exits.is_empty() || exits.len() > 8 {
        return None;
    }
    let hc = bilinear(field, w, h, c);
    type Raw = ([f32; 2], f32, [f32; ALONG], [f32; ACROSS]);
    let mut raw: Vec<Raw> = Vec::new();
    let mut prom = 0.0f32;
    for &q in exits {
        let l = dist(q, c).max(1e-3);
        let (dx, dy) = ((q[0] - c[0]) / l, (q[1] - c[1]) / l);
        let mut along = [0.0f32; ALONG];
        for (k, a) in along.iter_mut().enumerate() {
            let t = r * (k + 1) as f32 / ALONG as f32;
            *a = bilinear(field, w, h, [c[0] + dx * t, c[1] + dy * t]) - hc;
        }
        let hq = bilinear(field, w, h, q);
        let mut across = [0.0f32; ACROSS];
        for (k, a) in across.iter_mut().enumerate() {
            let t = (k as f32 - 3.0) * r / 4.0;
            *a = bilinear(field, w, h, [q[0] - dy * t, q[1] + dx * t]) - hq;
        }
        prom += -(across[0] + across[ACROSS - 1]) * 0.5;
        let angle = dy.atan2(dx) / std::f32::consts::TAU * TURN as f32;
        raw.push((q, angle, along, across));
    }
    prom /= exits.len() as f32;
    if prom.is_nan() || prom <= min_prom {
        return None;
    }
    let q = |v: f32| (v / prom * UNIT).round().clamp(-1024.0, 1023.0) as i16;
    let mut cps: Vec<Cp> = raw
        .iter()
        .map(|(p, a, al, ac)| Cp {
            pos: *p,
            angle: (a.round() as i32).rem_euclid(TURN) as u16,
            along: al.map(q),
            across: ac.map(q),
        })
        .collect();
    cps.sort_by_key(|c| c.angle);
    Some(FeatureNode {
        centre: c,
        cps,
        prominence: prom,
    })
}

/// A non-feature candidate: the patch with top-left `(x, y)` in its source.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FillCand {
    pub x: u32,
    pub y: u32,
    pub noise: [u32; 3],
}

/// The 6 non-feature transforms (seed 004 §7; issue: 90° rotations + 2
/// mirrors): the source index read for patch pixel `(x, y)` of an `n × n` patch.
#[inline]
pub fn fill_map(v: usize, x: usize, y: usize, n: usize) -> (usize, usize) {
    match v {
        0 => (x, y),
        1 => (y, n - 1 - x),
        2 => (n - 1 - x, n - 1 - y),
        3 => (n - 1 - y, x),
        4 => (n - 1 - x, y),
        _ => (x, n - 1 - y),
    }
}

/// Reduction of the grid on which round one of hole filling compares
/// patches: 8 × 8 block means, so a 64-pixel patch is 64 numbers (the
/// winner is checked at full resolution in round two). Patch sizes are
/// multiples of 8.
pub const COARSE: usize = 8;

/// Number of non-feature transforms.
pub const FILL_TRANSFORMS: usize = 6;

/// The part of a [`PreparedSource`] that is costly to compute and is
/// cached on disk ([`crate::patch::input::cache`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Features {
    pub ridges: Vec<FeatureNode>,
    pub valleys: Vec<FeatureNode>,
    pub fill: Vec<FillCand>,
}

/// One source DEM, prepared for synthesis.
#[derive(Debug, Clone)]
pub struct PreparedSource {
    pub name: String,
    pub width: usize,
    pub height: usize,
    pub cell_size: f64,
    /// Heights in metres (nodata filled harmonically).
    pub heights: Vec<f32>,
    /// Heights in integer decimetres (costs are integer).
    pub dm: Vec<i32>,
    pub ridges: Vec<FeatureNode>,
    pub valleys: Vec<FeatureNode>,
    /// [`COARSE`]² block means of `dm` (round one of hole filling).
    pub coarse: Vec<i32>,
    pub coarse_w: usize,
    pub fill: Vec<FillCand>,
    /// Per fill candidate, its `(patch/COARSE)²` reduced cells, contiguous,
    /// centred and clamped ([`centre_cells`]): what the
    /// round-one kernel reads, so it streams instead of gathering rows.
    pub fill_cells: Vec<i32>,
    /// The patch size this was prepared for.
    pub patch: usize,
}

/// PPA parameters for a field of relief `relief` at patch size `patch`:
/// profiles of patch/4, a dip of `frac · relief`, branches shorter than
/// patch/4 removed, components shorter than patch/2 dropped.
pub fn ppa_params(patch: usize, relief: f32, frac: f32) -> PpaParams {
    PpaParams {
        reach: (patch / 4).max(2),
        threshold: relief * frac,
        min_branch: patch as f32 / 4.0,
        passes: 6,
        min_component: patch as f32 / 2.0,
        smooth: 2,
    }
}

/// Feature nodes of one kind on `field` (ridges high): key nodes, and
/// points every patch/4 along paths, whose whole patch (with room for a
/// 45° rotation) lies inside the field; at most `cap`, strongest first.
#[allow(clippy::too_many_arguments)]
pub fn feature_nodes(
    field: &[f32],
    w: usize,
    h: usize,
    patch: usize,
    ppa: &PpaParams,
    min_prom: f32,
    margin: f32,
    cap: usize,
) -> (FeatureGraph, Vec<FeatureNode>) {
    let tree = ppa::extract(w, h, field, ppa);
    let graph = FeatureGraph::from_tree(&tree, patch as f32 / 8.0);
    let r = patch as f32 / 4.0;
    let mut centres: Vec<[f32; 2]> = graph.nodes.clone();
    for p in &graph.paths {
        let total = p.length();
        let mut s = r;
        while s < total - r * 0.5 {
            centres.push(point_at(&p.points, s));
            s += r;
        }
    }
    let inside = |c: [f32; 2]| {
        c[0] >= margin && c[1] >= margin && c[0] <= w as f32 - margin && c[1] <= h as f32 - margin
    };
    let idx = graph.exit_index();
    let mut nodes: Vec<FeatureNode> = centres
        .par_iter()
        .filter(|&&c| inside(c))
        .filter_map(|&c| describe(field, w, h, c, &graph.exits_in(&idx, c, r), r, min_prom))
        .collect();
    if nodes.len() > cap {
        // Strongest first; ties by position for determinism.
        nodes.sort_by(|a, b| {
            b.prominence
                .total_cmp(&a.prominence)
                .then(a.centre[1].total_cmp(&b.centre[1]))
                .then(a.centre[0].total_cmp(&b.centre[0]))
        });
        nodes.truncate(cap);
    }
    (graph, nodes)
}

/// Relief used to scale thresholds: the 2nd–98th percentile height range
/// (of every 7th sample: plenty for percentiles, and 7× cheaper to sort).
pub fn relief(v: &[f32]) -> f32 {
    let mut s: Vec<f32> = v
        .iter()
        .step_by(7)
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    if s.is_empty() {
        return 0.0;
    }
    s.sort_by(f32::total_cmp);
    let at = |q: f64| s[((s.len() - 1) as f64 * q) as usize];
    at(0.98) - at(0.02)
}

impl PreparedSource {
    /// Extracts features and candidates from one DEM whose heights are
    /// first multiplied by `scale` (see [`crate::patch::Library::prepare`]).
    pub fn prepare(
        name: &str,
        hf: &crate::Heightfield,
        params: &Params,
        scale: f32,
    ) -> crate::Result<Self> {
        Self::build(name, hf, params, scale, None)
    }

    /// What [`crate::patch::input::cache`] stores: the expensive part of [`Self::prepare`]
    /// (PPA on the whole DEM, candidate noise statistics).
    pub fn features(&self) -> Features {
        Features {
            ridges: self.ridges.clone(),
            valleys: self.valleys.clone(),
            fill: self.fill.clone(),
        }
    }

    /// [`Self::prepare`], taking the features from `cached` when given
    /// (they must come from the same DEM, parameters and scale: the cache
    /// key guarantees it) and deriving only the cheap rest.
    pub fn build(
        name: &str,
        hf: &crate::Heightfield,
        params: &Params,
        scale: f32,
        cached: Option<Features>,
    ) -> crate::Result<Self> {
        let mut hf = hf.clone();
        if hf.nodata_count() > 0 {
            crate::nodata::fill_nodata(&mut hf)?;
        }
        let (w, h) = (hf.width(), hf.height());
        let patch = params.patch;
        let heights: Vec<f32> = hf.data().iter().map(|v| v * scale).collect();
        let dm: Vec<i32> = heights.iter().map(|v| (v * 10.0).round() as i32).collect();
        let cw = w / COARSE;
        let ch = h / COARSE;
        let coarse: Vec<i32> = (0..cw * ch)
            .into_par_iter()
            .map(|i| {
                let (bx, by) = (i % cw, i / cw);
                let mut s = 0i64;
                for y in 0..COARSE {
                    for x in 0..COARSE {
                        s += dm[(COARSE * by + y) * w + COARSE * bx + x] as i64;
                    }
                }
                s.div_euclid((COARSE * COARSE) as i64) as i32
            })
            .collect();
        let Features {
            ridges,
            valleys,
            fill,
        } = match cached {
            Some(f) => f,
            None => Self::extract(&heights, &dm, w, h, params),
        };
        let m = patch / COARSE;
        let fill_cells: Vec<i32> = fill
            .par_iter()
            .flat_map_iter(|fc| {
                let (ox, oy) = (fc.x as usize / COARSE, fc.y as usize / COARSE);
                let mut cells: Vec<i32> = (0..m * m)
                    .map(|i| coarse[(oy + i / m) * cw + ox + i % m])
                    .collect();
                centre_cells(&mut cells, None);
                cells
            })
            .collect();
        Ok(PreparedSource {
            name: name.to_string(),
            width: w,
            height: h,
            cell_size: hf.cell_size(),
            heights,
            dm,
            ridges,
            valleys,
            coarse,
            coarse_w: cw,
            fill,
            fill_cells,
            patch,
        })
    }

    /// Feature nodes and non-feature candidates of scaled heights `heights`
    /// (`dm` in decimetres).
    fn extract(heights: &[f32], dm: &[i32], w: usize, h: usize, params: &Params) -> Features {
        let patch = params.patch;
        let rel = relief(heights).max(1.0);
        let ppa = ppa_params(patch, rel, params.source_dip);
        let margin = patch as f32 * 0.75;
        let min_prom = rel * params.source_min_prominence;
        let neg: Vec<f32> = heights.iter().map(|v| -v).collect();
        let ((_, ridges), (_, valleys)) = rayon::join(
            || {
                feature_nodes(
                    heights,
                    w,
                    h,
                    patch,
                    &ppa,
                    min_prom,
                    margin,
                    params.max_source_nodes,
                )
            },
            || {
                feature_nodes(
                    &neg,
                    w,
                    h,
                    patch,
                    &ppa,
                    min_prom,
                    margin,
                    params.max_source_nodes,
                )
            },
        );
        let stride = (patch / 2).max(COARSE) & !(COARSE - 1);
        let mut pos = Vec::new();
        let mut y = 0;
        while y + patch <= h {
            let mut x = 0;
            while x + patch <= w {
                pos.push((x, y));
                x += stride;
            }
            y += stride;
        }
        let valid = vec![true; patch * patch];
        let lowest = dm.iter().copied().min().unwrap_or(0);
        let fill: Vec<FillCand> = pos
            .par_iter()
            .filter_map(|&(x, y)| {
                let vals: Vec<i32> = (0..patch * patch)
                    .map(|i| dm[(y + i / patch) * w + x + i % patch])
                    .collect();
                // Patches with more than 5 % of water-flat ground at the
                // source's lowest level (SRTM sea is flat 0 m) would paste
                // plateaus; they are not candidates.
                let flat = vals.iter().filter(|&&v| v <= lowest + 5).count();
                (flat * 20 <= vals.len()).then(|| FillCand {
                    x: x as u32,
                    y: y as u32,
                    noise: noise_levels(patch, &vals, &valid),
                })
            })
            .collect();
        Features {
            ridges,
            valleys,
            fill,
        }
    }

    /// Feature nodes of one kind.
    pub fn nodes(&self, kind: Kind) -> &[FeatureNode] {
        match kind {
            Kind::Ridge => &self.ridges,
            Kind::Valley => &self.valleys,
        }
    }
}
