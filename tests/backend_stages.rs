//! CPU ≡ GPU, byte for byte, after every stage (DESIGN §6): each stage on
//! random states (proptest) and on real ones (the levels of syntheses from
//! the default database and from a database of ../shared/dem crops), and
//! whole syntheses end to end.
//!
//! Needs `--features gpu` and a Vulkan adapter (lavapipe will do: Debian
//! package `mesa-vulkan-drivers`); without one every test prints why and
//! passes without checking anything.
#![cfg(feature = "gpu")]

use proptest::prelude::*;
use std::sync::{Arc, OnceLock};
use terrasynth::backend::gpu::{Context, Gpu};
use terrasynth::backend::{Backend, cpu::Cpu};
use terrasynth::database::{self, BuildOptions, Database, default, layout::MARGIN};
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::fixed::{Coord, FRAC_BITS};
use terrasynth::synth::stages::correct::{CorrectParams, DEFAULT_PRIOR, PRIORS, SUBPASSES, scalar};
use terrasynth::synth::stages::upsample_jitter::{Step, UpsampleParams};
use terrasynth::synth::state::State;
use terrasynth::synth::{Params, Synthesizer};

mod common;
use common::dem::{self, DEM};

/// The shared device, or `None` without an adapter (see `common::gpu`).
fn ctx() -> Option<Arc<Context>> {
    common::gpu::context()
}

fn default_db() -> &'static Database {
    static DB: OnceLock<Database> = OnceLock::new();
    DB.get_or_init(|| default::build_default(&Silent).unwrap())
}

/// Two 192² crops of real DEMs (with their type masks), or `None` when
/// ../shared/dem is absent.
fn dem_db() -> Option<&'static Database> {
    static DB: OnceLock<Option<Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let crop = |name: &str, x, y| dem::exemplar(name, (x, y, 192, 192), false);
        let inputs = vec![
            crop("pyrenees_andorra", 300, 200)?,
            crop("franconian_jura", 200, 300)?,
        ];
        let opts = BuildOptions {
            levels: 4,
            ..Default::default()
        };
        Some(database::build(inputs, &opts, &Silent).unwrap().0)
    })
    .as_ref()
    .or_else(|| {
        eprintln!("{DEM} not found: real-DEM cross-checks skipped");
        None
    })
}

/// Both backends over one database.
struct Pair<'db> {
    atlas: Vec<AtlasLevel<'db>>,
    heights: &'db [u16],
    gpu: Gpu,
}

