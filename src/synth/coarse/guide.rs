//! The altitude guide of the coarse start: where a world stands high and
//! where low at the scale of massifs, drawn anew for every seed.
//!
//! A smooth random field — integer value noise, [`OCTAVES`] octaves from a
//! lattice of 256 or 512 output pixels ([`Scale`]), each octave half the
//! amplitude and lattice of the one before — is read through its own
//! distribution as a rank u ∈ [0, 1): the piece at a place takes its
//! source among the exemplars' places whose surroundings stand at quantile
//! u of their altitudes ([`super::pool::Pool`]). The field sets the layout
//! of highs and lows, the exemplars set everything else, and the output's
//! altitudes follow the exemplars' distribution whatever the layout: the
//! rank is local ([`RANK_STEPS`]), so every region of a few hundred
//! pixels holds the exemplars' whole range of altitudes — wider regions in
//! larger worlds ([`rank_steps`]). The field's scale follows the
//! exemplars' ([`Scale::of_exemplars`]).
//!
//! Why a field and not the exemplars' own layout: the start laid verbatim
//! exemplar blocks, so every output was the exemplar's own massifs
//! rearranged (issue 46: half of its 64-px windows matched the exemplar at
//! NCC ≥ 0.95, a world 3× the exemplar's side repeated its highest summit 8
//! times). Why not pieces drawn freely: an unguided mosaic of small pieces
//! has no structure above the piece size — highs and lows scattered as
//! blobs and pits, which correction then levels (relief 38–60 % with
//! 16-px blocks on the shared DEMs). Why no fit of each piece to its
//! neighbours (image quilting): choosing the best-fitting of several
//! candidates prefers pieces that fit anything — moderate altitudes,
//! smooth ground — and took a quarter of the relief before correction even
//! began (yosemite, 8 candidates: start relief 54 % of the exemplar's);
//! correction joins unfitted pieces at least as well.
//!
//! Every value is a hash of the seed and an absolute position (DESIGN §6):
//! a window of a world computes the same guide there.

use crate::hash::hash4;
use std::sync::OnceLock;

/// The scale of the field: its coarsest lattice, 2^`bits` output pixels,
/// and the spacing of the grid its local rank is taken on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scale {
    bits: u32,
}

impl Scale {
    /// The scale for exemplars whose shorter sides' median is `side`
    /// (output pixels): a
    /// lattice of the largest power of two below that side, 256 or 512 px
    /// — the field's coarsest cells are smaller than the exemplar that
    /// shows how large its landforms are.
    ///
    /// Why the exemplars' size: they are the only measure of how large
    /// the landforms they show are — a 600-px exemplar of a coast holds one
    /// sea, a 1024-px one a sea and a range. With a 256-px lattice for all
    /// (issue 46), every region of ~450 px held the whole range of
    /// altitudes, so the shared DEMs' coasts came out as round lakes
    /// between islands, each ringed by a narrow steep shore — several
    /// times the exemplar's coastline, and shore windows (sea against a
    /// ramp) are alike everywhere: catalan 16 % of windows copied (its
    /// halves 4 %), median slope 123 %. At 512 px the sea gathers into one
    /// or two large bodies with broad lowlands (the 8 shared DEMs, 600 to
    /// 1024 px; seeds 11–13, exemplar size: catalan 107 %, 9 % copied;
    /// worlds 3× the side, seed 11: 4 of the 8 meet every realism and
    /// novelty target, 3 of 8 before, and catalan, olympic and riviera miss
    /// one each). Why not 512 px for every exemplar: an
    /// output smaller than the lattice lies within one or two of its
    /// cells, and the embedded 512-px exemplars gave 256² outputs of one
    /// landform (seed 3: 950 m of relief where 256 px gives 2 455 m; a sea
    /// covering a fifth of seed 2). 128 px left no massifs larger than a
    /// few pieces; above 512 px nothing was measured.
    pub fn of_exemplars(side: usize) -> Scale {
        Scale {
            bits: if side > 512 { 9 } else { 8 },
        }
    }

