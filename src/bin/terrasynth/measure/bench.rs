//! `terrasynth bench`: median synthesis times per size, level and stage,
//! median `water` times per size and stage, and median `erode` times.
//!
//! Timings come from the synthesizer's own stage clocks ([`Timings`]), so
//! the numbers are the same ones a library user sees; each size is run
//! `--runs` times after one warm-up and the median of every figure reported
//! (these machines are shared and noisy: medians, not means).

use crate::CliResult;
use crate::args::{BackendArg, load_database, parse_size, select_backend};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Duration;
use terrasynth::synth::{Params, Synthesizer, Timings};

#[derive(clap::Args)]
pub struct Args {
    /// Exemplar database (.tsdb); default: the embedded one.
    #[arg(long)]
    db: Option<PathBuf>,
    /// Output sizes to synthesize, comma-separated WxH.
    #[arg(long, value_delimiter = ',', value_parser = parse_size,
          default_value = "512x512,1024x1024,2048x2048")]
    sizes: Vec<(usize, usize)>,
    /// Timed runs per size (after one warm-up run); the median is reported.
    #[arg(long, default_value_t = 7, value_parser = clap::value_parser!(u32).range(1..=1000))]
    runs: u32,
    /// Random seed of the first run (run k uses seed + k).
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Where the stages run: cpu, gpu (`--features gpu` builds) or auto.
    /// GPU stage times come from timestamp queries where the adapter has
    /// them, else wall clock until the device is idle.
    #[arg(long, value_enum, default_value_t = BackendArg::Cpu)]
    backend: BackendArg,
    /// Sizes to time `water` on (fill, flats, D8, accumulation, lakes,
    /// rivers), each on a synthesis of that size (made once, not timed).
    #[arg(long, value_delimiter = ',', value_parser = parse_size,
          default_value = "4096x4096")]
    water_sizes: Vec<(usize, usize)>,
    /// Sizes to time `erode` (the default strength) on, each on a
    /// synthesis of that size.
    #[arg(long, value_delimiter = ',', value_parser = parse_size,
          default_value = "1024x1024")]
    erode_sizes: Vec<(usize, usize)>,
    /// Time only synthesis, only water or only erode.
    #[arg(long, value_enum)]
    only: Option<Only>,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum Only {
    Synth,
    Water,
    Erode,
}

impl Only {
    /// The sizes to time for this part: `sizes`, or none when `--only`
    /// names another part.
    fn sizes(self, only: Option<Only>, sizes: &[(usize, usize)]) -> &[(usize, usize)] {
        if only.is_some_and(|o| o != self) {
            &[]
        } else {
            sizes
        }
    }
}

/// One size's median `erode` time.
#[derive(Serialize)]
struct ErodeReport {
    size: String,
    runs: u32,
    threads: usize,
    strength: f32,
    total_ms: f64,
}

/// One size's water medians, in milliseconds.
#[derive(Serialize)]
struct WaterReport {
    size: String,
    runs: u32,
    threads: usize,
    total_ms: f64,
    stages: BTreeMap<&'static str, f64>,
    lakes: usize,
    river_segments: usize,
}

/// One size's medians, in milliseconds.
#[derive(Serialize)]
struct SizeReport {
    size: String,
    backend: &'static str,
    /// The GPU adapter, when the stages ran on one.
    #[serde(skip_serializing_if = "Option::is_none")]
    adapter: Option<String>,
    /// "gpu timestamps" or "wall clock".
    clock: &'static str,
    runs: u32,
    threads: usize,
    total_ms: f64,
    /// Index = level (0 finest).
    levels: Vec<LevelReport>,
    stages: BTreeMap<&'static str, f64>,
    bytes_per_pixel: f64,
}

#[derive(Serialize)]
struct LevelReport {
    level: usize,
    width: usize,
    height: usize,
    upsample_jitter_ms: f64,
    correct_ms: f64,
}

