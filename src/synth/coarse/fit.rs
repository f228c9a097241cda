//! Which layout each 2 × 2 group of blocks keeps: of [`LAYOUTS`] hashed
//! draws, the one whose level-L heights, slopes and terrain types are
//! distributed most like the exemplars' own.
//!
//! Why: an output holds few blocks — one group of four at the size of a
//! shared DEM — so its make-up was a lottery even with stratified quarters
//! ([`super::blocks`]): a group whose blocks sat over one exemplar's
//! valleys, or mirrored its lowland twice, gave the whole output less
//! relief and gentler slopes than the exemplar. Measured on the 8 shared
//! DEMs (single-exemplar synthesis at the exemplar's size, seeds 11–13):
//! yosemite kept 70–79 % of its relief, riviera's median slope ran
//! 130–193 % of the exemplar's, and the median slope of 4 of the 8 DEMs
//! missed the exemplar's by more than 10 %. Choosing among a few draws by
//! the distance between distributions keeps every choice a hash of the
//! seed and the group's position (a window or tile computes the same
//! choice: it looks only at the group's part of the world), and keeps
//! the draws' variety: any layout whose blocks spread like the exemplars
//! can win, wherever its blocks come from.

use super::blocks::{Draws, ranges};
use crate::database::Database;
use crate::synth::atlas::AtlasLevel;
use rayon::prelude::*;
use std::collections::HashMap;

/// Layouts drawn per group.
const LAYOUTS: u32 = 8;
/// Histogram bins per descriptor.
const BINS: usize = 64;

/// The level-L height and slope bin of every interior texel and each
/// exemplar's own histogram, per exemplar (range of [`Draws`]).
///
/// It depends only on the database, the level and the start exemplar, so
/// a [`crate::synth::Synthesizer`] builds it once: rebuilt on every call it
/// cost ≈ 1 ms per synthesis, an edit's restricted re-synthesis included.
pub struct Profile {
    bins: Vec<Vec<(u8, u8)>>,
    reference: Vec<Cdf>,
    /// The terrain type of every interior texel, per exemplar, and each
    /// type's share of all the interiors.
    types: Vec<Vec<u8>>,
    type_shares: Vec<f64>,
}

/// Counts of height and slope bins.
#[derive(Clone)]
struct Histogram {
    heights: [u32; BINS],
    slopes: [u32; BINS],
    n: u32,
}

impl Histogram {
    fn new() -> Histogram {
        Histogram {
            heights: [0; BINS],
            slopes: [0; BINS],
            n: 0,
        }
    }

    fn add(&mut self, (h, s): (u8, u8)) {
        self.heights[h as usize] += 1;
        self.slopes[s as usize] += 1;
        self.n += 1;
    }

    /// The sum of several histograms.
    fn pooled(parts: &[Histogram]) -> Histogram {
        let mut h = Histogram::new();
        for p in parts {
            for b in 0..BINS {
                h.heights[b] += p.heights[b];
                h.slopes[b] += p.slopes[b];
            }
            h.n += p.n;
        }
        h
    }
}

/// Cumulative height and slope distributions (fractions per bin).
#[derive(Clone)]
struct Cdf {
    heights: [f64; BINS],
    slopes: [f64; BINS],
}

impl Cdf {
    fn of(h: &Histogram) -> Cdf {
        let cumulative = |a: &[u32; BINS]| {
            let mut c = [0.0; BINS];
            let mut sum = 0u64;
            for (c, &x) in c.iter_mut().zip(a) {
                sum += u64::from(x);
                *c = sum as f64 / f64::from(h.n.max(1));
            }
            c
        };
        Cdf {
            heights: cumulative(&h.heights),
            slopes: cumulative(&h.slopes),
        }
    }

    /// The mixture Σ wᵢ·cdfᵢ.
    fn mixture<'a>(parts: impl Iterator<Item = (f64, &'a Cdf)>) -> Cdf {
        let mut m = Cdf {
            heights: [0.0; BINS],
            slopes: [0.0; BINS],
        };
        for (w, c) in parts {
            for b in 0..BINS {
                m.heights[b] += w * c.heights[b];
                m.slopes[b] += w * c.slopes[b];
            }
        }
        m
    }

    /// How far apart two height-and-slope distributions are: for heights
    /// and for slopes, the 1-D Wasserstein distance plus the mean distance
    /// of nine quantiles from 1 % to 99 %, each as a fraction of its axis.
    ///
    /// Why the quantiles too: the Wasserstein distance weighs a tail by its
    /// mass, and relief is a tail — by it alone riviera's groups took
    /// layouts with half the exemplar's high ground (relief kept 79 % over
    /// seeds 11–13); the quantiles weigh the 1 % and 99 % points like the
    /// median.
    fn distance(&self, other: &Cdf) -> f64 {
        let axis = |a: &[f64; BINS], b: &[f64; BINS]| {
            let w1 = a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>();
            let q = QUANTILES
                .iter()
                .map(|&p| (quantile(a, p) - quantile(b, p)).abs())
                .sum::<f64>();
            (w1 + q / QUANTILES.len() as f64) / BINS as f64
        };
        axis(&self.heights, &other.heights) + axis(&self.slopes, &other.slopes)
    }
}

