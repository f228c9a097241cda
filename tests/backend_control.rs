//! CPU ≡ GPU, byte for byte, for the control pyramids (DESIGN §6): stages
//! `reduce_types` and `reduce_weights` on random rasters (proptest, odd and
//! even sizes, every value a u8/u32 can hold) and on real ones (the type
//! masks of every ../shared/dem DEM, reduced to the top of the pyramid as a
//! session does).
//!
//! Needs `--features gpu` and a Vulkan adapter (lavapipe will do: Debian
//! package `mesa-vulkan-drivers`); without one every test prints why and
//! passes without checking anything.
#![cfg(feature = "gpu")]

use proptest::prelude::*;
use std::path::Path;
use std::sync::OnceLock;
use terrasynth::backend::gpu::Gpu;
use terrasynth::backend::{Backend, BackendError, cpu::Cpu};
use terrasynth::database::{self, BuildOptions, Database, default, layout::MARGIN};
use terrasynth::io::type_mask::TypeMask;
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::control::UNCONSTRAINED;
use terrasynth::synth::control::blend::{MAX_TOL, Target};
use terrasynth::synth::fixed::{Coord, FRAC_BITS};
use terrasynth::synth::stages::correct::{
    self as correct, ALL_TYPES, Coherence, CorrectParams, DEFAULT_PRIOR, Guide, PRIORS, SUBPASSES,
    W_FREE, scalar,
};
use terrasynth::synth::stages::reduce_types::reduce_types;
use terrasynth::synth::stages::reduce_weights::reduce_weights;
use terrasynth::synth::state::{State, level_size, top_level};
use terrasynth::synth::{Guides, LevelGuide, Params, Synthesizer};

mod common;
use common::dem::{self, DEM};

/// Both backends over the default database (the reductions read none of
/// it, but a backend is bound to one).
struct Pair {
    atlas: Vec<AtlasLevel<'static>>,
    heights: &'static [u16],
    gpu: Gpu,
}

impl Pair {
    fn cpu(&self) -> Cpu<'_, 'static> {
        Cpu {
            atlas: &self.atlas,
            heights: self.heights,
        }
    }
}

/// The default database, built once.
static DB_DEFAULT: OnceLock<Database> = OnceLock::new();

/// The shared pair, or `None` without an adapter (see `common::gpu`).
fn pair() -> Option<&'static Pair> {
    static PAIR: OnceLock<Option<Pair>> = OnceLock::new();
    PAIR.get_or_init(|| {
        let ctx = common::gpu::context()?;
        let db = DB_DEFAULT.get_or_init(|| default::build_default(&Silent).unwrap());
        let atlas: Vec<_> = (0..db.level_count())
            .map(|i| AtlasLevel::new(db, i))
            .collect();
        let gpu = Gpu::new(ctx, &atlas, db.heights()).unwrap();
        Some(Pair {
            atlas,
            heights: db.heights(),
            gpu,
        })
    })
    .as_ref()
}

/// Reduces `r0` (`w × h`) level by level on both backends, with the level
/// sizes of a synthesis (`level_size`, at least 2 × 2, so the top levels
/// have pixels without children) one past its top, the GPU's rasters staying
/// on the device; every level must match. Returns how many levels were
/// compared.
fn check_types(pair: &Pair, r0: &[u32], (w, h): (usize, usize), full: u32, what: &str) -> usize {
    let cpu = pair.cpu();
    let mut c = cpu.upload_types(r0, w, h).unwrap();
    let mut g = pair.gpu.upload_types(r0, w, h).unwrap();
    assert_eq!(pair.gpu.download_types(&g).unwrap(), r0, "{what}: upload");
    let top = top_level(w, h) + 1;
    for level in 1..=top {
        let (lw, lh) = level_size(w, h, level);
        c = cpu.reduce_types(&c, lw, lh, full).unwrap();
        g = pair.gpu.reduce_types(&g, lw, lh, full).unwrap();
        let gd = pair.gpu.download_types(&g).unwrap();
        if let Some(i) = (0..c.data.len()).find(|&i| gd[i] != c.data[i]) {
            panic!(
                "{what}: reduce_types to level {level} ({lw}×{lh}): pixel {i}: GPU {:#x} vs CPU {:#x}",
                gd[i], c.data[i]
            );
        }
        assert_eq!(gd, c.data, "{what}: level {level}");
    }
    top
}

