//! CPU ≡ GPU, byte for byte, for the guided correction (DESIGN §6): the
//! `correct` stage under control — point/curve targets with tolerances,
//! painted types, frozen pixels and coherence weights — on random guides
//! and on guides a real scene produces, over a typed database of two real
//! DEM crops, at every height prior weight.
//!
//! Needs `--features gpu` and a Vulkan adapter (lavapipe will do: Debian
//! package `mesa-vulkan-drivers`); without one every test prints why and
//! passes without checking anything. Split from `backend_control.rs` (the
//! control pyramids and the end-to-end session), which shares no set-up
//! with it.
#![cfg(feature = "gpu")]

use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;
use terrasynth::backend::Backend;
use terrasynth::backend::gpu::Gpu;
use terrasynth::database::{self, BuildOptions, Database, layout::MARGIN};
use terrasynth::io::type_mask::TypeMask;
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::control::UNCONSTRAINED;
use terrasynth::synth::control::blend::{MAX_TOL, Target};
use terrasynth::synth::fixed::{Coord, FRAC_BITS};
use terrasynth::synth::stages::correct::{
    self as correct, ALL_TYPES, Coherence, CorrectParams, DEFAULT_PRIOR, Guide, PRIORS, SUBPASSES,
    scalar,
};
use terrasynth::synth::stages::reduce_types::reduce_types;
use terrasynth::synth::stages::reduce_weights::reduce_weights;
use terrasynth::synth::state::{State, level_size};
use terrasynth::synth::{Guides, LevelGuide, Params, Synthesizer};

mod common;
use common::dem::{self, DEM};

/// Two 160² crops of real DEMs with their type masks (so the database has
/// types and seeds), or `None` when ../shared/dem is absent.
fn typed_db() -> Option<&'static Database> {
    static DB: OnceLock<Option<Database>> = OnceLock::new();
    DB.get_or_init(|| {
        let crop = |name: &str, x: usize, y: usize| dem::exemplar(name, (x, y, 160, 160), true);
        let inputs = vec![
            crop("riviera_coast", 100, 150)?,
            crop("pyrenees_andorra", 300, 200)?,
        ];
        let opts = BuildOptions {
            levels: 4,
            ..Default::default()
        };
        Some(database::build(inputs, &opts, &Silent).unwrap().0)
    })
    .as_ref()
    .or_else(|| {
        eprintln!("{DEM} not found: real-guide correct cross-checks skipped");
        None
    })
}

fn copy(st: &State) -> State {
    let c = State::new(st.width, st.height);
    for i in 0..st.width * st.height {
        c.set(i, st.s(i), st.v(i));
    }
    c
}

/// One guided subpass on the GPU, the CPU (SIMD + scalar frame) and the
/// scalar oracle from the same state; all three must agree.
fn check_guided(
    gpu: &Gpu,
    atlas: &AtlasLevel<'_>,
    level: usize,
    (st, parent): (&State, Option<&State>),
    p: &CorrectParams,
    g: &Guide<'_>,
    what: &str,
) {
    let gs = gpu.upload(copy(st)).unwrap();
    let gp = parent.map(|pa| gpu.upload(copy(pa)).unwrap());
    let gg = gpu.upload_guide(g, st.width, st.height).unwrap();
    gpu.correct_guided(&gs, gp.as_ref(), level, p, &gg);
    let (gc, gv) = gpu.download(&gs).unwrap();
    let cpu = copy(st);
    correct::correct_guided(atlas, &cpu, parent, p, g);
    let oracle = copy(st);
    scalar::correct_guided(atlas, &oracle, parent, p, g);
    assert_eq!(
        (oracle.coords(), oracle.offsets()),
        (cpu.coords(), cpu.offsets()),
        "{what}: CPU paths differ"
    );
    let (cc, cv) = (cpu.coords(), cpu.offsets());
    if let Some(i) = (0..cc.len()).find(|&i| gc[i] != cc[i] || gv[i] != cv[i]) {
        panic!(
            "{what}: pixel {i}: GPU {:?} V {} vs CPU {:?} V {}",
            gc[i], gv[i], cc[i], cv[i]
        );
    }
}