/// The quantiles [`Cdf::distance`] compares.
const QUANTILES: [f64; 9] = [0.01, 0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.95, 0.99];

/// Quantile `p` of a cumulative histogram, in bins (linear inside a bin).
fn quantile(cdf: &[f64; BINS], p: f64) -> f64 {
    let mut below = 0.0;
    for (b, &c) in cdf.iter().enumerate() {
        if c >= p && c > below {
            return b as f64 + (p - below) / (c - below);
        }
        below = c;
    }
    cdf.len() as f64
}

impl Profile {
    /// Heights at level L are the means of each texel's 2^L × 2^L level-0
    /// footprint (the database keeps heights at level 0 only); slopes are
    /// the lengths of their central differences, in integers (a choice of
    /// the start must not hang on a platform's `hypot`). Bins span the
    /// exemplars' height range and their slopes up to the 99th percentile.
    pub fn new(db: &Database, atlas: &AtlasLevel<'_>, from: Option<usize>) -> Profile {
        let l = atlas.level.index;
        let (heights0, rects0) = (db.heights(), &db.level(0).layout.rects);
        let rects = &atlas.level.layout.rects;
        let first = from.unwrap_or(0);
        let ranges = ranges(atlas, from);
        // Per range: (height, slope) of every interior texel, row-major.
        let texels: Vec<Vec<(i64, i64)>> = ranges
            .par_iter()
            .enumerate()
            .map(|(r, &(x0, y0, nx, ny))| {
                let (e, r0) = (first + r, &rects0[first + r]);
                let rl = rects[e];
                let (w, w0) = (rl.width as usize, r0.width as usize);
                // Means over the whole level-L rectangle.
                let means: Vec<i64> = (0..rl.height as usize)
                    .flat_map(|y| (0..w).map(move |x| (x, y)))
                    .map(|(x, y)| {
                        let rows = (y << l)..((y + 1) << l);
                        let sum: i64 = rows
                            .map(|yy| {
                                let row = r0.offset as usize + yy * w0 + (x << l);
                                heights0[row..row + (1 << l)]
                                    .iter()
                                    .map(|&v| i64::from(v))
                                    .sum::<i64>()
                            })
                            .sum();
                        sum >> (2 * l)
                    })
                    .collect();
                let at = |x: i32, y: i32| means[y as usize * w + (x - rl.x0 as i32) as usize];
                (0..ny)
                    .flat_map(|ly| (0..nx).map(move |lx| (x0 + lx, y0 + ly)))
                    .map(|(x, y)| {
                        // Interiors keep a margin inside the rectangle, so
                        // the ±1 neighbours exist.
                        let dx = at(x + 1, y) - at(x - 1, y);
                        let dy = at(x, y + 1) - at(x, y - 1);
                        (at(x, y), (dx * dx + dy * dy).isqrt())
                    })
                    .collect()
            })
            .collect();
        let all = || texels.iter().flatten();
        let lo = all().map(|t| t.0).min().unwrap_or(0);
        let span = all().map(|t| t.0).max().unwrap_or(0) - lo + 1;
        let mut slopes: Vec<i64> = all().map(|t| t.1).collect();
        slopes.sort_unstable();
        let top = slopes
            .get(slopes.len() * 99 / 100)
            .copied()
            .unwrap_or(1)
            .max(1);
        let bin = |&(h, s): &(i64, i64)| {
            let hb = ((h - lo) * BINS as i64 / span) as u8;
            let sb = (s * BINS as i64 / top).min(BINS as i64 - 1) as u8;
            (hb, sb)
        };
        let bins: Vec<Vec<(u8, u8)>> = texels.iter().map(|t| t.iter().map(bin).collect()).collect();
        let reference = bins
            .iter()
            .map(|b| {
                let mut h = Histogram::new();
                b.iter().for_each(|&b| h.add(b));
                Cdf::of(&h)
            })
            .collect();
        let types: Vec<Vec<u8>> = ranges
            .par_iter()
            .map(|&(x0, y0, nx, ny)| {
                (0..ny)
                    .flat_map(|ly| (0..nx).map(move |lx| (x0 + lx, y0 + ly)))
                    .map(|(x, y)| atlas.level.types[atlas.index(x, y)])
                    .collect()
            })
            .collect();
        let mut counts = vec![0u64; db.type_names().len().max(1)];
        types
            .iter()
            .flatten()
            .for_each(|&t| counts[t as usize] += 1);
        let total = counts.iter().sum::<u64>().max(1) as f64;
        let type_shares = counts.iter().map(|&c| c as f64 / total).collect();
        Profile {
            bins,
            reference,
            types,
            type_shares,
        }
    }

