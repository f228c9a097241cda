//! Every stage on its own, one criterion group per WGSL kernel
//! (`<stage>/<variant>/<size>`), on inputs from the embedded default
//! database, so the bench always runs:
//!
//! - `upsample_jitter`, `correct` (one subpass), `reconstruct`: the real
//!   level states of a 1024² synthesis (level 1 → 0, level 0);
//! - `reduce_types`, `reduce_weights`: the 512² type mask of the embedded
//!   `catalan_coast_hills` exemplar (the one with all four types) as a
//!   session paints it (R⁰, and W⁰ from its regions), reduced one level;
//! - `shade`: the preview of the 1024² synthesis;
//! - `fill_ssd`: every fill candidate of the `pyrenees_andorra` exemplar
//!   (mountains, as sketches ask for) as a patch source, under every
//!   transform, against a half-filled window of it.
//!
//! Variants as in `tests/stages/<x>.rs`: `scalar` (the oracle, where the
//! CPU has a SIMD path), `simd` or `cpu` (at the default instruction-set
//! level, `isa::Isa::default`: `TERRASYNTH_PORTABLE_SIMD=1` benches the
//! portable copy), and with `--features gpu` and an adapter `gpu` (each
//! call waits for the device); without one the GPU variants are skipped
//! with a message. One group per stage of `stages::Stage::ALL`. Whole
//! syntheses: `benches/synth.rs`.

use criterion::{
    BenchmarkGroup, Criterion, criterion_group, criterion_main, measurement::WallTime,
};
use rayon::prelude::*;
use std::hint::black_box;
use std::path::Path;
use terrasynth::backend::{Backend, cpu::Cpu};
use terrasynth::database::{Database, default};
use terrasynth::io::maps::type_mask::TypeMask;
use terrasynth::level::atlas::AtlasLevel;
use terrasynth::level::state::State;
use terrasynth::patch::fill::hole_fill::user_cells;
use terrasynth::patch::place::candidates::{COARSE, PreparedSource};
use terrasynth::progress::Silent;
use terrasynth::render::{self, RenderOptions};
use terrasynth::stages::common::ALL_TYPES;
use terrasynth::stages::correct::{self, CorrectParams, W_FREE};
use terrasynth::stages::fill_ssd::{fill_ssd_scalar, fill_ssd_table};
use terrasynth::stages::upsample_jitter::{Step, UpsampleParams};
use terrasynth::stages::{
    Stage, reconstruct, reduce_types, reduce_weights, shade, upsample_jitter,
};
use terrasynth::synth::control::UNCONSTRAINED;
use terrasynth::synth::{Params, Synthesizer};

/// Side of the synthesis whose levels the level stages run on.
const N: usize = 1024;

/// The inputs, prepared once.
struct Inputs {
    db: Database,
    /// Levels 0 and 1 of an `N²` synthesis.
    l0: State,
    l1: State,
    /// Its heights, prepared for `shade`.
    preview: render::Prepared,
    /// R⁰ and W⁰ (`mask_w × mask_h`) and every type's bit.
    types: Vec<u32>,
    weights: Vec<u8>,
    mask_size: (usize, usize),
    full: u32,
    /// One fill window's user cells and masks per transform, and its
    /// valid count; a source's candidate cells.
    user: Vec<Vec<i32>>,
    masks: Vec<Vec<i32>>,
    count: i64,
    cells: Vec<i32>,
}

