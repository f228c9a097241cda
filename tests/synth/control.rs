//! User control on real DEMs (issue 5 "Done means"): point accuracy and
//! slope, painted types, freezing, coherence locality and exact restricted
//! re-synthesis (copy-paste: `tests/synth/paste.rs`). A small database is built from two 256²
//! crops of ../shared/dem (with their type masks), a second one from a
//! Yosemite crop for points at another output size; skipped when absent.

use std::sync::{Arc, OnceLock};
use terrasynth::database::{self, BuildOptions, Database};
use terrasynth::heightfield::Heightfield;
use terrasynth::progress::Silent;
use terrasynth::synth::control::{
    Constraint, ConstraintId, Lift, Paste, PasteSource, PointConstraint, UNCONSTRAINED,
};
use terrasynth::synth::session::{Edit, Session};
use terrasynth::synth::{Params, Synthesizer};

use crate::common::db::{PYRENEES_CATALAN, TwoDems, start_relief, two_dems};
use crate::common::dem;
use crate::common::moved_outside;
/// The output side, the crops' side.
const N: usize = PYRENEES_CATALAN.side;
/// Slope across sloped points (median and 5th percentile of the sites of
/// `point_sites`, degrees; 20° asked). Measured on ten sites, median and
/// least: 16.2° and 13.5° since a sloped point holds its plane over its
/// whole reach, 11.4° and 4.3° under the paper's level cap; on twenty with
/// the Z-ordered coarse start, 15.9° and 13.4°; with the pieces of issue
/// 46, 17.3° and 14.1°. The least of twenty was a lottery (12.0–13.9° over
/// three sets of twenty on the same engine, 10.7° over a hundred), so the
/// bound is on the 5th percentile of many.
const SLOPE_MEDIAN_MIN: f64 = 15.0;
const SLOPE_P05_MIN: f64 = 12.0;

fn db() -> Option<&'static Database> {
    two_dems(PYRENEES_CATALAN, "control tests on real DEMs")
}

fn session(db: &Database) -> Session<'_> {
    Session::new(db, Params::default(), N, N, 7).unwrap()
}

/// Height at output position (x, y), bilinear between pixel centres (at
/// +0.5): the height *at a site*, wherever it falls in its pixel.
fn at(hf: &Heightfield, x: f64, y: f64) -> f64 {
    let (w, h) = (hf.width(), hf.height());
    let (fx, fy) = (x - 0.5, y - 0.5);
    let (x0, y0) = (
        fx.floor().clamp(0.0, (w - 2) as f64),
        fy.floor().clamp(0.0, (h - 2) as f64),
    );
    let (tx, ty) = ((fx - x0).clamp(0.0, 1.0), (fy - y0).clamp(0.0, 1.0));
    let g = |i: f64, j: f64| hf.get(i as usize, j as usize) as f64;
    (g(x0, y0) * (1.0 - tx) + g(x0 + 1.0, y0) * tx) * (1.0 - ty)
        + (g(x0, y0 + 1.0) * (1.0 - tx) + g(x0 + 1.0, y0 + 1.0) * tx) * ty
}

/// Mean height in a (2r+1)² window around (x, y).
fn mean_around(hf: &Heightfield, x: usize, y: usize, r: usize) -> f64 {
    let mut s = 0.0;
    for v in y - r..=y + r {
        for u in x - r..=x + r {
            s += hf.get(u, v) as f64;
        }
    }
    s / ((2 * r + 1) * (2 * r + 1)) as f64
}