    /// The histograms, per exemplar, of group (gx, gy) under `layout`, over
    /// the group's pixels inside the world (the whole group when none is: a
    /// group the warp reaches into the world from outside), ignoring the
    /// warp.
    fn group(
        &self,
        draws: &Draws,
        seed: u32,
        layout: u32,
        (gx, gy): (i32, i32),
        world: [i32; 4],
    ) -> (Vec<Histogram>, Vec<u32>) {
        let side = 2 << draws.bits;
        let (x0, y0) = (gx * side, gy * side);
        let [mut x0c, mut y0c, mut x1c, mut y1c] = [
            x0.max(world[0]),
            y0.max(world[1]),
            (x0 + side).min(world[2]),
            (y0 + side).min(world[3]),
        ];
        if x0c >= x1c || y0c >= y1c {
            [x0c, y0c, x1c, y1c] = [x0, y0, x0 + side, y0 + side];
        }
        let mut h = vec![Histogram::new(); self.bins.len()];
        let mut types = vec![0u32; self.type_shares.len()];
        // Block by block (each block's origin is drawn once).
        for (bx, by) in [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(i, j)| (2 * gx + i, 2 * gy + j)) {
            let origin = draws.origin(seed, layout, (bx, by));
            let b = 1 << draws.bits;
            let (xs, ys) = (
                x0c.max(bx * b)..x1c.min((bx + 1) * b),
                y0c.max(by * b)..y1c.min((by + 1) * b),
            );
            for y in ys {
                for x in xs.clone() {
                    let (r, lx, ly) = draws.texel(origin, (bx, by), (x, y));
                    let k = (ly * draws.ranges[r].2 + lx) as usize;
                    h[r].add(self.bins[r][k]);
                    types[self.types[r][k] as usize] += 1;
                }
            }
        }
        (h, types)
    }

    /// How far group (gx, gy) under `layout` is from the exemplars it
    /// draws from: its pooled histogram against the mixture of those
    /// exemplars' own, weighted by how many of its pixels each gives.
    ///
    /// Why against its own exemplars' mixture: against the whole database,
    /// a group of four blocks is most typical when it draws from the
    /// exemplars in the middle of the pool — the embedded database's three
    /// styles gave 23 / 54 / 23 % of 512² outputs (35 / 34 / 32 % by area
    /// before); each exemplar's part judged alone against its exemplar
    /// instead shunned the bimodal coastal ones (typed database: 0 % sea of
    /// 10.4). Pooled, a block may make up for another's tail, as over one
    /// exemplar.
    ///
    /// Plus half the L1 distance between the group's terrain-type shares
    /// and the whole database's: types are what a user paints with, and an
    /// unpainted synthesis should use them by their share (the 8-DEM typed
    /// database at 1024², one group, seeds 11–13: "hills" +12.5 points
    /// without this term, −0.8 with it). One type: no term.
    fn distance(
        &self,
        draws: &Draws,
        seed: u32,
        layout: u32,
        group: (i32, i32),
        world: [i32; 4],
    ) -> f64 {
        let (parts, types) = self.group(draws, seed, layout, group, world);
        let pooled = Histogram::pooled(&parts);
        let n = f64::from(pooled.n);
        let weights = parts.iter().map(|h| f64::from(h.n) / n);
        let mixture = Cdf::mixture(weights.zip(&self.reference));
        let type_distance = types
            .iter()
            .zip(&self.type_shares)
            .map(|(&c, &share)| (f64::from(c) / n - share).abs())
            .sum::<f64>()
            / 2.0;
        Cdf::of(&pooled).distance(&mixture) + type_distance
    }
}

/// The layout of every group that `blocks` (level-L block positions on the
/// shifted grid) touch, keyed by group position. `world`: the world's size
/// in level-L pixels and the grid's shift.
pub(super) fn layouts(
    profile: &Profile,
    draws: &Draws,
    (world, shift): ((usize, usize), (i32, i32)),
    seed: u32,
    blocks: impl Iterator<Item = (i32, i32)>,
) -> HashMap<(i32, i32), u32> {
    // Runs of pixels share a group: dropping repeats first leaves a few
    // thousand to sort where a 512² start level has 262 144 pixels.
    let mut groups: Vec<(i32, i32)> = Vec::new();
    for g in blocks.map(|(bx, by)| (bx >> 1, by >> 1)) {
        if groups.last() != Some(&g) {
            groups.push(g);
        }
    }
    groups.sort_unstable();
    groups.dedup();
    let world = [
        shift.0,
        shift.1,
        shift.0 + world.0 as i32,
        shift.1 + world.1 as i32,
    ];
    // Every (group, layout) distance in parallel: an output the exemplars'
    // size is one group, whose eight layouts were one thread's work.
    let distances: Vec<_> = (0..groups.len() * LAYOUTS as usize)
        .into_par_iter()
        .map(|k| {
            let (g, c) = (groups[k / LAYOUTS as usize], k as u32 % LAYOUTS);
            profile.distance(draws, seed, c, g, world)
        })
        .collect();
    groups
        .iter()
        .zip(distances.chunks(LAYOUTS as usize))
        .map(|(&g, d)| {
            // Ties keep the earlier layout.
            let best =
                (1..LAYOUTS).fold(0, |b, c| if d[c as usize] < d[b as usize] { c } else { b });
            (g, best)
        })
        .collect()
}
