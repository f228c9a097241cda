//! `terrasynth eval --suite DIR`: the realism protocol of issue 14.
//!
//! For every DEM in DIR (16-bit PNG + JSON sidecar, like `../shared/dem`):
//! a single-exemplar database (default build options, cached on disk by
//! `database::cache`), synthesis at the exemplar's size with default
//! parameters for each seed, and `eval` against the DEM; per DEM the median
//! over seeds of the realism ratio (and of each descriptor's ratio), the
//! median slope, relief kept and pits. Then the typed database of all DEMs
//! with their `<stem>_types.png` masks: type usage of unconstrained
//! syntheses (default 1024²) for the same seeds. DEMs run in parallel (rayon;
//! `--jobs`), and each stage is parallel inside.

use crate::CliResult;
use crate::args::parse_size;
use crate::eval::{SizeArg, parse_size_arg, print_type_usage};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;
use terrasynth::Heightfield;
use terrasynth::database::{BuildOptions, Database, ExemplarInput, TypeMask, cache, default};
use terrasynth::eval::{self, Comparison, DESCRIPTORS, Reference, TypeUsage};
use terrasynth::io::{self, WriteOptions};
use terrasynth::render::{self, RenderOptions};
use terrasynth::synth::{Params, Synthesizer, source_map::source_map};

/// The targets of issue 14's "Done means", per DEM (median over seeds).
const TARGET_RATIO: f64 = 1.3;
const TARGET_SLOPE: f64 = 0.10;
const TARGET_RELIEF: f64 = 0.85;
const TARGET_PITS: f64 = 1.5;

#[derive(clap::Args)]
pub struct SuiteArgs {
    /// Run the realism protocol over every DEM in DIR (PNG + JSON sidecar;
    /// `<stem>_types.png` masks for the typed database) instead of
    /// comparing two files.
    #[arg(long, value_name = "DIR", conflicts_with_all = ["synth", "reference"])]
    pub suite: Option<PathBuf>,
    /// Seeds of the protocol, comma-separated; medians are over them.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "11,12,13",
        requires = "suite"
    )]
    seeds: Vec<u32>,
    /// Synthesis size per DEM: `exemplar` (its own size) or WxH.
    #[arg(long = "size", value_parser = parse_size_arg, default_value = "exemplar", requires = "suite")]
    synth_size: SizeArg,
    /// Output size of the typed database's syntheses (type usage).
    #[arg(long, value_parser = parse_size, default_value = "1024x1024", requires = "suite")]
    typed_size: (usize, usize),
    /// Skip the typed database (type usage).
    #[arg(long, requires = "suite")]
    no_typed: bool,
    /// Only these DEMs (file stems, comma-separated); the typed database
    /// still uses them all.
    #[arg(long, value_delimiter = ',', requires = "suite")]
    only: Vec<String>,
    /// Jitter amplitude r of the syntheses (synth's default).
    #[arg(long, default_value_t = Params::default().jitter, requires = "suite")]
    jitter: f64,
    /// Correction passes per level (synth's default).
    #[arg(long, default_value_t = Params::default().passes, requires = "suite")]
    passes: u32,
    /// Worker threads (default: one per core).
    #[arg(long, requires = "suite")]
    jobs: Option<usize>,
    /// Write every synthesis, side-by-side previews (exemplar | synthesis),
    /// a plot per DEM, the typed syntheses with their coordinates maps, and
    /// report.json here.
    #[arg(long, requires = "suite")]
    out_dir: Option<PathBuf>,
    /// Where databases are cached (default: the default database's cache).
    #[arg(long, requires = "suite")]
    cache_dir: Option<PathBuf>,
}

/// One DEM read from the suite folder.
struct Dem {
    name: String,
    hf: Heightfield,
    mask: Option<PathBuf>,
}

#[derive(Serialize)]
struct SeedResult {
    seed: u32,
    synth_ms: f64,
    #[serde(flatten)]
    comparison: Comparison,
}