    /// The spacing of the local rank's grid: 32 px at 256, 48 at 512 —
    /// the window (±[`RANK_STEPS`] nodes, ±224 or ±336 px) sets how large
    /// a low a region may hold. A 512-px field ranked within ±224 px came
    /// back as the 256-px field's lakes; within ±448 px the share of sea
    /// in a riviera-sized output was a lottery again (seed 11: more than
    /// half of it sea; seeds 12–13 a median slope of 169 %).
    fn spacing(self) -> i32 {
        16 + (1 << self.bits) / 16
    }
}

/// Octaves of the field (lattices of 256, 128 and 64 px at the 256-px
/// scale). A fourth octave at the 512-px scale measured the same on the 8
/// shared DEMs but for the coasts, 2–5 points steeper.
pub const OCTAVES: u32 = 3;

/// The rank of the field at a place is taken among its values at a grid
/// of places around it: `(2·RANK_STEPS + 1)²` nodes of a grid of
/// [`Scale::spacing`] output pixels anchored at the world's origin,
/// centred on the node at or before the place.
///
/// Why a local rank and not the field's global distribution: an output
/// the size of a shared DEM holds only a few lattice cells of the coarsest
/// octave, so the share of it the field put at low ranks was a lottery
/// (riviera, 39 % sea: a seed-11 output got 10 % at its start and a lake
/// after correction, median slope 211 % of the exemplar's; with local ranks
/// every ~450-px region holds the whole range of altitudes, in the
/// exemplars' proportions, and slope came to 133 %, relief 71 → 84 %).
///
/// Why nodes of a fixed grid and not places around each place: the pieces
/// of an output share them, so the field is evaluated once per node and
/// once per piece (2 209 + 1 024 evaluations for a 1024² output in 32-px
/// pieces, where 225 per piece were 230 400: 17 ms of a 1024² synthesis on
/// 2 cores).
///
/// This is the window of worlds up to 1024 px a side; larger ones take a
/// wider one ([`rank_steps`]).
const RANK_STEPS: i32 = 7;

/// The widest rank window, ±12 nodes (±576 px at the 512-px scale).
const MAX_RANK_STEPS: i32 = 12;

/// The rank window's half-width, in nodes, for a `world`: [`RANK_STEPS`]
/// up to 1024 px a side, growing with the longer side to
/// [`MAX_RANK_STEPS`] from 1756 px.
///
/// Why wider for large worlds: every window holds the whole range of
/// altitudes, the sea included, so a world many windows wide had a sea in
/// every one — a coast 3× the exemplar's side came out as a score of
/// enclosed seas ringed by coastal lowland (riviera: 15–17 % of its land
/// below 100 m where the DEM has 10 %, and with 39 % of the map flat sea
/// the map's median slope is the land's 18th percentile: 79 % of the
/// DEM's). At ±12 nodes the seas are fewer and larger and every shared
/// DEM's 3× world meets every target (seeds 11–13; riviera's slope 94 %).
/// Why not for all: on an output the size of an exemplar, a window that
/// reaches far past it made its share of sea a lottery again (riviera
/// 71 %, olympic 126 %).
pub fn rank_steps(world: (usize, usize)) -> i32 {
    let side = world.0.max(world.1);
    ((RANK_STEPS as usize * side / 1024) as i32).clamp(RANK_STEPS, MAX_RANK_STEPS)
}

/// Worlds up to this side (px) have the quantiles of their pieces
/// balanced among themselves ([`balance`]).
pub const BALANCED_SIDE: usize = 1024;

