//! The exemplar database: `db_build/default` (the three embedded 512²
//! exemplars: pyramid, appearance PCA, PatchMatch, types) and
//! `db_load/default` (open + verify every section checksum of the saved
//! file). The 8-DEM build (~5 Mpx) takes close to a minute and is measured
//! with `terrasynth db build` instead (see the database issue's note).

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use terrasynth::database::{BuildOptions, Database, build, default};
use terrasynth::progress::Silent;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("db_build");
    g.sample_size(10);
    g.bench_function("default", |b| {
        b.iter(|| build(default::inputs(), &BuildOptions::default(), &Silent).unwrap())
    });
    g.finish();

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("default.tsdb");
    default::build_default(&Silent)
        .unwrap()
        .save(&path)
        .unwrap();
    let mut g = c.benchmark_group("db_load");
    g.bench_function("default", |b| {
        b.iter(|| Database::load(black_box(&path)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