fn inputs() -> Inputs {
    let db = default::build_default(&Silent).unwrap();
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let out = Synthesizer::new(&db, params).unwrap().run(N, N, 1).unwrap();
    let load = |l: usize| {
        let m = &out.levels[l];
        let st = State::new(m.width, m.height);
        for i in 0..m.width * m.height {
            st.set(i, m.coords[i], m.offsets[i]);
        }
        st
    };
    let preview = render::prepare(&out.heightfield, &RenderOptions::default()).unwrap();

    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/exemplars");
    let mask =
        TypeMask::read(&data.join("catalan_coast_hills/catalan_coast_hills_types.png")).unwrap();
    let last = mask.indices.iter().filter(|&&t| t != UNCONSTRAINED).max();
    let full = (1u32 << last.map_or(1, |&t| t as u32 + 1)) - 1;
    let types = mask
        .indices
        .iter()
        .map(|&t| {
            if t == UNCONSTRAINED {
                ALL_TYPES
            } else {
                1 << t
            }
        })
        .collect();
    let weights = mask
        .indices
        .iter()
        .map(|&t| match t {
            0 => 0,
            1 => W_FREE,
            _ => 1,
        })
        .collect();

    let hf = terrasynth::io::read(
        &data.join("pyrenees_andorra/pyrenees_andorra.png"),
        &Default::default(),
    )
    .unwrap();
    let patch = terrasynth::patch::Params::default();
    let src = PreparedSource::prepare("pyrenees_andorra", &hf, &patch, 1.0).unwrap();
    let m = patch.patch / COARSE;
    let mut cells: Vec<i32> = (0..m * m)
        .map(|i| src.coarse[(20 + i / m) * src.coarse_w + 30 + i % m])
        .collect();
    let valid: Vec<bool> = (0..m * m).map(|i| i % m < m / 2).collect();
    let (user, masks, count) = user_cells(&mut cells, &valid, m);

    Inputs {
        l0: load(0),
        l1: load(1),
        db,
        preview,
        types,
        weights,
        mask_size: (mask.width, mask.height),
        full,
        user,
        masks,
        count,
        cells: src.fill_cells,
    }
}