/// [`check_types`] for coherence weights.
fn check_weights(pair: &Pair, w0: &[u8], (w, h): (usize, usize), what: &str) -> usize {
    let cpu = pair.cpu();
    let mut c = cpu.upload_weights(w0, w, h).unwrap();
    let mut g = pair.gpu.upload_weights(w0, w, h).unwrap();
    assert_eq!(pair.gpu.download_weights(&g).unwrap(), w0, "{what}: upload");
    let top = top_level(w, h) + 1;
    for level in 1..=top {
        let (lw, lh) = level_size(w, h, level);
        c = cpu.reduce_weights(&c, lw, lh).unwrap();
        g = pair.gpu.reduce_weights(&g, lw, lh).unwrap();
        let gd = pair.gpu.download_weights(&g).unwrap();
        if let Some(i) = (0..c.data.len()).find(|&i| gd[i] != c.data[i]) {
            panic!(
                "{what}: reduce_weights to level {level} ({lw}×{lh}): pixel {i}: GPU {} vs CPU {}",
                gd[i], c.data[i]
            );
        }
        assert_eq!(gd, c.data, "{what}: level {level}");
    }
    top
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    /// Sets drawn so that every branch is hit: ALL_TYPES, `full` itself,
    /// supersets of `full`, single types, empty sets and arbitrary words.
    #[test]
    fn reduce_types_matches_on_random_rasters(
        w in 1usize..70, h in 1usize..70, types in 1u32..=32,
        picks in prop::collection::vec((0u32..6, any::<u32>()), 1..128),
    ) {
        let Some(pair) = pair() else { return Ok(()) };
        let full = if types == 32 { u32::MAX } else { (1u32 << types) - 1 };
        let r0: Vec<u32> = (0..w * h)
            .map(|i| {
                let (kind, bits) = picks[(i * 7 + i / w) % picks.len()];
                let bits = bits ^ (i as u32).wrapping_mul(0x9E37_79B9);
                match kind {
                    0 => ALL_TYPES,
                    1 => full,
                    2 => full | bits,
                    3 => 1 << (bits % types),
                    4 => 0,
                    _ => bits,
                }
            })
            .collect();
        check_types(pair, &r0, (w, h), full, &format!("random {w}×{h}, {types} types"));
    }

    /// Weights over 0..=6 (values above 4 clamp) and any byte, with ties of
    /// every kind among the 2×2 children.
    #[test]
    fn reduce_weights_matches_on_random_rasters(
        w in 1usize..70, h in 1usize..70, wide in any::<bool>(),
        picks in prop::collection::vec(any::<u8>(), 1..128),
    ) {
        let Some(pair) = pair() else { return Ok(()) };
        let w0: Vec<u8> = (0..w * h)
            .map(|i| {
                let b = picks[(i * 5 + i / w) % picks.len()] ^ (i as u8).wrapping_mul(37);
                if wide { b } else { b % 7 }
            })
            .collect();
        check_weights(pair, &w0, (w, h), &format!("random {w}×{h}"));
    }
}

/// Raster lengths that are not width × height are a typed error on both
/// backends, never an out-of-bounds read.
#[test]
fn mis_sized_rasters_are_rejected() {
    let Some(pair) = pair() else { return };
    let cpu = pair.cpu();
    let bad = |r: Result<(), BackendError>| {
        assert!(
            matches!(
                r,
                Err(BackendError::RasterSize {
                    len: 5,
                    width: 2,
                    height: 3,
                    ..
                })
            ),
            "{r:?}"
        )
    };
    bad(cpu.upload_types(&[0; 5], 2, 3).map(|_| ()));
    bad(pair.gpu.upload_types(&[0; 5], 2, 3).map(|_| ()));
    bad(cpu.upload_weights(&[0; 5], 2, 3).map(|_| ()));
    bad(pair.gpu.upload_weights(&[0; 5], 2, 3).map(|_| ()));
}

