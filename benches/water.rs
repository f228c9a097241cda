//! `water` end to end (fill, flats, D8, accumulation, lakes, rivers):
//! `water/1024` on the shared 1024² Olympic Peninsula DEM, `water/4096` on
//! that DEM mirrored 4 × 4 (continuous across the joins: a real-terrain
//! 4096² without a synthesis in the set-up). Without `../shared/dem`, a
//! synthetic terrain of the same size stands in, with a message.
//! `terrasynth bench --only water` times the same on a synthesis.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use terrasynth::Heightfield;
use terrasynth::water::{self, Params};

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

/// `hf` mirrored `k × k` times: every other copy flipped, so heights are
/// continuous across the joins.
fn mirrored(hf: &Heightfield, k: usize) -> Heightfield {
    let (w, h) = (hf.width(), hf.height());
    Heightfield::from_fn(w * k, h * k, hf.cell_size(), |x, y| {
        let (tx, ty) = (x / w, y / h);
        let (mut sx, mut sy) = (x % w, y % h);
        if tx % 2 == 1 {
            sx = w - 1 - sx;
        }
        if ty % 2 == 1 {
            sy = h - 1 - sy;
        }
        hf.get(sx, sy)
    })
    .expect("a valid size")
}

fn bench(c: &mut Criterion) {
    let small = dem();
    let large = mirrored(&small, 4);
    let params = Params::default();
    let mut g = c.benchmark_group("water");
    g.sample_size(10);
    g.bench_function("1024", |b| {
        b.iter(|| water::compute(black_box(&small), &params).unwrap())
    });
    g.bench_function("4096", |b| {
        b.iter(|| water::compute(black_box(&large), &params).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
