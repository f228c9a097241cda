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

mod dem;
mod report;
mod typed;

use crate::CliResult;
use crate::args::parse_size;
use crate::measure::eval::{SizeArg, parse_size_arg};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;
use terrasynth::Heightfield;
use terrasynth::database::default;
use terrasynth::eval::novelty;
use terrasynth::io;
use terrasynth::synth::Params;

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
    /// Synthesis size per DEM: `exemplar` (its own size), a multiple of its
    /// sides (`3x`: a world 3× its side) or WxH.
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
    /// Side in pixels of the coarse start's exemplar pieces (synth's
    /// default): the knob between new and faithful.
    #[arg(long, default_value_t = Params::default().piece_size, requires = "suite")]
    piece_size: usize,
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
struct SuiteReport {
    dir: PathBuf,
    novelty: Option<novelty::Params>,
    seeds: Vec<u32>,
    jitter: f64,
    passes: u32,
    piece_size: usize,
    threads: usize,
    dems: Vec<dem::DemResult>,
    #[serde(skip_serializing_if = "Option::is_none")]
    typed: Option<typed::TypedResult>,
    wall_s: f64,
}

type Result<T> = std::result::Result<T, String>;

/// Runs the protocol; `novelty`: the copy-share rule (None: skipped).
pub fn run(a: &SuiteArgs, novelty: Option<novelty::Params>, json: bool) -> CliResult {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.jobs.unwrap_or(0))
        .build()?;
    pool.install(|| run_in_pool(a, novelty, json))
}

fn run_in_pool(a: &SuiteArgs, novelty: Option<novelty::Params>, json: bool) -> CliResult {
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
        "realism protocol: {} DEMs from {}, seeds {:?}, jitter {}, {} passes, {}-px pieces, {} threads",
        chosen.len(),
        dir.display(),
        a.seeds,
        a.jitter,
        a.passes,
        a.piece_size,
        rayon::current_num_threads()
    );
    let results = chosen
        .par_iter()
        .map(|d| dem::run_dem(d, a, novelty.as_ref(), &cache_dir))
        .collect::<Result<Vec<_>>>()?;
    let typed = if a.no_typed {
        None
    } else {
        typed::run_typed(&dems, a, &cache_dir)?
    };
    let report = SuiteReport {
        dir: dir.to_path_buf(),
        novelty,
        seeds: a.seeds.clone(),
        jitter: a.jitter,
        passes: a.passes,
        piece_size: a.piece_size,
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
        report::print_report(&report);
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
            let name = crate::measure::eval::name(&p.with_extension(""));
            let mask = p.with_file_name(format!("{name}_types.png"));
            Ok(Dem {
                name,
                hf,
                mask: mask.exists().then_some(mask),
            })
        })
        .collect()
}