#[test]
fn point_constraint_sets_height_and_slope() {
    // Two sites (one raised, one lowered, slopes facing +x / +y) on ten
    // terrains: a single site's error depends on what the terrain is there
    // — a target above the exemplars' highest peak is the hard case (2–3 %
    // of relief) — which every engine change moves, so the bound is on
    // the mean of twenty sites, with a looser one on the worst. Measured
    // (on the first ten): mean 1.27 % before synthesis started at level 3
    // (its terrains never reached those peaks), 1.16 % after; with the
    // paper's point tolerance s = ½ at level 3, 2.3 %; 0.92 % (worst
    // 2.83 %) since sloped points hold their whole reach; 1.56 % on the
    // terrains of the Z-ordered coarse start, whose twenty give 1.27 %
    // (worst 2.90 %) — over 144 points on the Pyrenees the Z order's sites
    // are closer (1.59 → 1.42 %), so ten sites were too few to judge by.
    // Since pixels held hard take their whole error (`nudge::phi`, t = 0:
    // a site's own coarse pixel), mean 1.13 %, and the worst site (a
    // target 2285 m high, seed 7) 3.56 % where it was 2.85 %; with the
    // coarse start's pieces (issue 46) mean 1.24 %, worst 2.65 % (seed 12,
    // the raised point), and the bound on the worst is 3.5 % again.
    let Some(db) = db() else { return };
    let sites = point_sites(db, 7..57);
    sites.assert_slopes_and_errors();
    assert!(
        sites.mean <= 0.015,
        "site heights off by {:.2}% of relief on average",
        sites.mean * 100.0
    );
    assert!(
        sites.worst <= 0.045,
        "a site height off by {:.2}% of relief",
        sites.worst * 100.0
    );
}

/// The same sites on a database of two 576² crops of the same DEMs:
/// exemplars larger than 512 px, whose coarse start lays out its highs
/// and lows on a 512-px field (`synth/coarse/guide.rs`, issue 46) where
/// the 256² crops above get the 256-px one. Measured: mean 1.29 % of
/// relief, slopes median 17.3°, least 14.1°; the 256-px field on the same
/// database gave a median of 18.1° but a least of 11.0°, under the bound.
/// Three of these seeds put a raised site in the sea (issue 40): 633 m
/// asked, 371 m got (10.3 % of relief) while the sea's flat candidates
/// were fitted towards their own altitude under a constraint too; fitted
/// by the pixel's prior there (`stages::correct::Prior::held`), 604 m
/// (1.2 %), and over all 60 sites mean 0.95 %, worst 2.53 %, least slope
/// 13.7°. So the worst site is bounded as on the small exemplars.
#[test]
fn point_constraints_hold_on_the_large_exemplars_scale() {
    let large = TwoDems {
        side: 576,
        ..PYRENEES_CATALAN
    };
    let Some(db) = two_dems(large, "control tests on large exemplars") else {
        return;
    };
    let sites = point_sites(db, 7..37);
    sites.assert_slopes_and_errors();
    assert!(
        sites.mean <= 0.015 && sites.worst <= 0.035,
        "site heights off by {:.2}% of relief on average, {:.2}% at worst",
        sites.mean * 100.0,
        sites.worst * 100.0
    );
}

/// What [`point_sites`] measured: site height errors (fractions of the
/// relief) and slopes across the sites (degrees).
struct Sites {
    /// Every site's error, ascending.
    errors: Vec<f64>,
    mean: f64,
    worst: f64,
    /// Every site's slope, ascending.
    slopes: Vec<f64>,
}

/// The `q`-quantile of ascending `v` (nearest rank).
fn quantile(v: &[f64], q: f64) -> f64 {
    v[((v.len() as f64 * q).ceil() as usize).clamp(1, v.len()) - 1]
}

impl Sites {
    /// The slope bounds above, a median error of at most 1.2 % of relief
    /// and a 90th percentile of at most 2.5 %.
    fn assert_slopes_and_errors(&self) {
        let (median, p05) = (quantile(&self.slopes, 0.5), quantile(&self.slopes, 0.05));
        assert!(
            median >= SLOPE_MEDIAN_MIN && p05 >= SLOPE_P05_MIN,
            "20° asked: median {median:.1}°, 5th percentile {p05:.1}°"
        );
        let (median, p90) = (quantile(&self.errors, 0.5), quantile(&self.errors, 0.9));
        assert!(
            median <= 0.012 && p90 <= 0.025,
            "site heights off by {:.2}% of relief (median), {:.2}% (90th percentile)",
            median * 100.0,
            p90 * 100.0
        );
    }
}

