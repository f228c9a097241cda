//! Synthesis on the embedded default database: each stage on its own at
//! 1024² (`upsample_jitter/cpu/1024`, `correct/cpu/1024` — one subpass of
//! level 0 on a real state, `reconstruct/cpu/1024`) and end to end
//! (`synth/cpu/512`, `synth/cpu/1024`; with `--features gpu` and an
//! adapter also `synth/gpu/256..1024`). The CLI's `terrasynth bench` gives
//! the same end-to-end numbers per level.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use terrasynth::database::default;
use terrasynth::progress::Silent;
use terrasynth::synth::atlas::AtlasLevel;
use terrasynth::synth::stages::correct::{self, CorrectParams};
use terrasynth::synth::stages::reconstruct;
use terrasynth::synth::stages::upsample_jitter::{self, Step, UpsampleParams};
use terrasynth::synth::state::State;
use terrasynth::synth::{Params, Synthesizer};

fn bench(c: &mut Criterion) {
    let db = default::build_default(&Silent).unwrap();
    let params = Params {
        keep_levels: true,
        ..Params::default()
    };
    let synth = Synthesizer::new(&db, params).unwrap();
    let out = synth.run(1024, 1024, 1).unwrap();
    let load = |l: usize| {
        let m = &out.levels[l];
        let st = State::new(m.width, m.height);
        for i in 0..m.width * m.height {
            st.set(i, m.coords[i], m.offsets[i]);
        }
        st
    };
    let (l0, l1) = (load(0), load(1));
    let atlas = AtlasLevel::new(&db, 0);

    let mut g = c.benchmark_group("upsample_jitter");
    g.bench_function("cpu/1024", |b| {
        let child = State::new(1024, 1024);
        let p = UpsampleParams {
            seed: 1,
            level: 0,
            jitter: 102,
            step: Step::Pyramid,
            origin: [0, 0],
        };
        b.iter(|| upsample_jitter::upsample_jitter(black_box(&l1), &child, Some(&atlas), &p))
    });
    g.finish();

    let mut g = c.benchmark_group("correct");
    g.sample_size(20);
    let p = CorrectParams {
        px: 0,
        py: 0,
        prior: correct::DEFAULT_PRIOR,
    };
    g.bench_function("cpu/1024", |b| {
        b.iter(|| correct::correct(&atlas, black_box(&l0), Some(&l1), &p))
    });
    g.bench_function("scalar/1024", |b| {
        b.iter(|| correct::scalar::correct(&atlas, black_box(&l0), Some(&l1), &p))
    });
    g.finish();

    let mut g = c.benchmark_group("reconstruct");
    g.bench_function("cpu/1024", |b| {
        b.iter(|| reconstruct::reconstruct(&atlas, db.heights(), black_box(&l0)))
    });
    g.finish();

    let synth = Synthesizer::new(&db, Params::default()).unwrap();
    let mut g = c.benchmark_group("synth");
    g.sample_size(10);
    for n in [512, 1024] {
        g.bench_function(format!("cpu/{n}"), |b| {
            b.iter(|| synth.synthesize(n, n, black_box(1)).unwrap())
        });
    }
    // The same loop on the GPU backend (`--features gpu`): on a real GPU,
    // or lavapipe where there is none (slow: a cross-check device, not a
    // fast one).
    #[cfg(feature = "gpu")]
    match terrasynth::backend::gpu::Context::new() {
        Ok(ctx) => {
            let mut gpu = Synthesizer::new(&db, Params::default()).unwrap();
            gpu.use_gpu(ctx).unwrap();
            for n in [256, 512, 1024] {
                g.bench_function(format!("gpu/{n}"), |b| {
                    b.iter(|| gpu.synthesize(n, n, black_box(1)).unwrap())
                });
            }
        }
        Err(e) => eprintln!("synth/gpu skipped: {e}"),
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
