//! Procedural toolbox: fBm synthesis and one step of each erosion at 1024²,
//! and the generation of each default style at its committed size.
//! Bench ids follow `<stage>/<backend>/<size>`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use terrasynth::Heightfield;
use terrasynth::procedural::fluvial::Routing;
use terrasynth::procedural::styles::{DEFAULT_SEED, DEFAULT_SIZE};
use terrasynth::procedural::*;
use terrasynth::progress::Silent;

const N: usize = 1024;
const CELL: f64 = 30.0;

fn fbm_field(f: &Fractal) -> Heightfield {
    let a = f.amplitude_sum();
    Heightfield::from_fn(N, N, CELL, |x, y| {
        (1500.0 * f.sample(x as f64 * CELL, y as f64 * CELL) / a) as f32
    })
    .unwrap()
}

fn terrain() -> Heightfield {
    fbm_field(&Fractal {
        octaves: 8,
        h: 0.8,
        ..Fractal::new(1, 1.0 / 8000.0)
    })
}

fn fbm(c: &mut Criterion) {
    let f = Fractal::new(1, 1.0 / 8000.0);
    c.bench_function("fbm/cpu/1024", |b| b.iter(|| fbm_field(black_box(&f))));
}

fn erosion(c: &mut Criterion) {
    let hf = terrain();
    let mut g = c.benchmark_group("erosion");
    g.sample_size(20);
    let talus = ThermalParams {
        talus: 0.7,
        rate: 0.5,
        variation: 0.0,
        seed: 0,
    };
    g.bench_function("thermal/cpu/1024", |b| {
        b.iter_batched_ref(
            || hf.clone(),
            |h| thermal_erode(h, &talus, 1, &Silent).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    let water = HydraulicParams {
        rain: 0.01,
        evaporation: 0.02,
        flow_rate: 0.125,
        capacity: 2.0,
        dissolve: 0.3,
        deposit: 0.3,
        boundary: Boundary::Open,
    };
    let mut sim = Hydraulic::new(&hf, water).unwrap();
    g.bench_function("hydraulic/cpu/1024", |b| b.iter(|| sim.step()));
    let rivers = FluvialParams {
        erodibility: 0.05,
        epsilon: 0.01,
        routing: Routing::Random(1),
    };
    g.bench_function("fluvial/cpu/1024", |b| {
        b.iter_batched_ref(
            || hf.clone(),
            |h| fluvial_erode(h, &rivers, None, 1, &Silent).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    g.bench_function("creep/cpu/1024", |b| {
        b.iter_batched_ref(
            || hf.clone(),
            |h| creep(h, 0.5, 1, &Silent).unwrap(),
            criterion::BatchSize::LargeInput,
        )
    });
    g.finish();
}

fn styles(c: &mut Criterion) {
    let mut g = c.benchmark_group("style");
    g.sample_size(10);
    for s in Style::ALL {
        g.bench_function(format!("{}/cpu/{DEFAULT_SIZE}", s.name()), |b| {
            b.iter(|| s.generate(DEFAULT_SIZE, DEFAULT_SEED, &Silent).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, fbm, erosion, styles);
criterion_main!(benches);
