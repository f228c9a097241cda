//! Synthesis engine: determinism, the exemplar-reproduction property,
//! coordinate invariants, and robustness over odd sizes.

use crate::common;
use proptest::prelude::*;
use std::sync::OnceLock;
use terrasynth::database::layout::MARGIN;
use terrasynth::database::{Database, default};
use terrasynth::level::atlas::AtlasLevel;
use terrasynth::level::fixed::{FRAC_BITS, round};
use terrasynth::level::state::State;
use terrasynth::progress::Silent;
use terrasynth::stages::common::texel_height;
use terrasynth::synth::cone::Rect;
use terrasynth::synth::{Params, Synthesizer, coarse};

fn db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

fn bits(hf: &terrasynth::Heightfield) -> Vec<u32> {
    hf.data().iter().map(|v| v.to_bits()).collect()
}

/// The coarse start over `region` of a world drawing from exemplar `from`
/// (or all) at level `l`, in pieces of `side` texels.
fn start(
    atlas: &AtlasLevel<'_>,
    from: Option<usize>,
    (region, world): (Rect, (usize, usize)),
    (l, side): (usize, i32),
    (seed, jitter): (u32, i32),
) -> State {
    let pool = coarse::Pool::new(atlas, from);
    let src = coarse::Source { atlas, pool: &pool };
    coarse::pieces(src, region, world, (l, side), seed, jitter, None)
}

/// The level synthesis starts at, and the database's atlas there.
fn start_level() -> (usize, AtlasLevel<'static>) {
    let l = (db().level_count() - 1).min(coarse::MAX_START_LEVEL);
    (l, AtlasLevel::new(db(), l))
}

/// Mode-1 height of the atlas texel a coordinate rounds to.
fn height_at(atlas: &AtlasLevel<'_>, s: terrasynth::level::fixed::Coord) -> i32 {
    texel_height(atlas.appearance(round(s.x), round(s.y)))
}

#[test]
fn identical_bytes_across_runs_and_thread_counts() {
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let s = Synthesizer::new(db(), Params::default()).unwrap();
                bits(&s.synthesize(300, 200, 42).unwrap())
            })
    };
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(2), "a second run must repeat the first");
    let s = Synthesizer::new(db(), Params::default()).unwrap();
    assert_ne!(
        one,
        bits(&s.synthesize(300, 200, 43).unwrap()),
        "the seed must matter"
    );
}

#[test]
fn without_jitter_the_exemplar_is_reproduced() {
    // The classic parallel-synthesis property: no jitter, and every level is a
    // shifted copy of the start exemplar, which correction leaves alone
    // (the identity candidate matches exactly and wins ties).
    let params = Params {
        jitter: 0.0,
        keep_levels: true,
        ..Params::default()
    };
    let s = Synthesizer::new(db(), params).unwrap();
    let out = s.run(200, 160, 9).unwrap();
    let l0 = &out.levels[0];
    let origin = l0.coords[0];
    assert_eq!(origin.x % (1 << FRAC_BITS), 0, "integral coordinates");
    let q = db().quantization();
    let level = db().level(0);
    let rect = level.layout.rects[0];
    for y in 0..160 {
        for x in 0..200 {
            let c = l0.coords[y * l0.width + x];
            let (ex, ey) = (
                (origin.x >> FRAC_BITS) + x as i32,
                (origin.y >> FRAC_BITS) + y as i32,
            );
            assert_eq!(
                (c.x, c.y),
                (ex << FRAC_BITS, ey << FRAC_BITS),
                "pixel ({x},{y}) left the copy"
            );
            assert_eq!(l0.offsets[y * l0.width + x], 0);
            let e0 = db().heights()[rect.index(ex as u32, ey as u32)];
            let want = (q.offset_m + q.scale_m * e0 as f64) as f32;
            assert_eq!(out.heightfield.get(x, y), want, "height at ({x},{y})");
        }
    }
}

