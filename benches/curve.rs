//! Curve constraints at 1024² (paper §6, Fig. 9: embedding a curve and
//! changing its area of effect cost extra): `curve/embed/1024` builds a
//! meandering curve from scratch (smoothing, distance field, envelope
//! isocurve and its smoothing), `curve/reach/1024` rebuilds it with a new
//! reach and `curve/height/1024` with new heights — both reuse the cached
//! distance field, as an edit does — and `curve/blend/1024` adds it to the
//! overlap blend of every level and subtracts it again (what an edit of
//! the curve does to the blend's running sums). `curve/embed-long/1024`
//! builds the editor bench's new long stroke from scratch (three points
//! across 80 % of the side, reach 3 % of it): what sketching one costs
//! before its synthesis.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec2;
use std::hint::black_box;
use terrasynth::database::Quantization;
use terrasynth::synth::control::Blend;
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
    let long = CurveSpec {
        points: vec![
            DVec2::new(102.4, 200.0),
            DVec2::new(512.0, 241.0),
            DVec2::new(921.6, 179.5),
        ],
        widgets: vec![Widget {
            at: 0.5,
            height_m: 1000.0,
            slope_deg: [-20.0, -20.0],
            reach_px: [30.72, 30.72],
        }],
        smoothing: 2,
    };
    g.bench_function("embed-long/1024", |b| {
        b.iter(|| build(std::slice::from_ref(&long), &[], 30.0, &FieldCache::new()).unwrap())
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
    let q = Quantization {
        offset_m: 0.0,
        scale_m: 0.05,
    };
    let mut blend = Blend::new(1024, 1024, 10, q);
    g.bench_function("blend/1024", |b| {
        b.iter(|| {
            blend.add(&curves[0]);
            blend.subtract(&curves[0]);
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