fn bench(c: &mut Criterion) {
    let i = inputs();
    let atlas: Vec<_> = (0..i.db.level_count())
        .map(|l| AtlasLevel::new(&i.db, l))
        .collect();
    let cpu = Cpu::new(&atlas, i.db.heights());
    #[cfg(feature = "gpu")]
    let gpu = match terrasynth::backend::gpu::Context::new() {
        Ok(ctx) => Some(terrasynth::backend::gpu::Gpu::new(ctx, &atlas, i.db.heights()).unwrap()),
        Err(e) => {
            eprintln!("the gpu variants are skipped: {e}");
            None
        }
    };
    let (mw, mh) = i.mask_size;
    let (rw, rh) = (mw.div_ceil(2), mh.div_ceil(2));

    // One group per line of the table of stages: a stage added there
    // does not compile here until it has a group (or a reason not to).
    for stage in Stage::ALL {
        match stage {
            Stage::UpsampleJitter => {
                let up = UpsampleParams {
                    seed: 1,
                    level: 0,
                    jitter: 102,
                    step: Step::Pyramid,
                    origin: [0, 0],
                };
                let mut g = group(c, stage);
                let child = State::new(N, N);
                g.bench_function(format!("cpu/{N}"), |b| {
                    b.iter(|| {
                        upsample_jitter::upsample_jitter(
                            black_box(&i.l1),
                            &child,
                            Some(&atlas[0]),
                            &up,
                            cpu.isa,
                        )
                    })
                });
                #[cfg(feature = "gpu")]
                if let Some(gpu) = &gpu {
                    let (parent, child) =
                        (gpu.upload(copy(&i.l1)).unwrap(), gpu.alloc(N, N).unwrap());
                    g.bench_function(format!("gpu/{N}"), |b| {
                        b.iter(|| {
                            gpu.upsample_jitter(&parent, &child, 0, &up);
                            gpu.finish().unwrap()
                        })
                    });
                }
                g.finish();
            }
            Stage::Correct => {
                let p = CorrectParams {
                    px: 0,
                    py: 0,
                    prior: correct::DEFAULT_PRIOR,
                    similar: true,
                };
                let mut g = group(c, stage);
                g.bench_function(format!("scalar/{N}"), |b| {
                    b.iter(|| {
                        correct::scalar::correct(&atlas[0], black_box(&i.l0), Some(&i.l1), &p)
                    })
                });
                g.bench_function(format!("simd/{N}"), |b| {
                    b.iter(|| cpu.correct(black_box(&i.l0), Some(&i.l1), 0, &p))
                });
                #[cfg(feature = "gpu")]
                if let Some(gpu) = &gpu {
                    let (st, parent) = (
                        gpu.upload(copy(&i.l0)).unwrap(),
                        gpu.upload(copy(&i.l1)).unwrap(),
                    );
                    g.bench_function(format!("gpu/{N}"), |b| {
                        b.iter(|| {
                            gpu.correct(&st, Some(&parent), 0, &p);
                            gpu.finish().unwrap()
                        })
                    });
                }
                g.finish();
            }
            Stage::Reconstruct => {
                let mut g = group(c, stage);
                g.bench_function(format!("cpu/{N}"), |b| {
                    b.iter(|| reconstruct::reconstruct(&atlas[0], i.db.heights(), black_box(&i.l0)))
                });
                #[cfg(feature = "gpu")]
                if let Some(gpu) = &gpu {
                    let st = gpu.upload(copy(&i.l0)).unwrap();
                    g.bench_function(format!("gpu/{N}"), |b| {
                        b.iter(|| gpu.reconstruct(&st).unwrap())
                    });
                }
                g.finish();
            }
            // Fused with `reconstruct` on the CPU and dispatched right after
            // it on the GPU: timed in its group.
            Stage::RepairExtrema => {}
            Stage::ReduceTypes => {
                let mut g = group(c, stage);
                g.bench_function(format!("cpu/{mw}"), |b| {
                    b.iter(|| {
                        reduce_types::reduce_types(black_box(&i.types), mw, mh, rw, rh, i.full)
                    })
                });
                #[cfg(feature = "gpu")]
                if let Some(gpu) = &gpu {
                    let r0 = gpu.upload_types(&i.types, mw, mh).unwrap();
                    g.bench_function(format!("gpu/{mw}"), |b| {
                        b.iter(|| {
                            gpu.reduce_types(&r0, rw, rh, i.full).unwrap();
                            gpu.finish().unwrap()
                        })
                    });
                }
                g.finish();
            }
            Stage::ReduceWeights => {
                let mut g = group(c, stage);
                g.bench_function(format!("cpu/{mw}"), |b| {
                    b.iter(|| reduce_weights::reduce_weights(black_box(&i.weights), mw, mh, rw, rh))
                });
                #[cfg(feature = "gpu")]
                if let Some(gpu) = &gpu {
                    let w0 = gpu.upload_weights(&i.weights, mw, mh).unwrap();
                    g.bench_function(format!("gpu/{mw}"), |b| {
                        b.iter(|| {
                            gpu.reduce_weights(&w0, rw, rh).unwrap();
                            gpu.finish().unwrap()
                        })
                    });
                }
                g.finish();
            }
            Stage::Shade => {
                let (params, buffers) = (&i.preview.params, i.preview.buffers());
                let mut out = vec![0u32; i.preview.heights.len()];
                let mut g = group(c, stage);
                g.bench_function(format!("cpu/{}", params.width), |b| {
                    b.iter(|| shade::shade(params, &buffers, black_box(&mut out)).unwrap())
                });
                #[cfg(feature = "gpu")]
                if let Some(gpu) = &gpu {
                    g.bench_function(format!("gpu/{}", params.width), |b| {
                        b.iter(|| gpu.context().shade(params, &buffers).unwrap())
                    });
                }
                g.finish();
            }
            Stage::FillSsd => {
                let (user, masks, k, cells) = (&i.user, &i.masks, &i.count, &i.cells);
                let n = cells.len() / user[0].len();
                let mut g = group(c, stage);
                // The oracle over the same rayon loop as the table, so that the two
                // differ by SIMD alone.
                g.bench_function(format!("scalar/{n}"), |b| {
                    b.iter(|| {
                        cells
                            .par_chunks(user[0].len())
                            .flat_map_iter(|c| {
                                user.iter()
                                    .zip(masks)
                                    .map(move |(u, m)| fill_ssd_scalar(u, m, c, *k))
                            })
                            .collect::<Vec<u64>>()
                    })
                });
                g.bench_function(format!("simd/{n}"), |b| {
                    b.iter(|| fill_ssd_table(user, masks, black_box(cells), *k))
                });
                #[cfg(feature = "gpu")]
                if let Some(gpu) = &gpu {
                    let ctx = gpu.context();
                    let src = ctx.upload_fill_source(cells, user[0].len()).unwrap();
                    g.bench_function(format!("gpu/{n}"), |b| {
                        b.iter(|| ctx.fill_ssd(&src, user, masks, *k).unwrap())
                    });
                }
                g.finish();
            }
        }
    }
}

/// A group of few samples: the slow variants (the scalar oracle, a
/// software GPU) take seconds each.
fn group(c: &mut Criterion, stage: Stage) -> BenchmarkGroup<'_, WallTime> {
    let mut g = c.benchmark_group(stage.name());
    g.sample_size(10);
    g
}

/// A copy of a host state, for upload (the GPU takes ownership).
#[cfg(feature = "gpu")]
fn copy(st: &State) -> State {
    let c = State::new(st.width, st.height);
    for i in 0..st.width * st.height {
        c.set(i, st.s(i), st.v(i));
    }
    c
}

criterion_group!(benches, bench);
criterion_main!(benches);