/// `Params::similar_from`: levels from it on score C₂ too, finer ones C₁
/// alone. Moving it from 0 (the paper's k = 2 everywhere) to 1 leaves
/// every level above 0 as it was and changes level 0 (C₂ wins there
/// rarely, but somewhere in 256²); moving it above level 1 changes level 1.
#[test]
fn similar_from_sets_where_c2_competes() {
    let levels = |from: usize| {
        let params = Params {
            keep_levels: true,
            similar_from: from,
            ..Params::default()
        };
        let out = Synthesizer::new(db(), params)
            .unwrap()
            .run(256, 256, 3)
            .unwrap();
        out.levels
    };
    let (paper, default, coarse) = (levels(0), levels(1), levels(2));
    let same =
        |a: &[terrasynth::synth::LevelMaps], b: &[terrasynth::synth::LevelMaps], l: usize| {
            a[l].coords == b[l].coords && a[l].offsets == b[l].offsets
        };
    for l in 1..paper.len() {
        assert!(
            same(&paper, &default, l),
            "level {l} changed without C₂ at level 0"
        );
    }
    assert!(!same(&paper, &default, 0), "level 0 ignored similar_from");
    assert!(!same(&default, &coarse, 1), "level 1 ignored similar_from");
    assert!(same(&default, &coarse, 2), "level 2 changed");
}

/// At every jitter up to the `--jitter` limit of 4 texels — which carries
/// a child past the 2-texel margin, into the gap or off the atlas, unless
/// the clamp picks the parent's exemplar (`--jitter 4` crashed before).
#[test]
fn coordinates_stay_inside_exemplar_interiors_at_every_level() {
    for (jitter, seed, (w, h)) in [
        (0.4, 5, (333, 257)),
        (4.0, 1, (512, 512)),
        (4.0, 2, (512, 512)),
    ] {
        let params = Params {
            keep_levels: true,
            jitter,
            ..Params::default()
        };
        let s = Synthesizer::new(db(), params).unwrap();
        let out = s.run(w, h, seed).unwrap();
        let coarsest = db().level_count() - 1;
        for maps in out.levels.iter().filter(|m| m.level <= coarsest) {
            let level = db().level(maps.level);
            let at = format!("jitter {jitter} seed {seed} level {}", maps.level);
            for c in &maps.coords {
                let (x, y) = (round(c.x), round(c.y));
                assert!(x >= 0 && y >= 0, "{at}: negative coordinate");
                let e = level
                    .layout
                    .exemplar_at(level.columns, x as u32, y as u32)
                    .unwrap_or_else(|| panic!("{at}: ({x},{y}) is in no exemplar"));
                assert!(
                    level.layout.rects[e].is_interior(x as u32, y as u32),
                    "{at}: ({x},{y}) on an edge"
                );
            }
        }
    }
}

#[test]
fn the_start_exemplar_dominates_the_result() {
    let level = db().level(0);
    let n = level.layout.rects.len();
    assert_eq!(n, default::names().len());
    for start in 0..n {
        let params = Params {
            keep_levels: true,
            start_exemplar: Some(start),
            ..Params::default()
        };
        let out = Synthesizer::new(db(), params)
            .unwrap()
            .run(256, 256, 3)
            .unwrap();
        let mut used = vec![0usize; n];
        for c in &out.levels[0].coords {
            let e = level
                .layout
                .exemplar_at(level.columns, round(c.x) as u32, round(c.y) as u32);
            used[e.expect("inside an exemplar")] += 1;
        }
        assert!(used[start] > 256 * 256 / 2, "start {start}: {used:?}");
    }
}

#[test]
fn without_a_start_exemplar_pieces_come_from_every_exemplar_by_area() {
    // Pieces are centred on texels drawn from the pool of every interior
    // texel by the guide's quantile, which is uniform over a large world:
    // each exemplar's share of the pieces follows its share of the
    // interior area (shares of the pooled altitudes, by exemplar). Three
    // crops of one terrain, of unequal sizes: uniform draws over the
    // exemplars (⅓ each) would be off by half of the largest share.
    let db = common::db::unequal_db();
    let l = (db.level_count() - 1).min(coarse::MAX_START_LEVEL);
    let atlas = AtlasLevel::new(db, l);
    let areas: Vec<f64> = atlas
        .level
        .layout
        .rects
        .iter()
        .map(|r| {
            let c = atlas.columns[r.x0 as usize];
            let nx = (c.max_x - c.min_x + 1) as u32;
            let ny = (c.max_y - MARGIN as i32 + 1) as u32;
            f64::from(nx * ny)
        })
        .collect();
    let total: f64 = areas.iter().sum();
    assert!(
        areas[0] > 0.5 * total && areas[2] < 0.2 * total,
        "interior areas {areas:?}: too alike to tell area from count"
    );
    let (n, side) = (160usize, 8i32);
    let world = n * side as usize;
    let st = start(
        &atlas,
        None,
        (Rect::new(0, 0, world, world), (world << l, world << l)),
        (l, side),
        (5, 0),
    );
    let mut used = vec![0usize; areas.len()];
    for j in 0..n {
        for i in 0..n {
            // The piece's centre pixel copies its centre texel.
            let at = (j * side as usize + side as usize / 2) * world
                + i * side as usize
                + side as usize / 2;
            let c = st.s(at);
            let e = atlas
                .level
                .layout
                .exemplar_at(atlas.level.columns, round(c.x) as u32, round(c.y) as u32)
                .expect("a piece's centre lies inside an exemplar");
            used[e] += 1;
        }
    }
    for (e, (&u, &p)) in used.iter().zip(&areas).enumerate() {
        let (got, want) = (u as f64 / (n * n) as f64, p / total);
        // Each draw is a uniform rank of the pooled altitudes; exemplars
        // whose altitudes overlap share the ranks. The guide's field is
        // smooth, so the 25 600 pieces are fewer independent draws.
        assert!(
            (got - want).abs() < 0.25 * want,
            "exemplar {e}: share {got:.3}, area share {want:.3} ({used:?})"
        );
    }
}