/// Pulls each of `quantiles` (1/2^16) halfway to its rank among `world`,
/// the quantiles of every piece of the world.
///
/// Why: a world the size of an exemplar is barely wider than the rank
/// window ([`RANK_STEPS`]: ±336 px at the 512-px scale, in worlds of 600 to
/// 1024 px), so how much of it the field put at low ranks was still a
/// lottery: riviera's exemplar is 39 % sea, and seeds 11–13 drew a map
/// more than half sea, a quarter sea and the right share (realism ratio
/// 1.34, 1.41 and 0.32); the north German plain drew its ridges over
/// a third of one map (ratio 2.76). Ranked among the world's own pieces
/// (every share the exemplars' exactly), the one or two lattice cells of
/// the field across such a world became one broad ramp — riviera's coastal
/// lowland too wide (median slope 80 % of the DEM's), the plain's relief
/// 83 %. Halfway (seeds 11–13), riviera meets every target (ratio 0.76,
/// slope 91 %, relief 91 %) and the plain's ratio is 1.30, the other six
/// DEMs at their own size as before or better.
///
/// Why not larger worlds: they hold many lattice cells and a wider window
/// ([`rank_steps`]), so their shares are near the exemplars' already, and
/// balancing asks for every piece of the world, which a tile of an
/// unbounded world cannot.
pub fn balance(quantiles: &mut [u32], mut world: Vec<u32>) {
    world.sort_unstable();
    if world.is_empty() {
        return;
    }
    for q in quantiles {
        *q = (*q + rank_in(&world, *q)) / 2;
    }
}

/// The rank of `r` among `sorted`, in 1/2^16: ties (equal values) take the
/// middle of their interval.
fn rank_in(sorted: &[u32], r: u32) -> u32 {
    let n = sorted.len() as u64;
    let lo = sorted.partition_point(|&s| s < r) as u64;
    let hi = sorted.partition_point(|&s| s <= r) as u64;
    (((lo + hi) << 15) / n) as u32
}

/// Salt of the field's hashes.
const SALT: u32 = 0x6A1D_0000;

/// The distribution of the field's local ranks is sampled over
/// `CDF_REGIONS` regions of `CDF_SIDE²` places (seed 0, far apart) at the
/// 256-px scale, 4× as many at 512 px: as many lattice cells either way
/// (with 256 regions the 512-px field's lowest decile held 12 % of a large
/// world).
const CDF_REGIONS: u32 = 256;
const CDF_SIDE: i32 = 4;

/// The quantiles u of the field of seed `seed` at output pixels `points`,
/// in 1/2^16 (0 ..= 65535): their local ranks, read through the
/// distribution of local ranks.
///
/// Why that distribution: the field is smooth at the scale of the rank's
/// window, so a place is rarely below (or above) all of the places around
/// it — measured, the lowest and highest deciles of local ranks held half
/// the share of the middle ones, and coasts came out with two thirds of
/// their sea (catalan 14.6 % at the start, exemplar 21.7 %).
pub fn quantiles(seed: u32, scale: Scale, steps: i32, points: &[(i32, i32)]) -> Vec<u32> {
    let steps = steps.clamp(RANK_STEPS, MAX_RANK_STEPS);
    let sorted = distribution(scale, steps);
    local_ranks(seed, scale, steps, points)
        .into_iter()
        .map(|r| rank_in(sorted, r))
        .collect()
}

/// The local ranks of [`CDF_REGIONS`] × [`CDF_SIDE`]² places of seed 0 at
/// `scale` in windows of ±`steps` nodes (`RANK_STEPS ..= MAX_RANK_STEPS`),
/// sorted: computed once per process, scale and window.
///
/// Why [`local_ranks`] runs on one thread: this is a lazy static's
/// initializer, and work handed to rayon's pool from inside it deadlocks
/// when the pool's threads are themselves waiting for the static (two
/// syntheses starting at once on 2 cores did). It is small: a 1024² output
/// ranks 1 024 places among 2 209 nodes in well under a millisecond.
fn distribution(scale: Scale, steps: i32) -> &'static [u32] {
    const WINDOWS: usize = (MAX_RANK_STEPS - RANK_STEPS + 1) as usize;
    static SORTED: [[OnceLock<Vec<u32>>; WINDOWS]; 2] =
        [const { [const { OnceLock::new() }; WINDOWS] }; 2];
    SORTED[(scale.bits - 8) as usize][(steps - RANK_STEPS) as usize]
        .get_or_init(|| sample(scale, steps))
}