/// Medians over seeds.
#[derive(Serialize)]
struct Medians {
    ratio: f64,
    /// Each descriptor's ratio.
    descriptors: BTreeMap<&'static str, f64>,
    median_slope_real: f64,
    median_slope_synth: f64,
    slope_ratio: f64,
    relief_real_m: f64,
    relief_kept: f64,
    pits_real: f64,
    pits_synth: f64,
    pits_ratio: f64,
}

/// Whether each of issue 14's targets is met.
#[derive(Serialize)]
struct Targets {
    ratio: bool,
    slope: bool,
    relief: bool,
    pits: bool,
}

#[derive(Serialize)]
struct DemResult {
    name: String,
    width: usize,
    height: usize,
    cell_size_m: f64,
    synth_size: [usize; 2],
    seeds: Vec<SeedResult>,
    median: Medians,
    targets: Targets,
}

#[derive(Serialize)]
struct TypedResult {
    size: [usize; 2],
    exemplars: Vec<String>,
    seeds: Vec<(u32, TypeUsage)>,
    /// Per type: (name, median share of the output, share of the exemplars).
    median: Vec<(String, f64, f64)>,
}

#[derive(Serialize)]
struct SuiteReport {
    dir: PathBuf,
    seeds: Vec<u32>,
    jitter: f64,
    passes: u32,
    threads: usize,
    dems: Vec<DemResult>,
    #[serde(skip_serializing_if = "Option::is_none")]
    typed: Option<TypedResult>,
    wall_s: f64,
}

type Result<T> = std::result::Result<T, String>;

pub fn run(a: &SuiteArgs, json: bool) -> CliResult {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.jobs.unwrap_or(0))
        .build()?;
    pool.install(|| run_in_pool(a, json))
}

fn run_in_pool(a: &SuiteArgs, json: bool) -> CliResult {
    let t0 = Instant::now();
    let dir = a.suite.as_deref().expect("run only with --suite");
    if a.seeds.is_empty() {
        return Err("--seeds is empty: give at least one seed".into());
    }
    let cache_dir = a.cache_dir.clone().unwrap_or_else(default::cache_dir);
    if let Some(d) = &a.out_dir {
        std::fs::create_dir_all(d).map_err(|e| format!("cannot create {}: {e}", d.display()))?;
    }
    let dems = read_dems(dir)?;
    let chosen: Vec<&Dem> = dems
        .iter()
        .filter(|d| a.only.is_empty() || a.only.contains(&d.name))
        .collect();
    if chosen.is_empty() {
        return Err(format!(
            "--only {:?} matches none of the DEMs in {}",
            a.only,
            dir.display()
        )
        .into());
    }
    eprintln!(
        "realism protocol: {} DEMs from {}, seeds {:?}, jitter {}, {} passes, {} threads",
        chosen.len(),
        dir.display(),
        a.seeds,
        a.jitter,
        a.passes,
        rayon::current_num_threads()
    );
    let results = chosen
        .par_iter()
        .map(|d| run_dem(d, a, &cache_dir))
        .collect::<Result<Vec<_>>>()?;
    let typed = if a.no_typed {
        None
    } else {
        run_typed(&dems, a, &cache_dir)?
    };
    let report = SuiteReport {
        dir: dir.to_path_buf(),
        seeds: a.seeds.clone(),
        jitter: a.jitter,
        passes: a.passes,
        threads: rayon::current_num_threads(),
        dems: results,
        typed,
        wall_s: t0.elapsed().as_secs_f64(),
    };
    let text = serde_json::to_string_pretty(&report)?;
    if let Some(d) = &a.out_dir {
        io::write_atomic(&d.join("report.json"), text.as_bytes())?;
    }
    if json {
        println!("{text}");
    } else {
        print_report(&report);
    }
    Ok(())
}

