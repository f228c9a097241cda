//! `terrasynth db`: build and inspect exemplar databases.

use crate::{CliResult, args::Input, progress::Bar};
use std::path::{Path, PathBuf};
use std::time::Instant;
use terrasynth::database::c2;
use terrasynth::database::{self, BuildOptions, Database, ExemplarInput};
use terrasynth::io::TypeMask;

#[derive(clap::Subcommand)]
pub enum Command {
    /// Analyse exemplar heightfields into a database file (.tsdb).
    ///
    /// Type masks are 8-bit index PNGs with a JSON naming the indices; by
    /// default `<exemplar stem>_types.png` is used when it exists.
    Build(BuildArgs),
    /// Describe a database: exemplars, levels, types, memory.
    Info(InfoArgs),
}

#[derive(clap::Args)]
pub struct BuildArgs {
    /// Exemplar heightfields (any readable format).
    #[arg(required = true)]
    exemplars: Vec<PathBuf>,
    /// Type masks, one per exemplar, in the same order.
    #[arg(long, num_args = 1..)]
    types: Vec<PathBuf>,
    /// Do not look for `<stem>_types.png` masks.
    #[arg(long, conflicts_with = "types")]
    no_types: bool,
    /// Coarsest pyramid level L (fewer if an exemplar is small).
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u8).range(0..=12))]
    levels: u8,
    /// Resample every exemplar to this cell size in metres first.
    #[arg(long)]
    cell_size: Option<f64>,
    /// Fill nodata by harmonic interpolation instead of refusing it.
    #[arg(long)]
    fill_nodata: bool,
    /// Output database file.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    input: Input,
}

#[derive(clap::Args)]
pub struct InfoArgs {
    /// Database file.
    db: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(cmd: Command) -> CliResult {
    match cmd {
        Command::Build(a) => build(a),
        Command::Info(a) => info(a),
    }
}

fn stem(p: &Path) -> String {
    p.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

fn build(a: BuildArgs) -> CliResult {
    if !a.types.is_empty() && a.types.len() != a.exemplars.len() {
        return Err(format!(
            "{} type masks for {} exemplars: give one per exemplar, in order",
            a.types.len(),
            a.exemplars.len()
        )
        .into());
    }
    let t0 = Instant::now();
    let mut inputs = Vec::with_capacity(a.exemplars.len());
    for (i, p) in a.exemplars.iter().enumerate() {
        let heights = a.input.read(p)?;
        let mask_path = if let Some(t) = a.types.get(i) {
            Some(t.clone())
        } else if a.no_types {
            None
        } else {
            let auto = p.with_file_name(format!("{}_types.png", stem(p)));
            auto.exists().then_some(auto)
        };
        let types = mask_path.map(|m| TypeMask::read(&m)).transpose()?;
        inputs.push(ExemplarInput {
            name: stem(p),
            heights,
            types,
        });
    }
    let opts = BuildOptions {
        levels: a.levels as usize,
        cell_size: a.cell_size,
        fill_nodata: a.fill_nodata,
        ..Default::default()
    };
    let (db, report) = database::build(inputs, &opts, &Bar::new())?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    db.save(&a.output)?;
    eprintln!(
        "wrote {}: {} exemplars, {} levels, {} types, {:.1} MiB ({:.2} B/px) in {:.1} s",
        a.output.display(),
        db.meta().exemplars.len(),
        db.level_count(),
        db.type_names().len(),
        db.file_bytes().len() as f64 / (1 << 20) as f64,
        db.bytes_per_pixel(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

fn info(a: InfoArgs) -> CliResult {
    let t0 = Instant::now();
    let db = Database::load(&a.db)?;
    let load_ms = t0.elapsed().as_secs_f64() * 1e3;
    let m = db.meta();
    let q = db.quantization();
    // Type fractions at level 0.
    let l0 = db.level(0);
    let mut counts = vec![0u64; db.type_names().len()];
    for &t in l0.types {
        counts[t as usize] += 1;
    }
    let total = l0.types.len() as f64;
    if a.json {
        let v = serde_json::json!({
            "file": a.db,
            "bytes": db.file_bytes().len(),
            "base_pixels": db.base_pixels(),
            "bytes_per_pixel": db.bytes_per_pixel(),
            "load_ms": load_ms,
            "cpu_table_bytes": c2::table_bytes(&db),
            "quantization": {"offset_m": q.offset_m, "scale_m": q.scale_m},
            "exemplars": m.exemplars,
            "levels": m.levels.iter().enumerate().map(|(i, l)| serde_json::json!({
                "level": i,
                "atlas": [l.layout.atlas_width, l.layout.atlas_height],
                "texels": l.layout.texels(),
                "pca_explained": l.basis.explained,
                "mean_match_distance_m": l.mean_match_distance * q.scale_m,
            })).collect::<Vec<_>>(),
            "types": db.type_names().iter().zip(&counts).map(|(n, &c)| serde_json::json!({
                "name": n, "fraction": c as f64 / total
            })).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!("database:   {}", a.db.display());
    println!(
        "memory:     {:.1} MiB for {} exemplar pixels = {:.2} bytes/pixel (pyramid included); loaded in {load_ms:.1} ms",
        db.file_bytes().len() as f64 / (1 << 20) as f64,
        db.base_pixels(),
        db.bytes_per_pixel()
    );
    println!(
        "            + {:.1} MiB while synthesizing on the CPU (C2's diagonal texels, 32 bytes/texel)",
        c2::table_bytes(&db) as f64 / (1 << 20) as f64
    );
    println!(
        "heights:    h = {:.3} m + {:.5} m x unit (16-bit units)",
        q.offset_m, q.scale_m
    );
    println!("exemplars:");
    for e in &m.exemplars {
        println!(
            "  {:<28} {:>5} x {:<5} cell {:>7.2} m  heights {:>8.1} .. {:<8.1} m",
            e.name, e.width, e.height, e.cell_size_m, e.min_m, e.max_m
        );
    }
    println!("levels:");
    for (i, l) in m.levels.iter().enumerate() {
        println!(
            "  {i}: atlas {:>5} x {:<5} {:>9} texels  PCA explains {:>5.1}%  C2 match distance {:.2} m",
            l.layout.atlas_width,
            l.layout.atlas_height,
            l.layout.texels(),
            l.basis.explained * 100.0,
            l.mean_match_distance * q.scale_m
        );
    }
    println!("types:");
    for (n, &c) in db.type_names().iter().zip(&counts) {
        println!("  {:<20} {:>5.1}%", n, c as f64 / total * 100.0);
    }
    Ok(())
}