#[test]
fn pieces_cover_every_interior_texel_alike_and_stay_inside() {
    // Pieces are centred on any interior texel and mirrored at the
    // interior's edges, so texels at the edges are drawn about as often as
    // central ones, and every jittered coordinate rounds to an interior
    // texel.
    let (l, atlas) = start_level();
    let c = atlas.columns[atlas.level.layout.rects[0].x0 as usize];
    let (nx, ny) = (
        (c.max_x - c.min_x + 1) as usize,
        (c.max_y - MARGIN as i32 + 1) as usize,
    );
    let world = 1024;
    let st = start(
        &atlas,
        Some(0),
        (Rect::new(0, 0, world, world), (world << l, world << l)),
        (l, 8),
        (9, 100),
    );
    let mut hits = vec![0u32; nx];
    for i in 0..world * world {
        let s = st.s(i);
        let (x, y) = (round(s.x), round(s.y));
        assert!((c.min_x..=c.max_x).contains(&x) && (MARGIN as i32..=c.max_y).contains(&y));
        hits[(x - c.min_x) as usize] += 1;
    }
    let mean = (world * world) as f64 / nx as f64;
    let (edge, centre) = ((hits[0] + hits[nx - 1]) as f64 / 2.0, hits[nx / 2] as f64);
    assert!(
        edge > 0.6 * mean && centre < 1.4 * mean,
        "edge {edge}, centre {centre}, mean {mean} over {nx}×{ny} interior texels"
    );
}

#[test]
fn pieces_stand_where_the_guide_says_and_keep_the_exemplars_relief() {
    // The guide sets each piece's altitude: a piece's height is the rank
    // of its surroundings (mean over 224 px), drawn at the guide's
    // quantile there, so the start's heights follow the guide's smooth
    // field; and since the quantiles are uniform, the start holds the
    // exemplar's whole range of heights.
    let (l, atlas) = start_level();
    let c = atlas.columns[atlas.level.layout.rects[0].x0 as usize];
    let own: Vec<i32> = (MARGIN as i32..=c.max_y)
        .flat_map(|y| (c.min_x..=c.max_x).map(move |x| (x, y)))
        .map(|(x, y)| texel_height(atlas.appearance(x, y)))
        .collect();
    let relief = |mut h: Vec<i32>| {
        h.sort_unstable();
        f64::from(h[h.len() * 99 / 100] - h[h.len() / 100])
    };
    let own_relief = relief(own);
    let (n, side) = (96usize, 8i32);
    let world = n * side as usize;
    for seed in [1, 2] {
        let st = start(
            &atlas,
            Some(0),
            (Rect::new(0, 0, world, world), (world << l, world << l)),
            (l, side),
            (seed, 0),
        );
        let heights: Vec<i32> = (0..world * world)
            .map(|i| height_at(&atlas, st.s(i)))
            .collect();
        let kept = relief(heights.clone()) / own_relief;
        assert!(
            kept > 0.9,
            "seed {seed}: the start holds {kept:.2} of the relief"
        );
        // Mean height of each piece against the mean of its neighbours two
        // pieces away: a start that ignored the guide would have no
        // correlation at that distance (pieces are independent draws).
        let mean = |i: usize, j: usize| {
            let mut s = 0i64;
            for y in 0..side as usize {
                for x in 0..side as usize {
                    s +=
                        i64::from(heights[(j * side as usize + y) * world + i * side as usize + x]);
                }
            }
            s as f64
        };
        let pairs: Vec<(f64, f64)> = (0..n - 2)
            .flat_map(|j| (0..n - 2).map(move |i| (i, j)))
            .map(|(i, j)| (mean(i, j), mean(i + 2, j)))
            .collect();
        // Measured (seeds 1, 2): relief 1.00, correlation 0.49 and 0.47;
        // without the guide (uniform draws) the correlation is ~0.
        let r = common::correlation(&pairs);
        assert!(r > 0.3, "seed {seed}: pieces two apart correlate {r:.2}");
    }
}