#[derive(Serialize)]
struct Report {
    sizes: Vec<SizeReport>,
    water: Vec<WaterReport>,
    erode: Vec<ErodeReport>,
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// The median (mean of the middle two for an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

pub fn run(a: Args) -> CliResult {
    let db = load_database(a.db.as_deref())?;
    let mut synth = Synthesizer::new(&db, Params::default())?;
    select_backend(&mut synth, a.backend)?;
    let mut sizes = Vec::new();
    let synth_sizes = Only::Synth.sizes(a.only, &a.sizes);
    for &(w, h) in synth_sizes {
        synth.run(w, h, a.seed)?; // warm-up: page in the database, spin up threads
        let timings: Vec<Timings> = (0..a.runs)
            .map(|k| synth.run(w, h, a.seed.wrapping_add(k)).map(|s| s.timings))
            .collect::<Result<_, _>>()?;
        let med =
            |f: &dyn Fn(&Timings) -> Duration| median(timings.iter().map(|t| ms(f(t))).collect());
        let n_levels = timings[0].levels.len();
        let levels = (0..n_levels)
            .map(|l| {
                let (lw, lh) = terrasynth::level::state::level_size(w, h, l);
                LevelReport {
                    level: l,
                    width: lw,
                    height: lh,
                    upsample_jitter_ms: med(&|t| t.levels[l].upsample),
                    correct_ms: med(&|t| t.levels[l].correct),
                }
            })
            .collect();
        let stages = BTreeMap::from([
            (
                "upsample_jitter",
                med(&|t| t.levels.iter().map(|l| l.upsample).sum()),
            ),
            (
                "correct",
                med(&|t| t.levels.iter().map(|l| l.correct).sum()),
            ),
            ("reconstruct", med(&|t| t.reconstruct)),
        ]);
        let report = SizeReport {
            size: format!("{w}x{h}"),
            backend: synth.backend_name(),
            adapter: synth.engine().adapter(),
            clock: if timings[0].device_clock {
                "gpu timestamps"
            } else {
                "wall clock"
            },
            runs: a.runs,
            threads: rayon::current_num_threads(),
            total_ms: med(&|t| t.total),
            levels,
            stages,
            bytes_per_pixel: Synthesizer::bytes_per_pixel(w, h),
        };
        if !a.json {
            print_table(&report);
        }
        sizes.push(report);
    }
    let mut water = Vec::new();
    let water_sizes = Only::Water.sizes(a.only, &a.water_sizes);
    for &(w, h) in water_sizes {
        let hf = synth.run(w, h, a.seed)?.heightfield;
        let params = terrasynth::water::Params::default();
        let first = terrasynth::water::compute(&hf, &params)?; // warm-up
        let timings: Vec<terrasynth::water::Timings> = (0..a.runs)
            .map(|_| terrasynth::water::compute(&hf, &params).map(|w| w.timings))
            .collect::<Result<_, _>>()?;
        let med = |f: &dyn Fn(&terrasynth::water::Timings) -> Duration| {
            median(timings.iter().map(|t| ms(f(t))).collect())
        };
        let report = WaterReport {
            size: format!("{w}x{h}"),
            runs: a.runs,
            threads: rayon::current_num_threads(),
            total_ms: med(&|t| t.total()),
            stages: BTreeMap::from([
                ("fill", med(&|t| t.fill)),
                ("flats", med(&|t| t.flats)),
                ("d8", med(&|t| t.d8)),
                ("accumulate", med(&|t| t.accumulate)),
                ("lakes", med(&|t| t.lakes)),
                ("rivers", med(&|t| t.rivers)),
            ]),
            lakes: first.bodies.lakes.len(),
            river_segments: first.rivers.segments.len(),
        };
        if !a.json {
            println!(
                "water {} (synthesis seed {}): {:.1} ms median of {} runs on {} threads; {} lakes, {} river segments",
                report.size,
                a.seed,
                report.total_ms,
                report.runs,
                report.threads,
                report.lakes,
                report.river_segments
            );
            for (name, t) in &report.stages {
                println!("  {name:<16} {t:>8.1} ms");
            }
        }
        water.push(report);
    }
    let mut erode = Vec::new();
    let erode_sizes = Only::Erode.sizes(a.only, &a.erode_sizes);
    for &(w, h) in erode_sizes {
        let hf = synth.run(w, h, a.seed)?.heightfield;
        let strength = terrasynth::erode::DEFAULT_STRENGTH;
        terrasynth::erode::erode(&hf, strength)?; // warm-up
        let times: Vec<f64> = (0..a.runs)
            .map(|_| {
                let t = std::time::Instant::now();
                terrasynth::erode::erode(&hf, strength).map(|_| ms(t.elapsed()))
            })
            .collect::<Result<_, _>>()?;
        let report = ErodeReport {
            size: format!("{w}x{h}"),
            runs: a.runs,
            threads: rayon::current_num_threads(),
            strength,
            total_ms: median(times),
        };
        if !a.json {
            println!(
                "erode {} (synthesis seed {}, strength {}): {:.1} ms median of {} runs on {} threads",
                report.size, a.seed, strength, report.total_ms, report.runs, report.threads
            );
        }
        erode.push(report);
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&Report {
                sizes,
                water,
                erode
            })?
        );
    }
    Ok(())
}

fn print_table(r: &SizeReport) {
    println!(
        "{} on {}: {:.1} ms median of {} runs on {} threads, {:.1} bytes/pixel",
        r.size, r.backend, r.total_ms, r.runs, r.threads, r.bytes_per_pixel
    );
    if let Some(a) = &r.adapter {
        println!("  adapter: {a}");
    }
    println!("  stage times: {}", r.clock);
    for (name, t) in &r.stages {
        println!("  {name:<16} {t:>8.1} ms");
    }
    println!("  level     size        upsample    correct");
    for l in r.levels.iter().rev() {
        println!(
            "  {:>5} {:>5}x{:<5} {:>8.2} ms {:>8.2} ms",
            l.level, l.width, l.height, l.upsample_jitter_ms, l.correct_ms
        );
    }
}
