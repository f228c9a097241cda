//! Curve constraints at 1024² (paper §6, Fig. 9: embedding a curve and
//! changing its area of effect cost extra): `curve/embed/1024` builds a
//! meandering curve from scratch (smoothing, distance field, envelope
//! isocurve and its smoothing), `curve/reach/1024` rebuilds it with a new
//! reach and `curve/height/1024` with new heights — both reuse the cached
//! distance field, as an edit does — and `curve/sample/1024` evaluates it
//! at every level-2 pixel centre (what the blend does per frame).

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec2;
use std::hint::black_box;
use terrasynth::synth::control::Constraint;
use terrasynth::synth::control::curve::{CurveSpec, FieldCache, Widget, build};

fn spec(height: f64, reach: f64) -> CurveSpec {
    let points = (0..=16)
        .map(|k| {
            let t = k as f64 / 16.0;
            DVec2::new(40.0 + 940.0 * t, 512.0 + 260.0 * (t * 9.0).sin())
        })
        .collect();
    let w = |at: f64, h: f64| Widget {
        at,
        height_m: h,
        slope_deg: [25.0, 30.0],
        reach_px: [reach, reach * 0.8],
    };
    CurveSpec {
        points,
        widgets: vec![
            w(0.0, height),
            w(0.5, height - 200.0),
            w(1.0, height + 100.0),
        ],
        smoothing: 2,
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("curve");
    g.sample_size(10);
    g.bench_function("embed/1024", |b| {
        b.iter(|| build(&[spec(1000.0, 60.0)], &[], 30.0, &FieldCache::new()).unwrap())
    });
    let cache = FieldCache::new();
    build(&[spec(1000.0, 80.0)], &[], 30.0, &cache).unwrap();
    g.bench_function("reach/1024", |b| {
        b.iter(|| build(&[spec(1000.0, black_box(60.0))], &[], 30.0, &cache).unwrap())
    });
    g.bench_function("height/1024", |b| {
        b.iter(|| build(&[spec(black_box(1100.0), 80.0)], &[], 30.0, &cache).unwrap())
    });
    let (curves, _) = build(&[spec(1000.0, 60.0)], &[], 30.0, &cache).unwrap();
    g.bench_function("sample/1024", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for y in 0..256 {
                for x in 0..256 {
                    let p = ((x as f64 + 0.5) * 4.0, (y as f64 + 0.5) * 4.0);
                    n += curves[0].sample(p.0, p.1).is_some() as usize;
                }
            }
            n
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