/// Two sites (one raised, one lowered, slopes facing +x / +y) on the
/// terrain of each seed of `db` at N²; every site descends along its
/// direction.
fn point_sites(db: &Database, seeds: std::ops::Range<u32>) -> Sites {
    let rel = start_relief(db);
    let mut errors = Vec::new();
    let mut slopes = Vec::new();
    for seed in seeds {
        let mut s = Session::new(db, Params::default(), N, N, seed).unwrap();
        let base = s.apply(vec![]).unwrap().heightfield;
        let cell = s.synthesizer().cell_size_m();
        for (k, (x, y, dir, lift)) in [
            (80.0, 90.0, 0.0, 0.25),
            (170.0, 160.0, std::f64::consts::FRAC_PI_2, -0.2),
        ]
        .into_iter()
        .enumerate()
        {
            let h = at(&base, x, y) + lift * rel;
            let p = PointConstraint::new((x, y), h, dir, 20f64.to_radians(), 40.0, cell).unwrap();
            let out = s
                .apply(vec![Edit::SetConstraint(
                    ConstraintId(k as u64),
                    Arc::new(p),
                )])
                .unwrap();
            let hf = &out.heightfield;
            let err = (at(hf, x, y) - h).abs() / rel;
            errors.push(err);
            // Slope: the terrain descends along the direction across the site.
            let (dx, dy) = (dir.cos(), dir.sin());
            let o = 12.0;
            let up = mean_around(hf, (x - o * dx) as usize, (y - o * dy) as usize, 2);
            let down = mean_around(hf, (x + o * dx) as usize, (y + o * dy) as usize, 2);
            println!(
                "seed {seed} point {k}: target {h:.1} m, got {:.1} m (error {:.2}% of relief {rel:.0} m); uphill {up:.1} m, downhill {down:.1} m (plane: {:.1} m apart)",
                at(hf, x, y),
                err * 100.0,
                2.0 * o * cell * 20f64.to_radians().tan()
            );
            assert!(
                up > down,
                "seed {seed} point {k}: no descent along the slope direction"
            );
            slopes.push(((up - down) / (2.0 * o * cell)).atan().to_degrees());
        }
    }
    slopes.sort_by(f64::total_cmp);
    errors.sort_by(f64::total_cmp);
    let mean = errors.iter().sum::<f64>() / errors.len() as f64;
    let worst = errors[errors.len() - 1];
    println!(
        "slopes across the sites (20° asked): median {:.1}°, 5th percentile {:.1}°, least {:.1}°",
        quantile(&slopes, 0.5),
        quantile(&slopes, 0.05),
        slopes[0]
    );
    println!(
        "site errors: mean {:.2}%, median {:.2}%, 90th percentile {:.2}%, 95th {:.2}%, worst {:.2}% of relief",
        mean * 100.0,
        quantile(&errors, 0.5) * 100.0,
        quantile(&errors, 0.9) * 100.0,
        quantile(&errors, 0.95) * 100.0,
        worst * 100.0
    );
    Sites {
        errors,
        mean,
        worst,
        slopes,
    }
}

