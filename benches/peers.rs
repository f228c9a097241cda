//! The peer table (`cargo bench --bench peers`): the same job — a square
//! output from one 512² exemplar, at 512² and 1024² — timed for terrasynth
//! and for the Rust peer, EmbarkStudios' texture-synthesis (0.8.2, the
//! library under its 0.8.3 CLI; archived), on the same threads.
//!
//! The exemplar is the embedded `pyrenees_andorra` (`data/`, SRTM
//! mountains): terrasynth synthesizes from a database of it alone (built
//! before timing, as its databases are built once and reused) and, for
//! reference, from the embedded default database (four exemplars, what
//! `terrasynth bench` times); the peer gets the same heights scaled to 8-bit grey (it works on
//! colour images) and its default parameters. Each timing covers what the
//! library does for one output, in process, from exemplar in memory to
//! output in memory. The peer takes about a minute per 1024² output on two
//! cores, so it runs few times (`TERRASYNTH_PEERS_RUNS`, default 3);
//! terrasynth runs 15 times. Every run of a size uses the same seed, so the
//! outputs' hashes tell whether a library repeats itself.
//!
//! `TERRASYNTH_PEERS_SIZES=256,512` picks the sizes. The table is printed
//! and written to `target/peers.md`; `benches/PEERS.md` keeps a measured one.

use std::fmt::Write;
use std::time::Instant;
use terrasynth::database::{BuildOptions, Database, build, default};
use terrasynth::progress::Silent;
use terrasynth::synth::{Params, Synthesizer};
use texture_synthesis as ts;

const SEED: u32 = 1;
const OURS_RUNS: usize = 15;

/// One library's runs of one job: median wall time and distinct outputs.
struct Timed {
    median_ms: f64,
    runs: usize,
    distinct: usize,
}

/// Runs `job` `runs` times after one warm-up (skipped for slow jobs:
/// `warm = false`); `job` returns a hash of its output.
fn time(runs: usize, warm: bool, mut job: impl FnMut() -> u32) -> Timed {
    if warm {
        job();
    }
    let mut ms = Vec::with_capacity(runs);
    let mut hashes = Vec::with_capacity(runs);
    for _ in 0..runs {
        let t = Instant::now();
        hashes.push(job());
        ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    ms.sort_by(f64::total_cmp);
    hashes.sort_unstable();
    hashes.dedup();
    Timed {
        median_ms: ms[ms.len() / 2],
        runs,
        distinct: hashes.len(),
    }
}

fn ours(db: &Database, n: usize) -> Timed {
    let synth = Synthesizer::new(db, Params::default()).expect("default parameters");
    time(OURS_RUNS, true, || {
        let out = synth.synthesize(n, n, SEED).expect("synthesis");
        crc32fast::hash(bytemuck::cast_slice(out.data()))
    })
}

/// The peer's job: an `n × n` image from `exemplar`, on `threads` threads.
fn peer(exemplar: &ts::image::DynamicImage, n: u32, threads: usize, runs: usize) -> Timed {
    time(runs, false, || {
        let session = ts::Session::builder()
            .add_example(exemplar.clone())
            .output_size(ts::Dims::square(n))
            .seed(SEED as u64)
            .max_thread_count(threads)
            .build()
            .expect("the peer accepts the exemplar");
        let out = session.run(None).into_image();
        crc32fast::hash(out.as_bytes())
    })
}

/// The exemplar's heights as 8-bit grey, min → 0, max → 255.
fn grey(h: &terrasynth::heightfield::Heightfield) -> ts::image::DynamicImage {
    let d = h.data();
    let (lo, hi) = d
        .iter()
        .fold((f32::MAX, f32::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    let px = d
        .iter()
        .map(|&v| ((v - lo) / (hi - lo).max(f32::MIN_POSITIVE) * 255.0).round() as u8)
        .collect();
    let img = ts::image::GrayImage::from_raw(h.width() as u32, h.height() as u32, px)
        .expect("width × height bytes");
    ts::image::DynamicImage::ImageLuma8(img)
}

fn main() {
    // `cargo bench` passes --bench; `cargo test --benches` runs nothing here.
    if !std::env::args().any(|a| a == "--bench") {
        return;
    }
    let env = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.into());
    let sizes: Vec<usize> = env("TERRASYNTH_PEERS_SIZES", "512,1024")
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let runs: usize = env("TERRASYNTH_PEERS_RUNS", "3")
        .parse()
        .unwrap_or(3)
        .max(1);
    let threads = rayon::current_num_threads();
    let pyrenees = default::inputs()
        .into_iter()
        .find(|e| e.name == "pyrenees_andorra")
        .expect("the embedded Pyrenees");
    let exemplar = grey(&pyrenees.heights);
    let one = build(vec![pyrenees], &BuildOptions::default(), &Silent)
        .expect("a database of the Pyrenees")
        .0;
    let all = default::load_or_build(&default::cache_dir(), &Silent)
        .expect("the default database")
        .0;
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into());
    let load = || {
        std::fs::read_to_string("/proc/loadavg")
            .unwrap_or_default()
            .split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut table = format!(
        "CPU: {cpu}, {threads} threads for each library; load average before: {}\n\n\
         | output (from a 512² exemplar) | terrasynth, one exemplar | terrasynth, default database (4) | texture-synthesis 0.8.2 | peer ÷ terrasynth |\n\
         |---|---|---|---|---|\n",
        load()
    );
    let cell = |t: &Timed| {
        format!(
            "{:.1} ms ({} runs, {} distinct output{})",
            t.median_ms,
            t.runs,
            t.distinct,
            if t.distinct == 1 { "" } else { "s" }
        )
    };
    for &n in &sizes {
        let a = ours(&one, n);
        let b = ours(&all, n);
        eprintln!(
            "terrasynth {n}²: {:.1} ms / {:.1} ms",
            a.median_ms, b.median_ms
        );
        let p = peer(&exemplar, n as u32, threads, runs);
        let line = format!(
            "| {n}² | {} | {} | {} | {:.0}× |\n",
            cell(&a),
            cell(&b),
            cell(&p),
            p.median_ms / a.median_ms
        );
        eprint!("{line}");
        table.push_str(&line);
    }
    let _ = writeln!(table, "\n(load average after: {})", load());
    println!("{table}");
    let out = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/peers.md");
    std::fs::write(&out, &table).expect("target/ is writable");
    eprintln!("wrote {}", out.display());
}