/// The sorted sample behind [`distribution`].
fn sample(scale: Scale, steps: i32) -> Vec<u32> {
    let spacing = scale.spacing();
    let mut sorted: Vec<u32> = (0..CDF_REGIONS << (2 * (scale.bits - 8)))
        .flat_map(|k| {
            let x0 = (hash4(0, SALT | 1, k, 0) >> 12) as i32;
            let y0 = (hash4(0, SALT | 2, k, 0) >> 12) as i32;
            let places: Vec<(i32, i32)> = (0..CDF_SIDE * CDF_SIDE)
                .map(|i| {
                    let (dx, dy) = (i % CDF_SIDE, i / CDF_SIDE);
                    (x0 + dx * spacing + 16, y0 + dy * spacing + 16)
                })
                .collect();
            local_ranks(0, scale, steps, &places)
        })
        .collect();
    sorted.sort_unstable();
    sorted
}

/// The rank of the field of seed `seed` at each of `points` among its
/// values at the grid nodes within ±`steps` of it, in 1/2^16.
fn local_ranks(seed: u32, scale: Scale, steps: i32, points: &[(i32, i32)]) -> Vec<u32> {
    let spacing = scale.spacing();
    let node = |v: i32| v.div_euclid(spacing);
    let (Some(gx0), Some(gx1), Some(gy0), Some(gy1)) = (
        points.iter().map(|p| node(p.0)).min(),
        points.iter().map(|p| node(p.0)).max(),
        points.iter().map(|p| node(p.1)).min(),
        points.iter().map(|p| node(p.1)).max(),
    ) else {
        return Vec::new();
    };
    let (gx0, gy0) = (gx0 - steps, gy0 - steps);
    let nx = gx1 + steps - gx0 + 1;
    let ny = gy1 + steps - gy0 + 1;
    let nodes: Vec<i32> = (0..nx * ny)
        .map(|k| {
            let (gx, gy) = (gx0 + k % nx, gy0 + k / nx);
            field(seed, scale, gx * spacing, gy * spacing)
        })
        .collect();
    let n = ((2 * steps + 1) * (2 * steps + 1)) as u64;
    points
        .iter()
        .map(|&(x, y)| {
            let v = field(seed, scale, x, y);
            let (cx, cy) = (node(x) - gx0, node(y) - gy0);
            let mut below = 0u64;
            for gy in cy - steps..=cy + steps {
                let row = &nodes[(gy * nx) as usize..][..nx as usize];
                let around = &row[(cx - steps) as usize..=(cx + steps) as usize];
                below += around.iter().filter(|&&o| o < v).count() as u64;
            }
            // The middle of the rank's interval: (below + ½) / n.
            (((2 * below + 1) << 16) / (2 * n)) as u32
        })
        .collect()
}

/// The field at output pixel (x, y): [`OCTAVES`] octaves of value noise.
fn field(seed: u32, scale: Scale, x: i32, y: i32) -> i32 {
    (0..OCTAVES)
        .map(|o| value_noise(seed, SALT | (o + 8), x, y, scale.bits - o) >> o)
        .sum()
}