#[test]
fn painted_types_take_their_coordinates_from_that_type() {
    let Some(db) = db() else { return };
    let hills = db
        .type_names()
        .iter()
        .position(|n| n == "hills")
        .expect("a hills type") as u8;
    let mut s = session(db);
    let (c, r) = (128.0, 60.0);
    let map: Vec<u8> = (0..N * N)
        .map(|k| {
            let (x, y) = ((k % N) as f64 + 0.5, (k / N) as f64 + 0.5);
            if (x - c).hypot(y - c) <= r {
                hills
            } else {
                UNCONSTRAINED
            }
        })
        .collect();
    let before = s.apply(vec![]).unwrap();
    drop(before);
    let share = |s: &Session<'_>| {
        let f = s.frames().unwrap();
        let lvl = db.level(2);
        let atlas = terrasynth::level::atlas::AtlasLevel::new(db, 2);
        let last = f.levels()[2].last().unwrap();
        let w = N / 4;
        let (mut inside, mut ok) = (0, 0);
        for (k, co) in last.coords.iter().enumerate() {
            let (x, y) = ((k % w) as f64 * 4.0 + 2.0, (k / w) as f64 * 4.0 + 2.0);
            if (x - c).hypot(y - c) <= r - 4.0 {
                inside += 1;
                let (tx, ty) = ((co.x + 128) >> 8, (co.y + 128) >> 8);
                ok += (lvl.types[atlas.index(tx, ty)] == hills) as usize;
            }
        }
        ok as f64 / inside as f64
    };
    let unpainted = share(&s);
    s.apply(vec![Edit::PaintTypes(Some(map))]).unwrap();
    let painted = share(&s);
    println!(
        "level-2 coordinates of type hills in the painted disc: {:.1}% (unpainted {:.1}%)",
        painted * 100.0,
        unpainted * 100.0
    );
    assert!(painted >= 0.95, "only {:.1}% hills", painted * 100.0);
}

#[test]
fn frozen_pixels_survive_edits_elsewhere_bit_for_bit() {
    let Some(db) = db() else { return };
    let mut s = session(db);
    let base = s.apply(vec![]).unwrap().heightfield;
    let frozen = |x: usize, y: usize| (20..110).contains(&x) && (30..120).contains(&y);
    let mask: Vec<bool> = (0..N * N).map(|k| frozen(k % N, k / N)).collect();
    s.apply(vec![Edit::Freeze(Some(mask))]).unwrap();
    let cell = s.synthesizer().cell_size_m();
    let p = PointConstraint::new((150.0, 120.0), 2500.0, 1.0, 0.3, 60.0, cell).unwrap();
    let out = s
        .apply(vec![Edit::SetConstraint(ConstraintId(1), Arc::new(p))])
        .unwrap();
    let change = out.change.unwrap();
    let mut checked = 0;
    for y in 0..N {
        for x in (0..N).filter(|&x| frozen(x, y)) {
            assert_eq!(
                out.heightfield.get(x, y).to_bits(),
                base.get(x, y).to_bits(),
                "({x}, {y})"
            );
            checked += 1;
        }
    }
    println!(
        "{checked} frozen pixels unchanged; {} pixels changed elsewhere",
        change.pixels
    );
    assert!(change.pixels > 100, "the point changed nothing");
}

#[test]
fn coherence_keeps_a_new_point_local() {
    let Some(db) = db() else { return };
    let rel = start_relief(db);
    let site = (140.0, 100.0);
    let run = |coherence: bool| {
        let mut s = session(db);
        s.coherence = coherence;
        let base = s.apply(vec![]).unwrap().heightfield;
        let cell = s.synthesizer().cell_size_m();
        let h = at(&base, site.0, site.1) + 0.2 * rel;
        let p = PointConstraint::new(site, h, 0.5, 0.2, 32.0, cell).unwrap();
        let after = s
            .apply(vec![Edit::SetConstraint(ConstraintId(3), Arc::new(p))])
            .unwrap();
        moved_outside(&base, &after.heightfield, site, 32.0, rel)
    };
    let (with, without) = (run(true), run(false));
    println!(
        "pixels outside the reach moved by > 1% of relief: {:.2}% with coherence, {:.2}% without",
        with * 100.0,
        without * 100.0
    );
    assert!(with < 0.02, "{:.2}% with coherence", with * 100.0);
    assert!(
        without > 2.0 * with && without > 0.01,
        "{:.2}% without",
        without * 100.0
    );
}