/// The type mask of every shared DEM as a session paints it (R⁰ = one type
/// per pixel, unconstrained where the mask has none), and a W⁰ drawn from
/// the same regions (type 0 frozen, type 1 free, the rest coherent), both
/// reduced to the top of the pyramid on both backends.
#[test]
fn reductions_match_on_shared_dem_type_masks() {
    let Some(pair) = pair() else { return };
    let dir = Path::new(DEM);
    if !dir.exists() {
        eprintln!("{DEM} not found: real-mask reduction cross-check skipped");
        return;
    }
    let mut used = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if !name.ends_with("_types.png") {
            continue;
        }
        let m = TypeMask::read(&path).unwrap();
        let types = m.indices.iter().filter(|&&t| t != UNCONSTRAINED).max();
        let count = types.map_or(1, |&t| t as u32 + 1).min(32);
        let full = if count == 32 {
            u32::MAX
        } else {
            (1 << count) - 1
        };
        let r0: Vec<u32> = m
            .indices
            .iter()
            .map(|&t| {
                if t == UNCONSTRAINED || t >= 32 {
                    ALL_TYPES
                } else {
                    1 << t
                }
            })
            .collect();
        let w0: Vec<u8> = m
            .indices
            .iter()
            .map(|&t| match t {
                0 => 0,
                1 => W_FREE,
                _ => 1,
            })
            .collect();
        let size = (m.width, m.height);
        let levels = check_types(pair, &r0, size, full, &name);
        assert_eq!(check_weights(pair, &w0, size, &name), levels);
        assert!(levels >= 6, "{name}: only {levels} levels");
        used += 1;
    }
    assert!(used >= 4, "only {used} type masks in {DEM}");
}

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

/// End to end: the Fig. 11-style design of `data/scenes/` (curves with
/// junctions, a point, painted types, a frozen region, a paste) and its
/// edit, as an editing session on each backend: every frame's heights and
/// every level's per-pass results must be the same bytes. The second frame
/// is a restricted coherent re-synthesis, so the window path of `correct`
/// (pixels outside take the previous result) runs on the device too.
#[test]
fn scene_session_matches_end_to_end() {
    use terrasynth::scene::{Scene, SceneEdits};
    use terrasynth::synth::session::Session;
    let Some(pair) = pair() else { return };
    let db = DB_DEFAULT.get_or_init(|| default::build_default(&Silent).unwrap());
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/scenes");
    let scenes: Vec<Scene> = ["canyonlands.json", "canyonlands_edit1.json"]
        .iter()
        .map(|f| Scene::read(&dir.join(f)).unwrap())
        .collect();
    let base = &scenes[0];
    let run = |gpu: bool| {
        let mut session = Session::new(
            db,
            SceneEdits::params(base),
            base.width,
            base.height,
            base.seed,
        )
        .unwrap();
        if gpu {
            session
                .synthesizer_mut()
                .use_gpu(pair.gpu.context().clone())
                .unwrap();
        }
        assert_eq!(
            session.synthesizer().backend_name(),
            if gpu { "gpu" } else { "cpu" }
        );
        let mut edits = SceneEdits::new();
        scenes
            .iter()
            .map(|s| {
                let list = edits.edits(s, db).unwrap();
                let f = session.apply(list).unwrap();
                (f, session.frames().cloned().unwrap())
            })
            .collect::<Vec<_>>()
    };
    let cpu = run(false);
    let gpu = run(true);
    for (k, ((c, cf), (g, gf))) in cpu.iter().zip(&gpu).enumerate() {
        let (a, b) = (c.heightfield.data(), g.heightfield.data());
        if let Some(i) = (0..a.len()).find(|&i| a[i].to_bits() != b[i].to_bits()) {
            panic!("frame {k}: pixel {i}: GPU {} m vs CPU {} m", b[i], a[i]);
        }
        for (level, (cl, gl)) in cf.levels.iter().zip(&gf.levels).enumerate() {
            assert!(
                cl == gl,
                "frame {k}: level {level}: per-pass results differ"
            );
        }
        assert_eq!(c.change, g.change, "frame {k}: change report");
    }
    let changed = cpu[1].0.change.as_ref().unwrap().pixels;
    assert!(changed > 0, "the edit must change the terrain");
}