impl<'db> Pair<'db> {
    fn new(db: &'db Database, ctx: Arc<Context>) -> Pair<'db> {
        let atlas: Vec<_> = (0..db.level_count())
            .map(|i| AtlasLevel::new(db, i))
            .collect();
        let gpu = Gpu::new(ctx, &atlas, db.heights()).unwrap();
        Pair {
            atlas,
            heights: db.heights(),
            gpu,
        }
    }
    fn cpu(&self) -> Cpu<'_, 'db> {
        Cpu {
            atlas: &self.atlas,
            heights: self.heights,
        }
    }
}

fn copy(st: &State) -> State {
    let c = State::new(st.width, st.height);
    for i in 0..st.width * st.height {
        c.set(i, st.s(i), st.v(i));
    }
    c
}

fn state_from(w: usize, h: usize, coords: &[Coord], offsets: &[i32]) -> State {
    let st = State::new(w, h);
    for i in 0..w * h {
        st.set(i, coords[i], offsets[i]);
    }
    st
}

/// What the synthesis guarantees of a level's state: every coordinate
/// rounds into an exemplar's interior, its fraction in [−½, ½) texel.
fn random_state(atlas: &AtlasLevel<'_>, w: usize, h: usize, bits: &[u32]) -> State {
    let rects = &atlas.level.layout.rects;
    let st = State::new(w, h);
    for i in 0..w * h {
        let b = |k: usize| bits[(4 * i + k) % bits.len()] ^ (i as u32).wrapping_mul(0x9E37_79B9);
        let r = rects[b(0) as usize % rects.len()];
        let tx = r.x0 + MARGIN + b(1) % (r.width - 2 * MARGIN);
        let ty = MARGIN + b(2) % (r.height - 2 * MARGIN);
        let fx = (b(3) & 0xFF) as i32 - 128;
        let fy = ((b(3) >> 8) & 0xFF) as i32 - 128;
        let v = ((b(3) >> 16) % 801) as i32 - 400;
        st.set(
            i,
            Coord {
                x: ((tx as i32) << FRAC_BITS) + fx,
                y: ((ty as i32) << FRAC_BITS) + fy,
            },
            v,
        );
    }
    st
}

/// Runs one subpass on the GPU, the CPU (SIMD + scalar frame) and the scalar
/// oracle from the same state; all three must agree.
fn check_correct(
    pair: &Pair<'_>,
    level: usize,
    (st, parent): (&State, Option<&State>),
    p: &CorrectParams,
    what: &str,
) {
    let g = pair.gpu.upload(copy(st)).unwrap();
    let gp = parent.map(|pa| pair.gpu.upload(copy(pa)).unwrap());
    pair.gpu.correct(&g, gp.as_ref(), level, p);
    let gpu = pair.gpu.download(&g).unwrap();
    let cpu_st = copy(st);
    pair.cpu().correct(&cpu_st, parent, level, p);
    let oracle = copy(st);
    scalar::correct(&pair.atlas[level], &oracle, parent, p);
    assert_eq!(
        (oracle.coords(), oracle.offsets()),
        (cpu_st.coords(), cpu_st.offsets()),
        "{what}: CPU paths differ"
    );
    assert_states_eq(&gpu, &(cpu_st.coords(), cpu_st.offsets()), what);
}

fn assert_states_eq(gpu: &(Vec<Coord>, Vec<i32>), cpu: &(Vec<Coord>, Vec<i32>), what: &str) {
    if let Some(i) = (0..cpu.0.len()).find(|&i| gpu.0[i] != cpu.0[i] || gpu.1[i] != cpu.1[i]) {
        panic!(
            "{what}: first difference at pixel {i}: GPU {:?} V {} vs CPU {:?} V {}",
            gpu.0[i], gpu.1[i], cpu.0[i], cpu.1[i]
        );
    }
    assert_eq!(gpu, cpu, "{what}");
}

fn check_upsample(
    pair: &Pair<'_>,
    parent: &State,
    (w, h): (usize, usize),
    level: usize,
    p: &UpsampleParams,
) {
    let gp = pair.gpu.upload(copy(parent)).unwrap();
    let gc = pair.gpu.alloc(w, h).unwrap();
    pair.gpu.upsample_jitter(&gp, &gc, level, p);
    let cc = State::new(w, h);
    pair.cpu().upsample_jitter(parent, &cc, level, p);
    assert_states_eq(
        &pair.gpu.download(&gc).unwrap(),
        &(cc.coords(), cc.offsets()),
        &format!("upsample_jitter to level {level} ({:?})", p.step),
    );
}

fn check_reconstruct(pair: &Pair<'_>, st: &State) {
    let g = pair.gpu.upload(copy(st)).unwrap();
    assert_eq!(
        pair.gpu.reconstruct(&g).unwrap(),
        pair.cpu().reconstruct(st).unwrap(),
        "reconstruct"
    );
}

fn default_pair() -> Option<&'static Pair<'static>> {
    static PAIR: OnceLock<Option<Pair<'static>>> = OnceLock::new();
    PAIR.get_or_init(|| ctx().map(|c| Pair::new(default_db(), c)))
        .as_ref()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn correct_matches_on_random_states(
        w in 2usize..48, h in 2usize..48, level_pick in 0usize..8, sub in 0usize..4,
        prior in prop::sample::select(PRIORS.to_vec()), with_parent in any::<bool>(),
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let Some(pair) = default_pair() else { return Ok(()) };
        let level = level_pick % pair.atlas.len();
        let st = random_state(&pair.atlas[level], w, h, &bits);
        let rev: Vec<u32> = bits.iter().rev().copied().collect();
        let parent = random_state(&pair.atlas[level], w.div_ceil(2), h.div_ceil(2), &rev);
        let (px, py) = SUBPASSES[sub];
        let p = CorrectParams { px, py, prior };
        let what = format!("random {w}x{h} level {level} prior {prior}");
        check_correct(pair, level, (&st, with_parent.then_some(&parent)), &p, &what);
    }

    #[test]
    fn upsample_jitter_matches_on_random_states(
        w in 2usize..40, h in 2usize..40, level_pick in 0usize..8, seed in any::<u32>(),
        jitter in 0i32..=1024, shift in 1u32..4, kind in 0u32..3,
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let Some(pair) = default_pair() else { return Ok(()) };
        let l = pair.atlas.len() - 1;
        let (cw, ch) = (2 * w - (bits[0] & 1) as usize, 2 * h - (bits[1] & 1) as usize);
        let (level, step, parent_level) = match kind {
            0 => {
                let level = level_pick % l;
                (level, Step::Pyramid, level + 1)
            }
            1 => (l + shift as usize, Step::Virtual { shift }, l),
            _ => {
                let r = pair.atlas[l].level.layout.rects[0];
                let step = Step::Wrap {
                    min_x: (r.x0 + MARGIN) as i32,
                    max_x: (r.x0 + r.width - 1 - MARGIN) as i32,
                    min_y: MARGIN as i32,
                    max_y: (r.height - 1 - MARGIN) as i32,
                };
                (l, step, l)
            }
        };
        let parent = random_state(&pair.atlas[parent_level], w, h, &bits);
        // Windowed synthesis: the jitter hashes absolute (even-cornered)
        // coordinates.
        let origin = [bits[1] % 65536 * 2, bits[2] % 65536 * 2];
        let p = UpsampleParams { seed, level: level as u32, jitter, step, origin };
        check_upsample(pair, &parent, (cw.max(2), ch.max(2)), level, &p);
    }

    #[test]
    fn reconstruct_matches_on_random_states(
        w in 2usize..64, h in 2usize..64,
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let Some(pair) = default_pair() else { return Ok(()) };
        check_reconstruct(pair, &random_state(&pair.atlas[0], w, h, &bits));
    }
}

/// Every stage on the real states of one synthesis: each kept level is
/// upsampled, corrected (every subpass) and, at level 0, reconstructed on
/// both backends from the same CPU state.
fn check_real_states(db: &Database, ctx: Arc<Context>, (w, h): (usize, usize), seed: u32) {
    let pair = Pair::new(db, ctx);
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let synth = Synthesizer::new(db, params).unwrap();
    let out = synth.run(w, h, seed).unwrap();
    let l = db.level_count() - 1;
    for maps in out.levels.iter().filter(|m| !m.coords.is_empty()) {
        let st = state_from(maps.width, maps.height, &maps.coords, &maps.offsets);
        let parent = out
            .levels
            .get(maps.level + 1)
            .filter(|m| !m.coords.is_empty());
        let parent = parent.map(|m| state_from(m.width, m.height, &m.coords, &m.offsets));
        if maps.level <= l {
            for (k, &(px, py)) in SUBPASSES.iter().enumerate() {
                let what = format!("real state, level {}, subpass {k}", maps.level);
                let p = CorrectParams {
                    px,
                    py,
                    prior: DEFAULT_PRIOR,
                };
                check_correct(&pair, maps.level, (&st, parent.as_ref()), &p, &what);
            }
        }
        if maps.level >= 1 && maps.level <= l {
            let level = maps.level - 1;
            let child = terrasynth::synth::state::level_size(w, h, level);
            let p = UpsampleParams {
                seed,
                level: level as u32,
                jitter: 102,
                step: Step::Pyramid,
                origin: [0, 0],
            };
            check_upsample(&pair, &st, child, level, &p);
        }
        if maps.level == 0 {
            check_reconstruct(&pair, &st);
        }
    }
}

#[test]
fn every_stage_matches_on_real_states_of_the_default_database() {
    let Some(ctx) = ctx() else { return };
    check_real_states(default_db(), ctx, (256, 192), 3);
}

#[test]
fn every_stage_matches_on_real_states_of_shared_dems() {
    let (Some(ctx), Some(db)) = (ctx(), dem_db()) else {
        return;
    };
    check_real_states(db, ctx, (200, 256), 11);
}

/// A whole synthesis: same heights (bit patterns), same kept levels.
fn check_end_to_end(db: &Database, ctx: Arc<Context>, (w, h): (usize, usize), seed: u32) {
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let cpu = Synthesizer::new(db, params.clone()).unwrap();
    let mut gpu = Synthesizer::new(db, params).unwrap();
    gpu.use_gpu(ctx).unwrap();
    assert_eq!((cpu.backend_name(), gpu.backend_name()), ("cpu", "gpu"));
    let (a, b) = (cpu.run(w, h, seed).unwrap(), gpu.run(w, h, seed).unwrap());
    for (la, lb) in a.levels.iter().zip(&b.levels) {
        assert_states_eq(
            &(lb.coords.clone(), lb.offsets.clone()),
            &(la.coords.clone(), la.offsets.clone()),
            &format!("level {} after synthesis", la.level),
        );
    }
    let bits = |s: &terrasynth::synth::Synthesis| -> Vec<u32> {
        s.heightfield.data().iter().map(|v| v.to_bits()).collect()
    };
    assert_eq!(bits(&a), bits(&b), "output heights");
}

#[test]
fn end_to_end_synthesis_is_identical() {
    let Some(ctx) = ctx() else { return };
    check_end_to_end(default_db(), ctx.clone(), (256, 256), 1);
    check_end_to_end(default_db(), ctx, (173, 61), 77);
}

#[test]
fn end_to_end_synthesis_of_shared_dems_is_identical() {
    let (Some(ctx), Some(db)) = (ctx(), dem_db()) else {
        return;
    };
    check_end_to_end(db, ctx, (256, 200), 5);
}
