//! Every reader and writer on a 1024² heightfield (SRTM: its native 1201²),
//! bytes in memory so the file system is not measured. Ids: `read/<format>/1024`,
//! `write/<format>/1024`.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;
use terrasynth::Heightfield;
use terrasynth::io::{self, Format, ReadOptions, WriteOptions};

const N: usize = 1024;

/// Smooth terrain-like relief (a few octaves of sines), 0..~1500 m.
fn terrain(n: usize) -> Heightfield {
    Heightfield::from_fn(n, n, 10.0, |x, y| {
        let (x, y) = (x as f32 / n as f32, y as f32 / n as f32);
        (1..6).fold(700.0, |h, o| {
            let f = (1 << o) as f32 * 3.1;
            h + 400.0 / o as f32 * (f * x + o as f32).sin() * (f * 1.3 * y).cos()
        })
    })
    .unwrap()
}

fn png8(hf: &Heightfield) -> Vec<u8> {
    let s = hf.stats().unwrap();
    let px: Vec<u8> = hf
        .data()
        .iter()
        .map(|&v| ((v - s.min) / (s.max - s.min) * 255.0).round() as u8)
        .collect();
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, hf.width() as u32, hf.height() as u32);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(png::BitDepth::Eight);
    enc.write_header().unwrap().write_image_data(&px).unwrap();
    out
}

fn hgt(side: usize) -> Vec<u8> {
    let hf = terrain(side);
    hf.data()
        .iter()
        .flat_map(|&v| (v as i16).to_be_bytes())
        .collect()
}

fn config<'a>(
    c: &'a mut Criterion,
    name: &str,
) -> criterion::BenchmarkGroup<'a, criterion::measurement::WallTime> {
    let mut g = c.benchmark_group(name);
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .throughput(Throughput::Elements((N * N) as u64));
    g
}

/// A reader's input: format, side, file bytes, sidecar bytes.
type Input = (Format, usize, Vec<u8>, Option<Vec<u8>>);

fn bench(c: &mut Criterion) {
    let hf = terrain(N);
    let writable: Vec<Format> = Format::ALL
        .iter()
        .copied()
        .filter(|f| f.can_write())
        .collect();

    let mut g = config(c, "write");
    for &f in &writable {
        g.bench_with_input(BenchmarkId::new(f.name(), N), &hf, |b, hf| {
            b.iter(|| io::encode(black_box(hf), f, &WriteOptions::default()).unwrap())
        });
    }
    g.finish();

    let mut inputs: Vec<Input> = writable
        .iter()
        .map(|&f| {
            let e = io::encode(&hf, f, &WriteOptions::default()).unwrap();
            (f, N, e.bytes, e.sidecar)
        })
        .collect();
    inputs.push((Format::Png8, N, png8(&hf), None));
    inputs.push((Format::Hgt, 1201, hgt(1201), None));
    let mut g = config(c, "read");
    for (f, side, bytes, sidecar) in &inputs {
        g.throughput(Throughput::Elements((side * side) as u64));
        g.bench_with_input(BenchmarkId::new(f.name(), side), bytes, |b, bytes| {
            b.iter(|| {
                io::decode(
                    black_box(bytes),
                    *f,
                    sidecar.as_deref(),
                    &ReadOptions::default(),
                )
                .unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