#[test]
fn a_window_of_the_start_is_the_crop_of_the_whole() {
    // Every piece is a hash of the seed and its position, and the guide a
    // field of absolute positions: any region starts as the crop of the
    // whole (what windows and tiles rely on).
    // Worlds of 1000, 1200 and 4800 px: the first has its pieces' ranks
    // balanced among the whole world's (`coarse::guide::balance`), the
    // guide's rank window is ±8 nodes in the second, ±12 in the third
    // (`coarse::guide::rank_steps`). Its top-left 300 × 200 level-L
    // pixels (at most the world) stand for the whole.
    let (l, atlas) = start_level();
    for world in [(1000, 700), (1200, 800), (4800, 3200)] {
        let (w, h) = (300.min(world.0 >> l), 200.min(world.1 >> l));
        let whole = start(
            &atlas,
            None,
            (Rect::new(0, 0, w, h), world),
            (l, 8),
            (4, 100),
        );
        for r in [
            Rect::new(37, 21, 50, 40),
            Rect::new(0, 0, 7, 9),
            Rect::new(w - 50, h - 50, 50, 50),
        ] {
            let part = start(&atlas, None, (r, world), (l, 8), (4, 100));
            for y in 0..r.height() {
                for x in 0..r.width() {
                    let (a, b) = (
                        part.s(y * r.width() + x),
                        whole.s((r.y0 + y) * w + r.x0 + x),
                    );
                    assert_eq!((a.x, a.y), (b.x, b.y), "{world:?} {r:?} pixel ({x}, {y})");
                }
            }
        }
    }
}

#[test]
fn bad_parameters_are_refused() {
    for p in [
        Params {
            jitter: -0.1,
            ..Params::default()
        },
        Params {
            jitter: f64::NAN,
            ..Params::default()
        },
        Params {
            passes: 99,
            ..Params::default()
        },
        Params {
            start_exemplar: Some(default::names().len()),
            ..Params::default()
        },
        Params {
            piece_size: 7,
            ..Params::default()
        },
        Params {
            piece_size: 1025,
            ..Params::default()
        },
    ] {
        assert!(Synthesizer::new(db(), p).is_err());
    }
    let s = Synthesizer::new(db(), Params::default()).unwrap();
    assert!(s.synthesize(0, 10, 1).is_err());
}

/// How far beyond the exemplars' altitudes, as a share of their relief,
/// an unconstrained synthesis may reach. Measured: not at all (12 cases of
/// `odd_sizes_never_panic_and_heights_stay_in_range`, the lowest −15.9 m
/// for the exemplars' −16.5 m); 2 % (62 m) leaves room for joins.
const HEIGHT_MARGIN: f64 = 0.02;

proptest! {
    #![proptest_config(crate::common::proptest_cases(12))]

    #[test]
    fn odd_sizes_never_panic_and_heights_stay_in_range(
        (w, h) in prop_oneof![
            Just((1usize, 1usize)),
            Just((3, 2049)),
            Just((777, 333)),
            (1usize..200, 1usize..200),
        ],
        seed in any::<u32>(),
    ) {
        let s = Synthesizer::new(db(), Params { keep_levels: true, ..Params::default() }).unwrap();
        let out = s.run(w, h, seed).unwrap();
        prop_assert_eq!((out.heightfield.width(), out.heightfield.height()), (w, h));
        // Heights lie within the exemplars' altitudes, widened by
        // HEIGHT_MARGIN of their relief: unconstrained, the height prior
        // anchors each
        // level's offsets to the level above's, from a start that copies
        // exemplar texels (offset 0), so offsets only absorb the joins.
        let e = &db().meta().exemplars;
        let lo = e.iter().map(|e| e.min_m).fold(f64::INFINITY, f64::min);
        let hi = e.iter().map(|e| e.max_m).fold(f64::NEG_INFINITY, f64::max);
        let margin = HEIGHT_MARGIN * (hi - lo);
        prop_assert!(out.heightfield.data().iter().all(|v| v.is_finite()));
        let (got_lo, got_hi) = out.heightfield.data().iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v as f64), b.max(v as f64)));
        println!("{w}×{h} seed {seed}: heights {got_lo:.1}..{got_hi:.1} m, exemplars {lo:.1}..{hi:.1} m");
        prop_assert!(got_lo >= lo - margin && got_hi <= hi + margin, "{}..{} outside {}..{} ± {}", got_lo, got_hi, lo, hi, margin);
    }
}