#[test]
fn restricted_resynthesis_is_exact_and_unchanged_inputs_repeat() {
    let Some(db) = db() else { return };
    let hills = db.type_names().iter().position(|n| n == "hills").unwrap() as u8;
    let paint: Vec<u8> = (0..N * N)
        .map(|k| {
            if (k % N) > 180 && (k / N) < 70 {
                hills
            } else {
                UNCONSTRAINED
            }
        })
        .collect();
    let passes = |db| {
        Synthesizer::new(db, Params::default())
            .unwrap()
            .level_passes(N, N)
    };
    assert_eq!(passes(db), [2, 2, 2]);
    restricted_matches_full(db, restricted_edits(db, Some(paint)));
    // Yosemite, smooth at the pixel scale: its start level takes four
    // times the passes (`Synthesizer::level_passes`), so a change there
    // spreads farther.
    let Some(yosemite) = yosemite() else { return };
    assert_eq!(passes(yosemite), [2, 2, 8]);
    restricted_matches_full(yosemite, restricted_edits(yosemite, None));
}

/// The edits of the restricted re-synthesis test: points set, moved and
/// removed, types painted (`paint`, where the database has types), a
/// paste and a freeze.
fn restricted_edits(db: &Database, paint: Option<Vec<u8>>) -> Vec<Vec<Edit>> {
    let cell = db.meta().exemplars[0].cell_size_m;
    let p1: Arc<dyn Constraint> =
        Arc::new(PointConstraint::new((60.0, 60.0), 1800.0, 0.0, 0.2, 30.0, cell).unwrap());
    let p2: Arc<dyn Constraint> =
        Arc::new(PointConstraint::new((70.0, 190.0), 900.0, 2.0, 0.4, 40.0, cell).unwrap());
    let p1b: Arc<dyn Constraint> =
        Arc::new(PointConstraint::new((90.0, 70.0), 1700.0, 0.0, 0.2, 30.0, cell).unwrap());
    vec![
        vec![],
        vec![Edit::SetConstraint(ConstraintId(1), p1)],
        vec![
            Edit::SetConstraint(ConstraintId(2), p2),
            Edit::PaintTypes(paint),
        ],
        vec![Edit::SetConstraint(ConstraintId(1), p1b)],
        vec![Edit::RemoveConstraint(ConstraintId(2))],
        vec![],
        // A paste rewrites the previous frame's results under it, and a
        // freeze keeps them: the restricted frame must still match.
        vec![Edit::Paste(Paste {
            source: PasteSource::Terrain,
            lasso: vec![(20.0, 150.0), (60.0, 150.0), (40.0, 190.0)],
            offset: (110, -30),
            delta_m: 80.0,
            lift: Lift::Source,
        })],
        vec![Edit::Freeze(Some(
            (0..N * N).map(|k| (k % N) < 40 && (k / N) < 40).collect(),
        ))],
    ]
}

/// Applies `edits` to a restricted and to a full re-synthesizing session:
/// every frame and every pass's results are the same.
fn restricted_matches_full(db: &Database, edits: Vec<Vec<Edit>>) {
    let mut fast = session(db);
    let mut full = session(db);
    full.restrict = false;
    for (k, e) in edits.into_iter().enumerate() {
        let a = fast.apply(e.clone()).unwrap();
        let b = full.apply(e).unwrap();
        let same = a
            .heightfield
            .data()
            .iter()
            .zip(b.heightfield.data())
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "edit {k}: restricted and full re-synthesis differ");
        assert!(
            fast.frames() == full.frames(),
            "edit {k}: per-pass results differ"
        );
        if k == 5 {
            assert_eq!(
                a.change.unwrap().pixels,
                0,
                "unchanged inputs must repeat bit for bit"
            );
        }
    }
}

/// A paste from an exemplar copies the exemplar's own pixels (lasso in its
/// coordinates) to their targets, near the exemplar's edge too: a paste
/// that addressed the atlas in other coordinates than the exemplar's (a
/// pad, an offset) would land other pixels there.
#[test]
fn sessions_are_identical_on_one_and_two_threads() {
    let Some(db) = db() else { return };
    let cell = db.meta().exemplars[0].cell_size_m;
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut s = session(db);
            s.apply(vec![]).unwrap();
            let p = PointConstraint::new((100.0, 120.0), 2000.0, 0.7, 0.3, 40.0, cell).unwrap();
            let f = s
                .apply(vec![Edit::SetConstraint(ConstraintId(9), Arc::new(p))])
                .unwrap();
            (f.heightfield, s.frames().unwrap().clone())
        })
    };
    let (a, b) = (run(1), run(2));
    assert!(
        a.0.data()
            .iter()
            .zip(b.0.data())
            .all(|(x, y)| x.to_bits() == y.to_bits())
    );
    assert!(a.1 == b.1);
}

