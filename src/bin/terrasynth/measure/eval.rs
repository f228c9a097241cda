//! `terrasynth eval`: how real a synthesized terrain is (issue 14) — one
//! synthesis against its reference, or the whole realism protocol over a
//! folder of DEMs (`--suite`, in `suite/`).

use crate::CliResult;
use crate::args::{Input, parse_size};
use serde::Serialize;
use std::path::{Path, PathBuf};
use terrasynth::Heightfield;
use terrasynth::database::Database;
use terrasynth::eval::{self, Comparison, Reference, TypeUsage, novelty};
use terrasynth::io::{self, CoordsMap};

#[derive(clap::Args)]
#[command(after_long_help = eval::help_text())]
pub struct Args {
    /// Synthesized heightfield (any readable format).
    #[arg(required_unless_present = "suite")]
    synth: Option<PathBuf>,
    /// Reference heightfield: the real terrain the synthesis should be like
    /// (at least 32 cells wide; it is also split into left and right
    /// halves). Also the exemplar novelty is measured against, unless
    /// --exemplars or --db names others. Without it only novelty is
    /// measured.
    #[arg(required_unless_present_any = ["suite", "exemplars", "db"])]
    reference: Option<PathBuf>,
    /// Measure novelty against these exemplars (any readable format)
    /// instead of the reference.
    #[arg(long, num_args = 1.., conflicts_with = "suite")]
    exemplars: Vec<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Write a picture of the comparison: histograms of every distribution
    /// (synthesis, reference, its halves), spectra, scalars.
    #[arg(long, conflicts_with = "suite", requires = "reference")]
    plot: Option<PathBuf>,
    /// Write the copy map: the synthesis's preview with every window that
    /// copies an exemplar filled red (the others outlined).
    #[arg(long, conflicts_with_all = ["suite", "no_novelty"])]
    copy_map: Option<PathBuf>,
    /// Skip the novelty measures (copy share, baseline, self-repetition).
    #[arg(long)]
    no_novelty: bool,
    #[command(flatten)]
    novelty: NoveltyArgs,
    /// A coordinates map of the synthesis (`synth --coords`) for type usage:
    /// each type's share of the output against its share of the exemplars.
    #[arg(long, requires = "db", conflicts_with = "suite")]
    coords: Option<PathBuf>,
    /// The database the synthesis was made from: its exemplars are what
    /// novelty is measured against (unless --exemplars), and with --coords
    /// it gives type usage.
    #[arg(long, conflicts_with = "suite")]
    db: Option<PathBuf>,
    #[command(flatten)]
    input: Input,
    #[command(flatten)]
    suite: crate::measure::suite::SuiteArgs,
}

/// The novelty rule's settings (`eval::novelty`; the defaults are those of
/// `../shared/tools/novelty.py`).
#[derive(clap::Args, Clone, Copy)]
pub struct NoveltyArgs {
    /// Novelty: window side in cells of the synthesis.
    #[arg(long, default_value_t = novelty::Params::default().window)]
    copy_window: usize,
    /// Novelty: heights are averaged over blocks of this side first.
    #[arg(long, default_value_t = novelty::Params::default().downsample)]
    copy_downsample: usize,
    /// Novelty: a window whose best normalised cross-correlation with any
    /// exemplar window (8 orientations) reaches this is a copy.
    #[arg(long, default_value_t = novelty::Params::default().threshold)]
    copy_threshold: f64,
    /// Novelty: windows whose standard deviation is under this fraction of
    /// the exemplars' median window are skipped as flat.
    #[arg(long, default_value_t = novelty::Params::default().flat)]
    copy_flat: f64,
    /// Novelty: at most this many windows are scored, evenly spread.
    #[arg(long, default_value_t = novelty::Params::default().max_windows)]
    copy_max_windows: usize,
}

impl NoveltyArgs {
    pub fn params(&self) -> novelty::Params {
        novelty::Params {
            window: self.copy_window,
            downsample: self.copy_downsample,
            threshold: self.copy_threshold,
            flat: self.copy_flat,
            max_windows: self.copy_max_windows,
        }
    }
}

/// What `--json` prints for one comparison.
#[derive(Serialize)]
struct Report<'a> {
    synth: &'a Path,
    #[serde(skip_serializing_if = "Option::is_none")]
    reference: Option<&'a Path>,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    comparison: Option<&'a Comparison>,
    #[serde(skip_serializing_if = "Option::is_none")]
    type_usage: Option<TypeUsage>,
    #[serde(skip_serializing_if = "Option::is_none")]
    novelty: Option<&'a novelty::Report>,
}

