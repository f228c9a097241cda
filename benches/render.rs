//! The preview renderer on a 1024² DEM end to end (`render/1024`: prepare
//! and shade, and with PNG encoding). The `shade` stage alone:
//! `benches/stages.rs`.
//!
//! Uses the shared 1024² Olympic Peninsula DEM when `../shared/dem` is
//! present, otherwise (with a message) a synthetic 1024² terrain of the same
//! relief, so the bench always runs.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use terrasynth::Heightfield;
use terrasynth::render::{self, RenderOptions};

fn dem() -> Heightfield {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../shared/dem/olympic_peninsula_coast.png"
    ));
    match terrasynth::io::read(path, &Default::default()) {
        Ok(hf) => hf,
        Err(e) => {
            eprintln!("{e}; benchmarking a synthetic 1024² terrain instead");
            Heightfield::from_fn(1024, 1024, 30.0, |x, y| {
                let (x, y) = (x as f32 / 80.0, y as f32 / 70.0);
                300.0 + 200.0 * x.sin() * y.cos() + 60.0 * (3.1 * x + y).sin() - 20.0
            })
            .expect("1024² is a valid size")
        }
    }
}

fn bench(c: &mut Criterion) {
    let hf = dem();
    let opts = RenderOptions::default();
    let mut g = c.benchmark_group("render");
    g.sample_size(10);
    g.bench_function("1024", |b| {
        b.iter(|| render::render(black_box(&hf), &opts).unwrap())
    });
    g.bench_function("1024+png", |b| {
        b.iter(|| {
            render::encode_png(&render::render(black_box(&hf), &opts).unwrap().image).unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