/// A second database and output size: a 384² crop of the Yosemite DEM
/// (granite domes and glacial canyons, 30.8 m cells), synthesized at
/// 320 × 224.
fn yosemite() -> Option<&'static Database> {
    static DB: OnceLock<Option<Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let input = dem::exemplar("yosemite_half_dome", (200, 220, 384, 384), false)?;
        let opts = BuildOptions {
            levels: 5,
            ..Default::default()
        };
        Some(database::build(vec![input], &opts, &Silent).unwrap().0)
    })
    .as_ref()
}

/// RMS of the 3×3 high-pass (height − its 3×3 mean) over the pixels within
/// `r` of (x, y): the terrain's fine texture there.
fn texture(hf: &Heightfield, (x, y): (f64, f64), r: f64) -> f64 {
    let (mut s2, mut n) = (0.0, 0);
    for v in 1..hf.height() - 1 {
        for u in 1..hf.width() - 1 {
            if (u as f64 + 0.5 - x).hypot(v as f64 + 0.5 - y) > r {
                continue;
            }
            let m = mean_around(hf, u, v, 1);
            s2 += (hf.get(u, v) as f64 - m).powi(2);
            n += 1;
        }
    }
    (s2 / n as f64).sqrt()
}

#[test]
fn lowered_and_raised_points_on_a_second_dem_and_size() {
    let Some(db) = yosemite() else { return };
    let (w, h) = (320, 224);
    let rel = start_relief(db);
    for (k, (site, dir, lift)) in [((110.3, 96.8), 2.4, -0.22), ((214.6, 130.2), -0.9, 0.22)]
        .into_iter()
        .enumerate()
    {
        let mut s = Session::new(db, Params::default(), w, h, 11).unwrap();
        let base = s.apply(vec![]).unwrap().heightfield;
        let cell = s.synthesizer().cell_size_m();
        let target = at(&base, site.0, site.1) + lift * rel;
        let radius = 48.0;
        let slope = 15f64.to_radians();
        let p = PointConstraint::new(site, target, dir, slope, radius, cell).unwrap();
        let out = s
            .apply(vec![Edit::SetConstraint(ConstraintId(1), Arc::new(p))])
            .unwrap()
            .heightfield;
        let got = at(&out, site.0, site.1);
        let err = (got - target).abs() / rel;
        let (dx, dy) = (dir.cos(), dir.sin());
        let o = 10.0;
        let probe = |sign: f64| {
            let (u, v) = (site.0 + sign * o * dx, site.1 + sign * o * dy);
            mean_around(&out, u as usize, v as usize, 2)
        };
        let (up, down) = (probe(-1.0), probe(1.0));
        let (t_new, t_old) = (texture(&out, site, radius), texture(&base, site, radius));
        println!(
            "{} point {k}: target {target:.1} m, got {got:.1} m (error {:.2}% of relief {rel:.0} m); uphill {up:.1} m, downhill {down:.1} m; texture within the radius {t_new:.2} m (unconstrained {t_old:.2} m)",
            if lift < 0.0 { "lowered" } else { "raised" },
            err * 100.0,
        );
        assert!(
            err <= 0.02,
            "point {k}: site off by {:.2}% of relief",
            err * 100.0
        );
        assert!(up > down, "point {k}: no descent along the slope direction");
        // The disc keeps the exemplar's fine relief: a constraint that pinned
        // it to its target plane (the old terraced pits) would leave none.
        assert!(
            t_new >= 0.5 * t_old,
            "point {k}: texture {t_new:.2} m vs {t_old:.2} m unconstrained"
        );
    }
}
