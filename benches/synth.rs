//! Whole syntheses on the embedded default database: `synth/cpu/512`,
//! `synth/cpu/1024`; with `--features gpu` and an adapter also
//! `synth/gpu/256..1024`. The CLI's `terrasynth bench` gives the same
//! numbers per level. Each stage on its own: `benches/stages.rs`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use terrasynth::database::default;
use terrasynth::progress::Silent;
use terrasynth::synth::{Params, Synthesizer};

fn bench(c: &mut Criterion) {
    let db = default::build_default(&Silent).unwrap();
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