/// Every `*.png` with a `.json` sidecar in `dir` (masks `*_types.png`
/// excluded), sorted by name.
fn read_dems(dir: &Path) -> Result<Vec<Dem>> {
    let entries = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension().is_some_and(|x| x == "png")
                && !p
                    .file_stem()
                    .is_some_and(|s| s.to_string_lossy().ends_with("_types"))
                && p.with_extension("json").exists()
        })
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(format!(
            "{}: no DEMs (16-bit PNG with a JSON sidecar) found",
            dir.display()
        ));
    }
    paths
        .into_par_iter()
        .map(|p| {
            let hf = io::read(&p, &Default::default()).map_err(|e| e.to_string())?;
            let name = crate::eval::name(&p.with_extension(""));
            let mask = p.with_file_name(format!("{name}_types.png"));
            Ok(Dem {
                name,
                hf,
                mask: mask.exists().then_some(mask),
            })
        })
        .collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        (v[n / 2 - 1] + v[n / 2]) / 2.0
    }
}

/// Writes a heightfield, its side-by-side preview with the exemplar, and
/// (when asked) the comparison plot, under `out/<stem>…`.
fn write_outputs(
    out: &Path,
    stem: &str,
    exemplar: &Heightfield,
    synth: &Heightfield,
    plot: Option<(&Reference, &eval::Descriptors, &Comparison)>,
) -> Result<()> {
    let err = |e: &dyn std::fmt::Display| e.to_string();
    io::write(
        synth,
        &out.join(format!("{stem}.png")),
        &WriteOptions::default(),
    )
    .map_err(|e| err(&e))?;
    let opts = RenderOptions {
        max_size: 1024,
        ..Default::default()
    };
    let side = render::side_by_side(&[("exemplar", exemplar), ("synthesis", synth)], &opts)
        .map_err(|e| err(&e))?;
    render::write_png(&out.join(format!("{stem}_side.png")), &side).map_err(|e| err(&e))?;
    if let Some((r, d, c)) = plot {
        let img = eval::plot::plot(r, d, c, stem);
        render::write_png(&out.join(format!("{stem}_plot.png")), &img).map_err(|e| err(&e))?;
    }
    Ok(())
}

/// The protocol on one DEM.
fn run_dem(dem: &Dem, a: &SuiteArgs, cache_dir: &Path) -> Result<DemResult> {
    let t = Instant::now();
    let name = &dem.name;
    let input = ExemplarInput {
        name: name.clone(),
        heights: dem.hf.clone(),
        types: None,
    };
    let (db, built) = cache::cached_build(
        cache_dir,
        vec![input],
        &BuildOptions::default(),
        &terrasynth::progress::Silent,
    )
    .map_err(|e| format!("{name}: {e}"))?;
    eprintln!(
        "{name}: database {} ({:.1} s)",
        if built {
            "built and cached"
        } else {
            "from cache"
        },
        t.elapsed().as_secs_f64()
    );
    let reference = Reference::new(&dem.hf).map_err(|e| format!("{name}: {e}"))?;
    let (w, h) = match a.synth_size {
        SizeArg::Exemplar => (dem.hf.width(), dem.hf.height()),
        SizeArg::Fixed(w, h) => (w, h),
    };
    let params = Params {
        jitter: a.jitter,
        passes: a.passes,
        ..Params::default()
    };
    let synth = Synthesizer::new(&db, params).map_err(|e| format!("{name}: {e}"))?;
    let mut seeds = Vec::new();
    for (k, &seed) in a.seeds.iter().enumerate() {
        let ts = Instant::now();
        let out = synth.run(w, h, seed).map_err(|e| format!("{name}: {e}"))?;
        let synth_ms = ts.elapsed().as_secs_f64() * 1e3;
        let d = eval::describe(&out.heightfield).map_err(|e| format!("{name}: {e}"))?;
        let c = reference.compare(&d);
        if let Some(o) = &a.out_dir {
            let plot = (k == 0).then_some((&reference, &d, &c));
            write_outputs(
                o,
                &format!("{name}_s{seed}"),
                &dem.hf,
                &out.heightfield,
                plot,
            )?;
        }
        eprintln!(
            "{name} seed {seed}: ratio {:.2}, median slope {:.1}° → {:.1}°, relief kept {:.0} %, pits ×{:.2} ({:.1} s)",
            c.ratio,
            c.median_slope.reference,
            c.median_slope.synth,
            c.relief.ratio * 100.0,
            c.pits.ratio,
            ts.elapsed().as_secs_f64()
        );
        seeds.push(SeedResult {
            seed,
            synth_ms,
            comparison: c,
        });
    }
    let med =
        |f: &dyn Fn(&Comparison) -> f64| median(seeds.iter().map(|s| f(&s.comparison)).collect());
    let first = &seeds[0].comparison;
    let median = Medians {
        ratio: med(&|c| c.ratio),
        descriptors: DESCRIPTORS
            .iter()
            .enumerate()
            .map(|(i, d)| (d.id, med(&|c| c.descriptors[i].ratio)))
            .collect(),
        median_slope_real: first.median_slope.reference,
        median_slope_synth: med(&|c| c.median_slope.synth),
        slope_ratio: med(&|c| c.median_slope.ratio),
        relief_real_m: first.relief.reference,
        relief_kept: med(&|c| c.relief.ratio),
        pits_real: first.pits.reference,
        pits_synth: med(&|c| c.pits.synth),
        pits_ratio: med(&|c| c.pits.ratio),
    };
    let targets = Targets {
        ratio: median.ratio <= TARGET_RATIO,
        slope: (median.slope_ratio - 1.0).abs() <= TARGET_SLOPE,
        relief: median.relief_kept >= TARGET_RELIEF,
        pits: median.pits_ratio <= TARGET_PITS,
    };
    Ok(DemResult {
        name: name.clone(),
        width: dem.hf.width(),
        height: dem.hf.height(),
        cell_size_m: dem.hf.cell_size(),
        synth_size: [w, h],
        seeds,
        median,
        targets,
    })
}

