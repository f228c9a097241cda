//! The patch engine per stage (issue 7), on the shared DEMs when present:
//! `ppa/sketch/1024` (PPA + feature graph of a sketch), `prepare/source/800`
//! (one DEM's features and candidates), `feature_cost/cpu/<n>` (round one
//! over every ridge node of one source × 10 transforms for one user patch),
//! `graphcut/cpu/64` (one full seam) and
//! `graphcut/banded/64` (half-resolution seam, then the banded full one, as
//! synthesis does), `poisson_merge/cpu/64` (Shepard + multigrid Poisson of
//! one patch), and end to end `sketch/<k>src/512`. Stage `fill_ssd` (round
//! one of hole filling): `benches/stages.rs`. Per-stage times of a
//! whole 1024² run are printed by `terrasynth sketch` (Timings).

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::path::Path;
use terrasynth::io::{self, ReadOptions};
use terrasynth::patch::input::sketch::{Kind, Sketch};
use terrasynth::patch::merge::{self, Canvas, Window};
use terrasynth::patch::place::costs::{FEATURE_TRANSFORMS, feature_cost};
use terrasynth::patch::{self, Library, Params, sketch_field, sketch_graph};
use terrasynth::progress::Silent;

const DEM: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/dem");
const NAMES: [&str; 8] = [
    "catalan_coast_hills",
    "franconian_jura",
    "north_german_plain",
    "olympic_peninsula_coast",
    "pyrenees_andorra",
    "riviera_coast",
    "thuringia_hills",
    "yosemite_half_dome",
];

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sketch = Sketch::read(&root.join("data/sketches/lambda_circle.json")).unwrap();
    let mut g = c.benchmark_group("ppa");
    g.sample_size(10);
    g.bench_function("sketch/1024", |b| {
        let field = sketch_field(&sketch, 1024, 1024, 64);
        b.iter(|| black_box(sketch_graph(&field, 1024, 1024, 64, Kind::Ridge)))
    });
    g.finish();

    if !Path::new(DEM).join("pyrenees_andorra.png").exists() {
        eprintln!("skipping the DEM benches: {DEM} not found");
        return;
    }
    let sources: Vec<(String, terrasynth::Heightfield)> = NAMES
        .iter()
        .map(|n| {
            let p = Path::new(DEM).join(format!("{n}.png"));
            (
                n.to_string(),
                io::read(&p, &ReadOptions::default()).unwrap(),
            )
        })
        .collect();
    let params = Params::default();
    let mut g = c.benchmark_group("prepare");
    g.sample_size(10);
    g.bench_function("source/800", |b| {
        b.iter(|| black_box(Library::prepare(&sources[6..7], &params, &Silent).unwrap()))
    });
    g.finish();

    let lib = Library::prepare(&sources, &params, &Silent).unwrap();
    let field = sketch_field(&sketch, 1024, 1024, 64);
    let (_, _, users) = patch::user_patches(&field, 1024, 1024, 64);
    let user = users.iter().find(|u| u.node.cps.len() == 2).unwrap();
    let nodes = &lib.sources[4].ridges;
    let mut g = c.benchmark_group("feature_cost");
    g.bench_function(format!("cpu/{}", nodes.len()), |b| {
        b.iter(|| {
            let mut best = u32::MAX;
            for n in nodes.iter().filter(|n| n.cps.len() == 2) {
                for t in 0..FEATURE_TRANSFORMS {
                    best = best.min(feature_cost(&user.node.cps, &n.cps, t).0);
                }
            }
            black_box(best)
        })
    });
    g.finish();

    let src = &lib.sources[4];
    // A half-filled canvas and a patch from another place of the same DEM.
    let mut canvas = Canvas::new(128, 128);
    for y in 0..128 {
        for x in 0..128 {
            let i = y * 128 + x;
            canvas.heights[i] = src.heights[(100 + y) * src.width + 100 + x];
            canvas.filled[i] = x < 64;
        }
    }
    let win = Window {
        x0: 32,
        y0: 32,
        n: 64,
    };
    let mut p: Vec<f32> = (0..64 * 64)
        .map(|i| src.heights[(400 + i / 64) * src.width + 400 + i % 64])
        .collect();
    let off = merge::offset(&canvas, win, &p);
    p.iter_mut().for_each(|v| *v += off);
    let mut g = c.benchmark_group("graphcut");
    g.bench_function("cpu/64", |b| {
        b.iter(|| black_box(merge::seam(&canvas, win, &p, None)))
    });
    g.bench_function("banded/64", |b| {
        b.iter(|| {
            let coarse = merge::seam_coarse(&canvas, win, &p, None);
            black_box(merge::seam_banded(&canvas, win, &p, None, &coarse))
        })
    });
    g.finish();
    let seam = merge::seam(&canvas, win, &p, None);
    let mut g = c.benchmark_group("poisson_merge");
    let opts = terrasynth::poisson::SolveOptions {
        tolerance: 1e-5,
        max_iterations: 2000,
    };
    g.bench_function("cpu/64", |b| {
        b.iter(|| {
            let mut cv = canvas.clone();
            black_box(merge::apply(&mut cv, win, (&p, 0), &seam.take_new, &opts))
        })
    });
    g.finish();

    let mut g = c.benchmark_group("sketch");
    g.sample_size(10);
    let one = Library::prepare(&sources[4..5], &params, &Silent).unwrap();
    for (name, l) in [("1src", &one), ("8src", &lib)] {
        g.bench_function(format!("{name}/512"), |b| {
            b.iter(|| black_box(patch::synthesize(l, &sketch, 512, 512, &Silent).unwrap()))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