/// A coast: the procedural hills flooded to their 30th height percentile
/// (`common::db::coast_db`), so that 30 % of it is one flat sea. Flat
/// texels fit any offset, and before flat candidates were anchored to their
/// own altitude the sea came out lifted wherever it met land (on the shared
/// coastal DEMs a green plain 5–130 m up); now the output keeps a sea at
/// sea level of about the exemplar's share.
#[test]
fn a_flat_sea_stays_at_sea_level() {
    let (db, sea) = common::db::coast_db();
    let sea = *sea;
    let s = Synthesizer::new(db, Params::default()).unwrap();
    let at_sea: Vec<f64> = (1..=3)
        .map(|seed| {
            let out = s.run(256, 256, seed).unwrap().heightfield;
            let n = out.data().iter().filter(|&&v| (v - sea).abs() <= 1.0);
            n.count() as f64 / out.data().len() as f64
        })
        .collect();
    // Measured: 8–19 % (mean 14 %) with the flat prior, 1.4–4.7 % (mean
    // 3.3 %) without; since the coarse start of issue 46 (0922eda)
    // 7.0–16.0 % (mean 11.6 %) with, 1.8–9.0 % (mean 5.4 %) without. Most
    // of the flooded valleys are narrow, so their texels' Gaussian-mean
    // heights see land and are not flat.
    let mean = at_sea.iter().sum::<f64>() / 3.0;
    assert!(
        mean >= 0.08,
        "{:.1} % of the output within 1 m of sea level (seeds 1–3: {at_sea:.3?}; exemplar 30 %)",
        100.0 * mean
    );
}

#[test]
fn the_outer_strips_of_the_exemplars_are_drawn() {
    // Synthesis starts at level ≤ coarse::MAX_START_LEVEL, where the 2-texel
    // margin is at most 16 pixels, so the exemplars' outer strips (here 32
    // px a side) are drawn about as often as their area says. Started at
    // the database's coarsest level (5 for the shared DEMs) they were
    // drawn a tenth as often or less: the outer 64 columns of
    // franconian_jura, 8 % of its area, gave 0.0–0.5 % of the output.
    let level = db().level(0);
    let strip = 32u32;
    let (mut in_strip, mut area_strip, mut area, mut n) = (0usize, 0u64, 0u64, 0usize);
    for r in &level.layout.rects {
        let inner = |s: u32| u64::from(s.saturating_sub(2 * strip));
        area += r.texels();
        area_strip += r.texels() - inner(r.width) * inner(r.height);
    }
    for seed in 1..=12 {
        let params = Params {
            keep_levels: true,
            ..Params::default()
        };
        let out = Synthesizer::new(db(), params)
            .unwrap()
            .run(512, 512, seed)
            .unwrap();
        for c in &out.levels[0].coords {
            let (x, y) = (round(c.x) as u32, round(c.y) as u32);
            let e = level.layout.exemplar_at(level.columns, x, y).unwrap();
            let r = level.layout.rects[e];
            let lx = x - r.x0;
            let edge = lx < strip || y < strip || lx >= r.width - strip || y >= r.height - strip;
            in_strip += usize::from(edge);
            n += 1;
        }
    }
    let (got, want) = (in_strip as f64 / n as f64, area_strip as f64 / area as f64);
    // Measured over these 12 seeds: 11.3 % of 23.4 % with the blocks the
    // start laid before issue 46 (seeds 3–5 alone: 10.3 / 13.5 % — a mean
    // over a few outputs is a lottery).
    assert!(
        got > 0.35 * want,
        "outer {strip} px: {:.1} % of the output, {:.1} % of the exemplars",
        got * 100.0,
        want * 100.0
    );
}