pub fn run(a: Args) -> CliResult {
    if a.suite.suite.is_some() {
        let novelty = (!a.no_novelty).then(|| a.novelty.params());
        return crate::measure::suite::run(&a.suite, novelty, a.json);
    }
    let sp = a.synth.as_deref().expect("clap requires it");
    let rp = a.reference.as_deref();
    let synth = a.input.read(sp)?;
    let reference = rp.map(|p| a.input.read(p)).transpose()?;
    let db =
        a.db.as_deref()
            .map(|d| Database::load(d).map_err(|e| format!("{}: {e}", d.display())))
            .transpose()?;
    // What novelty is measured against: --exemplars, else the database's,
    // else the reference.
    let exemplars: Vec<(String, Heightfield)> = if !a.exemplars.is_empty() {
        a.exemplars
            .iter()
            .map(|p| Ok((name(p), a.input.read(p)?)))
            .collect::<Result<_, io::IoError>>()?
    } else if let Some(db) = &db {
        (0..db.meta().exemplars.len())
            .map(|i| (db.meta().exemplars[i].name.clone(), db.exemplar(i)))
            .collect()
    } else {
        reference
            .iter()
            .zip(rp)
            .map(|(r, p)| (name(p), r.clone()))
            .collect()
    };
    let cmp = match (&reference, rp) {
        (Some(r), Some(p)) => Some(realism(&synth, sp, r, p)?),
        _ => None,
    };
    let usage = match (&a.coords, &db) {
        (Some(c), Some(d)) => Some(type_usage(c, d, (synth.width(), synth.height()))?),
        _ => None,
    };
    let novelty = if a.no_novelty {
        None
    } else {
        let ex: Vec<&Heightfield> = exemplars.iter().map(|e| &e.1).collect();
        let report = novelty::measure(&synth, &ex, &a.novelty.params())
            .map_err(|e| format!("{}: {e}", sp.display()))?;
        Some(report)
    };
    if let (Some(p), Some(r)) = (&a.plot, &cmp) {
        let title = format!("{} vs {}", name(sp), rp.map(name).unwrap_or_default());
        terrasynth::render::write_png(p, &eval::plot::plot(&r.1, &r.2, &r.0, &title))?;
        eprintln!("wrote {}", p.display());
    }
    if let (Some(p), Some(n)) = (&a.copy_map, &novelty) {
        terrasynth::render::write_png(p, &novelty::copy_map(&synth, &n.copies, &name(sp))?)?;
        eprintln!("wrote {}", p.display());
    }
    if a.json {
        let report = Report {
            synth: sp,
            reference: rp,
            comparison: cmp.as_ref().map(|c| &c.0),
            type_usage: usage,
            novelty: novelty.as_ref(),
        };
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "synthesis  {}  ({} x {}, cell {:.2} m)",
        sp.display(),
        synth.width(),
        synth.height(),
        synth.cell_size()
    );
    if let (Some(r), Some(p)) = (&reference, rp) {
        println!(
            "reference  {}  ({} x {}, cell {:.2} m)",
            p.display(),
            r.width(),
            r.height(),
            r.cell_size()
        );
    }
    if let Some(c) = &cmp {
        println!();
        print_comparison(&c.0);
    }
    if let Some(u) = &usage {
        println!();
        print_type_usage(u);
    }
    if let Some(n) = &novelty {
        println!();
        let names: Vec<&str> = exemplars.iter().map(|e| e.0.as_str()).collect();
        print_novelty(n, &names);
    }
    Ok(())
}

/// The realism comparison of `synth` with `reference` (descriptors of
/// both, with a note when their cell sizes differ).
fn realism(
    synth: &Heightfield,
    sp: &Path,
    reference: &Heightfield,
    rp: &Path,
) -> Result<(Comparison, Reference, eval::Descriptors), String> {
    let cells = (synth.cell_size(), reference.cell_size());
    if (cells.0 / cells.1 - 1.0).abs() > 0.01 {
        eprintln!(
            "note: cell sizes differ ({:.2} m vs {:.2} m): slopes and curvatures compare at different scales",
            cells.0, cells.1
        );
    }
    let (s, r) = rayon::join(
        || eval::describe(synth).map_err(|e| format!("{}: {e}", sp.display())),
        || Reference::new(reference).map_err(|e| format!("{}: {e}", rp.display())),
    );
    let (s, r) = (s?, r?);
    Ok((r.compare(&s), r, s))
}

/// The novelty figures: copies, the exemplars' own baseline, self-repetition.
pub fn print_novelty(n: &novelty::Report, exemplars: &[&str]) {
    let p = &n.copies.params;
    println!(
        "novelty ({}-cell windows averaged {}x{}, a copy at NCC >= {} in any of 8 orientations; {} flat windows skipped)",
        p.window, p.downsample, p.downsample, p.threshold, n.copies.flat
    );
    println!(
        "  copy share       {:>5.1} %  of {} windows, median best NCC {:.3}, against {}",
        n.copies.share * 100.0,
        n.copies.scored,
        n.copies.median_ncc,
        exemplars.join(", ")
    );
    match n.baseline {
        Some(b) => println!(
            "  baseline         {:>5.1} %  the exemplars' top halves against their bottom halves (real against real)",
            b * 100.0
        ),
        None => println!("  baseline            -    (no exemplar is two windows high)"),
    }
    println!(
        "  self-repetition  {:>5.1} %  of {} windows have a near-duplicate elsewhere in the synthesis, median best NCC {:.3}",
        n.repetition.share * 100.0,
        n.repetition.scored,
        n.repetition.median_ncc
    );
}