/// Value noise in `[−2^15, 2^15)` at (x, y): hashed values on a lattice of
/// 2^g pixels, interpolated bilinearly in integers.
fn value_noise(seed: u32, salt: u32, x: i32, y: i32, g: u32) -> i32 {
    let (cx, cy, fx, fy) = (x >> g, y >> g, x & ((1 << g) - 1), y & ((1 << g) - 1));
    let v = |dx: i32, dy: i32| {
        let h = hash4(seed, salt, (cx + dx) as u32, (cy + dy) as u32);
        i64::from((h >> 16) as i32 - (1 << 15))
    };
    let (fx, fy, n) = (i64::from(fx), i64::from(fy), 1i64 << g);
    let top = v(0, 0) * (n - fx) + v(1, 0) * fx;
    let bottom = v(0, 1) * (n - fx) + v(1, 1) * fx;
    ((top * (n - fy) + bottom * fy) >> (2 * g)) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranks_are_uniform_over_a_large_world_and_smooth() {
        for (side, step) in [(512, 32), (600, 64)] {
            let scale = Scale::of_exemplars(side);
            // 256 × 256 places an eighth of a lattice apart: a world of
            // 32 × 32 lattice cells at either scale.
            assert_eq!(step, (1 << scale.bits) / 8);
            for steps in [RANK_STEPS, MAX_RANK_STEPS] {
                uniform_and_smooth(scale, steps, step);
            }
        }
    }

    #[test]
    fn the_rank_window_widens_with_the_world_from_1024_px() {
        let steps: Vec<i32> = [
            (600, 600),
            (1024, 700),
            (1200, 1200),
            (1536, 9),
            (1800, 1800),
            (99999, 5),
        ]
        .map(rank_steps)
        .to_vec();
        assert_eq!(steps, [7, 7, 8, 10, 12, 12]);
    }

    #[test]
    fn balance_halves_the_lottery_of_a_small_world() {
        // A riviera-sized world (600 px, the 512-px scale, ±7 nodes): the
        // share of its 32-px places below the 39th percentile, over 40
        // seeds, against the 39 % every share should be.
        let scale = Scale::of_exemplars(600);
        let places: Vec<(i32, i32)> = (0..19 * 19)
            .map(|k| ((k % 19) * 32 + 16, (k / 19) * 32 + 16))
            .collect();
        let t = (39 << 16) / 100;
        let off = |q: &[u32]| {
            let below = q.iter().filter(|&&u| u < t).count() as f64 / q.len() as f64;
            (below - 0.39).abs()
        };
        let (mut raw, mut balanced) = (0.0, 0.0);
        for seed in 0..40 {
            let q = quantiles(seed, scale, RANK_STEPS, &places);
            raw += off(&q) / 40.0;
            let mut b = q.clone();
            balance(&mut b, q);
            assert!(b.iter().all(|&u| u < 65536));
            balanced += off(&b) / 40.0;
        }
        // Measured: 11 points off on average, 5.6 balanced.
        assert!(raw > 0.08, "raw {raw}");
        assert!(balanced < 0.6 * raw, "balanced {balanced}, raw {raw}");
        // A world already balanced keeps its quantiles, but for rounding.
        let even: Vec<u32> = (0..256).map(|k| (k << 8) + 128).collect();
        let mut b = even.clone();
        balance(&mut b, even.clone());
        assert!(b.iter().zip(&even).all(|(a, b)| a.abs_diff(*b) <= 1));
    }

    fn uniform_and_smooth(scale: Scale, window: i32, step: i32) {
        let places: Vec<(i32, i32)> = (0..256 * 257)
            .map(|k| ((k % 257) * step + 16, (k / 257) * step + 16))
            .collect();
        let q = quantiles(7, scale, window, &places);
        let mut hist = [0u32; 10];
        let (mut steps, mut n) = (0u64, 0u64);
        for (k, &r) in q.iter().enumerate() {
            if k % 257 == 256 {
                continue;
            }
            assert!(r < 65536);
            hist[((r * 10) >> 16) as usize] += 1;
            steps += u64::from(r.abs_diff(q[k + 1]));
            n += 1;
        }
        let mean = n as f64 / 10.0;
        for (k, &c) in hist.iter().enumerate() {
            assert!(
                (c as f64 - mean).abs() < 0.15 * mean,
                "window ±{window}, decile {k}: {c} of {n}"
            );
        }
        // Neighbours an eighth of a lattice apart differ by a tenth of the
        // range (measured 0.11 at 256 px): the field is smooth at the scale
        // of pieces (white noise: a third).
        let mean_step = steps as f64 / n as f64 / 65536.0;
        assert!(mean_step < 0.15, "mean step {mean_step}");
        // Another seed, another field.
        let places: Vec<(i32, i32)> = (0..64).map(|k| (k * 97, 5)).collect();
        let (a, b) = (
            quantiles(7, scale, window, &places),
            quantiles(8, scale, window, &places),
        );
        // A place's quantile is its own: the same whatever else is asked
        // with it (a window of a world asks for fewer places).
        assert_eq!(quantiles(7, scale, window, &places[40..45]), a[40..45]);
        let same = a.iter().zip(&b).filter(|(a, b)| a == b).count();
        assert!(same < 8, "{same}");
    }
}