/// What the synthesis guarantees of a state: every coordinate rounds into
/// an exemplar's interior, its fraction in [−½, ½) texel.
fn random_state(atlas: &AtlasLevel<'_>, w: usize, h: usize, bits: &[u32], salt: u32) -> State {
    let rects = &atlas.level.layout.rects;
    let st = State::new(w, h);
    for i in 0..w * h {
        let b =
            |k: usize| bits[(4 * i + k) % bits.len()] ^ (i as u32 ^ salt).wrapping_mul(0x9E37_79B9);
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

fn typed_gpu() -> Option<(
    &'static Database,
    &'static Vec<AtlasLevel<'static>>,
    &'static Gpu,
)> {
    static G: OnceLock<Option<(Vec<AtlasLevel<'static>>, Gpu)>> = OnceLock::new();
    let db = typed_db()?;
    let g = G.get_or_init(|| {
        let ctx = common::gpu::context()?;
        let atlas: Vec<_> = (0..db.level_count())
            .map(|i| AtlasLevel::new(db, i))
            .collect();
        let gpu = Gpu::new(ctx, &atlas, db.heights()).unwrap();
        Some((atlas, gpu))
    });
    g.as_ref().map(|(a, g)| (db, a, g))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Random states, targets (some unconstrained, tolerances 0..MAX_TOL,
    /// far-off heights), type sets (none, one or several types, empty
    /// sets forcing seeding), previous results with weights 0..=5, and
    /// windows: every control path of the kernel.
    #[test]
    fn guided_correct_matches_on_random_guides(
        w in 2usize..40, h in 2usize..40, level_pick in 0usize..8, sub in 0usize..4,
        flags in 0u32..8, windowed in any::<bool>(),
        bits in prop::collection::vec(any::<u32>(), 64),
    ) {
        let Some((db, atlas, gpu)) = typed_gpu() else { return Ok(()) };
        let level = level_pick % atlas.len();
        let a = &atlas[level];
        let st = random_state(a, w, h, &bits, 0);
        let prev = random_state(a, w, h, &bits, 0x51);
        let types = db.type_names().len() as u32;
        let b = |i: usize, k: u32| bits[(i * 3 + k as usize) % bits.len()] ^ (i as u32).wrapping_mul(0x2545_F491) ^ k;
        let targets: Vec<Target> = (0..w * h).map(|i| {
            let r = b(i, 1);
            if r % 4 == 0 { Target::NONE } else {
                Target { height: (r >> 8) as i32 % 90_000 - 10_000, tol: (b(i, 2) % (MAX_TOL as u32 + 1)) as i32 }
            }
        }).collect();
        let allowed: Vec<u32> = (0..w * h).map(|i| match b(i, 3) % 5 {
            0 => ALL_TYPES,
            1 => 1 << (b(i, 4) % types.max(1)),
            2 => b(i, 4) & ((1 << types) - 1),
            3 => 0,
            _ => b(i, 4),
        }).collect();
        let weights: Vec<u8> = (0..w * h).map(|i| (b(i, 5) % 6) as u8).collect();
        let (coords, offsets) = (prev.coords(), prev.offsets());
        let window = windowed.then(|| {
            let (x0, y0) = (b(0, 6) as usize % w, b(0, 7) as usize % h);
            [x0, y0, x0 + 1 + b(0, 8) as usize % w, y0 + 1 + b(0, 9) as usize % h]
        });
        let g = Guide {
            level: level as u32,
            targets: (flags & 1 != 0).then_some(&targets[..]),
            allowed: (flags & 2 != 0).then_some(&allowed[..]),
            coherence: (flags & 4 != 0).then_some(Coherence { coords: &coords, offsets: &offsets, weights: &weights }),
            window,
            // Windowed synthesis: type seeding hashes absolute coordinates.
            origin: [b(0, 10) % 65536 * 2, b(0, 11) % 65536 * 2],
        };
        let (px, py) = SUBPASSES[sub];
        let parent = random_state(a, w.div_ceil(2), h.div_ceil(2), &bits, 0x5EED);
        let prior = PRIORS[bits[5] as usize % PRIORS.len()];
        let p = CorrectParams { px, py, prior };
        let what = format!("random {w}×{h} level {level} flags {flags} prior {prior}");
        check_guided(gpu, a, level, (&st, Some(&parent)), &p, &g, &what);
    }
}

/// Real guides: a two-frame controlled synthesis of the typed DEM database
/// (R⁰ from a real type mask, targets from real heights, W⁰ from the mask's
/// regions); every kept level of frame 2 is corrected (each subpass) under
/// its level's guide and frame 1's results on both backends.
#[test]
fn guided_correct_matches_on_real_guides() {
    let Some((db, atlas, gpu)) = typed_gpu() else {
        return;
    };
    let (w, h) = (160, 128);
    let m = TypeMask::read(&Path::new(DEM).join("riviera_coast_types.png")).unwrap();
    let hf = terrasynth::io::read(
        &Path::new(DEM).join("riviera_coast.png"),
        &Default::default(),
    )
    .unwrap();
    let (ox, oy) = (200, 260);
    let full = ((1u64 << db.type_names().len()) - 1) as u32;
    let l = db.level_count() - 1;
    let mut levels = Vec::new();
    let (lw, lh) = level_size(w, h, 0);
    let mut allowed: Vec<u32> = (0..lw * lh)
        .map(|k| {
            let (x, y) = (k % lw, k / lw);
            let t = m.indices[(oy + y.min(h - 1)) * m.width + ox + x.min(w - 1)];
            if t == UNCONSTRAINED || t as usize >= db.type_names().len() {
                ALL_TYPES
            } else {
                1 << t
            }
        })
        .collect();
    let mut weights: Vec<u8> = (0..lw * lh)
        .map(|k| (allowed[k].trailing_zeros() % 3) as u8 * 2)
        .collect();
    for i in 0..=l {
        let (cw, ch) = level_size(w, h, i);
        if i > 0 {
            let (pw, ph) = level_size(w, h, i - 1);
            allowed = reduce_types(&allowed, pw, ph, cw, ch, full);
            weights = reduce_weights(&weights, pw, ph, cw, ch);
        }
        let targets: Vec<Target> = (0..cw * ch)
            .map(|k| {
                let (x, y) = ((k % cw) << i, (k / cw) << i);
                let v = hf.data()[(oy + y.min(h - 1)) * hf.width() + ox + x.min(w - 1)];
                if x < w / 2 {
                    Target::NONE
                } else {
                    Target {
                        height: (v * 20.0) as i32,
                        tol: (y as i32 * 50).min(MAX_TOL),
                    }
                }
            })
            .collect();
        levels.push(LevelGuide {
            targets: Some(targets),
            allowed: Some(allowed.clone()),
            weights: Some(weights.clone()),
            dirty: None,
        });
    }
    let guides = Guides {
        levels,
        restrict: false,
    };
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let synth = Synthesizer::new(db, params).unwrap();
    let (_, f1) = synth.run_with(w, h, 9, &guides, None, true).unwrap();
    let f1 = f1.unwrap();
    let (out, _) = synth.run_with(w, h, 9, &guides, Some(&f1), false).unwrap();
    let mut checked = 0;
    for maps in out
        .levels
        .iter()
        .filter(|m| m.level <= l && !m.coords.is_empty())
    {
        let i = maps.level;
        let from = |m: &terrasynth::synth::LevelMaps| {
            let st = State::new(m.width, m.height);
            for k in 0..m.width * m.height {
                st.set(k, m.coords[k], m.offsets[k]);
            }
            st
        };
        let st = from(maps);
        let parent = out
            .levels
            .get(i + 1)
            .filter(|m| !m.coords.is_empty())
            .map(from);
        let lg = &guides.levels[i];
        let r = &f1.levels[i][0];
        let g = Guide {
            level: i as u32,
            targets: lg.targets.as_deref(),
            allowed: lg.allowed.as_deref(),
            coherence: Some(Coherence {
                coords: &r.coords,
                offsets: &r.offsets,
                weights: lg.weights.as_deref().unwrap(),
            }),
            window: None,
            origin: [0, 0],
        };
        // With frame 1's results, and without (a first frame: every pixel
        // picks a k-coherence candidate or a seed, then is nudged).
        let first = Guide {
            coherence: None,
            ..g
        };
        for (s, &(px, py)) in SUBPASSES.iter().enumerate() {
            for (g, frame) in [(&g, 2), (&first, 1)] {
                check_guided(
                    gpu,
                    &atlas[i],
                    i,
                    (&st, parent.as_ref()),
                    &CorrectParams {
                        px,
                        py,
                        prior: DEFAULT_PRIOR,
                    },
                    g,
                    &format!("real guide, frame {frame}, level {i}, subpass {s}"),
                );
            }
            checked += 1;
        }
    }
    assert!(checked >= 4 * (l + 1), "only {checked} subpasses checked");
}