/// A file's name, for titles.
pub fn name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

/// Type usage from a coordinates map file and a database file; the map
/// must have the synthesis's size.
fn type_usage(coords: &Path, db: &Database, size: (usize, usize)) -> Result<TypeUsage, String> {
    let map = CoordsMap::read(coords).map_err(|e| e.to_string())?;
    if (map.width, map.height) != size {
        return Err(format!(
            "{}: the coordinates map is {}x{} but the synthesis is {}x{}",
            coords.display(),
            map.width,
            map.height,
            size.0,
            size.1
        ));
    }
    eval::type_usage(&map, db).map_err(|e| format!("{}: {e}", coords.display()))
}

/// Four significant digits, without exponent for ordinary magnitudes.
pub fn sig(v: f64) -> String {
    let a = v.abs();
    if !v.is_finite() {
        format!("{v}")
    } else if a == 0.0 {
        "0".into()
    } else if !(1e-3..1e5).contains(&a) {
        format!("{v:.3e}")
    } else {
        let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{v:.decimals$}")
    }
}

/// The descriptor table, the ratio and the headline quantities.
pub fn print_comparison(c: &Comparison) {
    println!(
        "{:<24} {:>10} {:>10} {:>10} {:>10} {:>8} {:>8} {:>7}",
        "descriptor (median)",
        "synthesis",
        "reference",
        "left",
        "right",
        "d(s,r)",
        "d(L,R)",
        "ratio"
    );
    for d in &c.descriptors {
        let label = if d.unit.is_empty() {
            d.id.to_string()
        } else {
            format!("{} ({})", d.id, d.unit)
        };
        println!(
            "{label:<24} {:>10} {:>10} {:>10} {:>10} {:>8.4} {:>8.4} {:>7.2}",
            sig(d.synth),
            sig(d.reference),
            sig(d.left),
            sig(d.right),
            d.distance,
            d.halves,
            d.ratio
        );
    }
    println!();
    println!(
        "realism ratio {:.2}  (mean of {} ratios d(s,r) / max(d(L,R), {}); 1.0 = as different as the reference's halves)",
        c.ratio,
        c.descriptors.len(),
        eval::compare::FLOOR
    );
    println!(
        "median slope {:.1}° → {:.1}° ({:.0} %)   relief {:.0} m → {:.0} m ({:.0} % kept)   pits {:.2} % → {:.2} % ({:.2}×)",
        c.median_slope.reference,
        c.median_slope.synth,
        c.median_slope.ratio * 100.0,
        c.relief.reference,
        c.relief.synth,
        c.relief.ratio * 100.0,
        c.pits.reference * 100.0,
        c.pits.synth * 100.0,
        c.pits.ratio
    );
    println!(
        "closed depressions {:.1} % → {:.1} % of the area  (more than {} m below their spill level: water with no valley out)",
        c.closed.reference * 100.0,
        c.closed.synth * 100.0,
        eval::drainage::CLOSED_DEPTH_M
    );
}

/// Type and exemplar shares, with the difference in points.
pub fn print_type_usage(u: &TypeUsage) {
    for (what, rows) in [("type", &u.types), ("exemplar", &u.exemplars)] {
        println!(
            "{:<28} {:>8} {:>10} {:>8}",
            format!("{what} usage ({} px)", u.pixels),
            "output",
            "exemplars",
            "points"
        );
        for s in rows.iter() {
            println!(
                "  {:<26} {:>7.1}% {:>9.1}% {:>+8.1}",
                s.name,
                s.used * 100.0,
                s.exemplars * 100.0,
                s.points()
            );
        }
    }
}

/// `--size` of the protocol: the exemplar's own, a whole multiple of its
/// sides (`3x`: a world 3× its side), or a fixed WxH.
#[derive(Clone, Copy, Debug)]
pub enum SizeArg {
    Exemplar,
    Times(usize),
    Fixed(usize, usize),
}

impl SizeArg {
    /// The synthesis size for an exemplar of `w × h`.
    pub fn of(self, w: usize, h: usize) -> (usize, usize) {
        match self {
            SizeArg::Exemplar => (w, h),
            SizeArg::Times(k) => (k * w, k * h),
            SizeArg::Fixed(w, h) => (w, h),
        }
    }
}

pub fn parse_size_arg(s: &str) -> Result<SizeArg, String> {
    if s == "exemplar" {
        return Ok(SizeArg::Exemplar);
    }
    if let Some(k) = s.strip_suffix(['x', 'X']) {
        return match k.parse::<usize>() {
            Ok(k @ 1..=16) => Ok(SizeArg::Times(k)),
            _ => Err(format!(
                "invalid size {s:?}: expected `exemplar`, a multiple of the exemplar's sides 1x..16x, or WxH"
            )),
        };
    }
    parse_size(s).map(|(w, h)| SizeArg::Fixed(w, h))
}