/// Type usage of unconstrained syntheses from the database of every DEM
/// with its type mask; None (with a note) when no DEM has a mask.
fn run_typed(dems: &[Dem], a: &SuiteArgs, cache_dir: &Path) -> Result<Option<TypedResult>> {
    if dems.iter().all(|d| d.mask.is_none()) {
        eprintln!("note: no <stem>_types.png masks: no type usage");
        return Ok(None);
    }
    let t = Instant::now();
    let inputs = dems
        .iter()
        .map(|d| {
            let types = d
                .mask
                .as_deref()
                .map(TypeMask::read)
                .transpose()
                .map_err(|e| e.to_string())?;
            Ok(ExemplarInput {
                name: d.name.clone(),
                heights: d.hf.clone(),
                types,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let (db, built) = cache::cached_build(
        cache_dir,
        inputs,
        &BuildOptions::default(),
        &crate::progress::Bar::new(),
    )
    .map_err(|e| format!("typed database: {e}"))?;
    eprintln!(
        "typed database of {} DEMs: {} ({:.1} s)",
        dems.len(),
        if built {
            "built and cached"
        } else {
            "from cache"
        },
        t.elapsed().as_secs_f64()
    );
    let (w, h) = a.typed_size;
    let params = Params {
        jitter: a.jitter,
        passes: a.passes,
        keep_levels: true,
        ..Params::default()
    };
    let synth = Synthesizer::new(&db, params).map_err(|e| e.to_string())?;
    let mut seeds = Vec::new();
    for &seed in &a.seeds {
        let out = synth.run(w, h, seed).map_err(|e| e.to_string())?;
        let l0 = &out.levels[0];
        let map = source_map(&l0.coords, l0.width, w, h, &db);
        let usage = eval::type_usage(&map, &db).map_err(|e| e.to_string())?;
        if let Some(o) = &a.out_dir {
            write_typed(o, seed, &db, &out.heightfield, &map)?;
        }
        let shares: Vec<String> = usage
            .types
            .iter()
            .map(|s| {
                format!(
                    "{} {:.0} % (of {:.0} %)",
                    s.name,
                    s.used * 100.0,
                    s.exemplars * 100.0
                )
            })
            .collect();
        eprintln!("typed seed {seed}: {}", shares.join(", "));
        seeds.push((seed, usage));
    }
    let median = db
        .type_names()
        .iter()
        .enumerate()
        .map(|(t, n)| {
            let used = median(seeds.iter().map(|(_, u)| u.types[t].used).collect());
            (n.clone(), used, seeds[0].1.types[t].exemplars)
        })
        .collect();
    Ok(Some(TypedResult {
        size: [w, h],
        exemplars: db.meta().exemplars.iter().map(|e| e.name.clone()).collect(),
        seeds,
        median,
    }))
}

/// The typed synthesis, its preview, its coordinates map and that map's picture.
fn write_typed(
    out: &Path,
    seed: u32,
    db: &Database,
    hf: &Heightfield,
    map: &io::CoordsMap,
) -> Result<()> {
    let stem = format!("typed_s{seed}");
    io::write(
        hf,
        &out.join(format!("{stem}.png")),
        &WriteOptions::default(),
    )
    .map_err(|e| e.to_string())?;
    let preview = render::render(hf, &RenderOptions::default()).map_err(|e| e.to_string())?;
    render::write_png(&out.join(format!("{stem}_preview.png")), &preview.image)
        .map_err(|e| e.to_string())?;
    map.write(&out.join(format!("{stem}_coords.png")))
        .map_err(|e| e.to_string())?;
    let sizes: Vec<(u32, u32)> = db
        .meta()
        .exemplars
        .iter()
        .map(|e| (e.width, e.height))
        .collect();
    render::write_png(
        &out.join(format!("{stem}_coords_preview.png")),
        &render::coords_preview(map, &sizes),
    )
    .map_err(|e| e.to_string())
}

fn mark(ok: bool) -> &'static str {
    if ok { "✓" } else { "✗" }
}

fn print_report(r: &SuiteReport) {
    println!(
        "realism protocol: {} DEMs, seeds {:?}, jitter {}, {} passes; medians over seeds",
        r.dems.len(),
        r.seeds,
        r.jitter,
        r.passes
    );
    println!(
        "{:<26} {:>9} {:>7} {:>6}  {:>20}  {:>7}  {:>22}  targets",
        "DEM", "size", "cell m", "ratio", "median slope real→synth", "relief", "pits real→synth",
    );
    for d in &r.dems {
        let m = &d.median;
        let t = &d.targets;
        println!(
            "{:<26} {:>9} {:>7.1} {:>6.2}  {:>6.1}° → {:>5.1}° ({:>3.0} %)  {:>6.0} %  {:>5.2} % → {:>5.2} % ({:>4.2}×)  {}{}{}{}",
            d.name,
            format!("{}x{}", d.width, d.height),
            d.cell_size_m,
            m.ratio,
            m.median_slope_real,
            m.median_slope_synth,
            m.slope_ratio * 100.0,
            m.relief_kept * 100.0,
            m.pits_real * 100.0,
            m.pits_synth * 100.0,
            m.pits_ratio,
            mark(t.ratio),
            mark(t.slope),
            mark(t.relief),
            mark(t.pits)
        );
    }
    println!(
        "targets (issue 14): ratio ≤ {TARGET_RATIO}, median slope within {:.0} %, relief ≥ {:.0} %, pits ≤ {TARGET_PITS}×",
        TARGET_SLOPE * 100.0,
        TARGET_RELIEF * 100.0
    );
    println!();
    print!("{:<26}", "descriptor ratios");
    for d in &DESCRIPTORS {
        print!(" {:>11}", d.id);
    }
    println!();
    for d in &r.dems {
        print!("{:<26}", d.name);
        for info in &DESCRIPTORS {
            print!(" {:>11.2}", d.median.descriptors[info.id]);
        }
        println!();
    }
    if let Some(t) = &r.typed {
        println!();
        println!(
            "type usage: typed database of {} DEMs, {}x{}, median over seeds",
            t.exemplars.len(),
            t.size[0],
            t.size[1]
        );
        println!(
            "  {:<24} {:>8} {:>10} {:>8}",
            "type", "output", "exemplars", "points"
        );
        for (name, used, ex) in &t.median {
            println!(
                "  {:<24} {:>7.1}% {:>9.1}% {:>+8.1}",
                name,
                used * 100.0,
                ex * 100.0,
                (used - ex) * 100.0
            );
        }
        if let Some((seed, u)) = t.seeds.first() {
            println!("seed {seed} in detail:");
            print_type_usage(u);
        }
    }
    println!();
    println!("wall time {:.1} s on {} threads", r.wall_s, r.threads);
}
