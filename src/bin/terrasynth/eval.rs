//! `terrasynth eval`: how real a synthesized terrain is (issue 14) — one
//! synthesis against its reference, or the whole realism protocol over a
//! folder of DEMs (`--suite`, in `suite.rs`).

use crate::CliResult;
use crate::args::{Input, parse_size};
use serde::Serialize;
use std::path::{Path, PathBuf};
use terrasynth::database::Database;
use terrasynth::eval::{self, Comparison, Reference, TypeUsage};
use terrasynth::io::CoordsMap;

#[derive(clap::Args)]
#[command(after_long_help = eval::help_text())]
pub struct Args {
    /// Synthesized heightfield (any readable format).
    #[arg(required_unless_present = "suite", requires = "reference")]
    synth: Option<PathBuf>,
    /// Reference heightfield: the real terrain the synthesis should be like
    /// (at least 32 cells wide; it is also split into left and right halves).
    reference: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Write a picture of the comparison: histograms of every distribution
    /// (synthesis, reference, its halves), spectra, scalars.
    #[arg(long, conflicts_with = "suite")]
    plot: Option<PathBuf>,
    /// A coordinates map of the synthesis (`synth --coords`) for type usage:
    /// each type's share of the output against its share of the exemplars.
    #[arg(long, requires = "db", conflicts_with = "suite")]
    coords: Option<PathBuf>,
    /// The database the coordinates map was synthesized from.
    #[arg(long, requires = "coords")]
    db: Option<PathBuf>,
    #[command(flatten)]
    input: Input,
    #[command(flatten)]
    suite: crate::suite::SuiteArgs,
}

/// What `--json` prints for one comparison.
#[derive(Serialize)]
struct Report<'a> {
    synth: &'a Path,
    reference: &'a Path,
    #[serde(flatten)]
    comparison: &'a Comparison,
    #[serde(skip_serializing_if = "Option::is_none")]
    type_usage: Option<TypeUsage>,
}

pub fn run(a: Args) -> CliResult {
    if a.suite.suite.is_some() {
        return crate::suite::run(&a.suite, a.json);
    }
    let (sp, rp) = (
        a.synth.as_deref().expect("clap requires it"),
        a.reference.as_deref().expect("clap requires it"),
    );
    let (synth, reference) = (a.input.read(sp)?, a.input.read(rp)?);
    let cells = (synth.cell_size(), reference.cell_size());
    if (cells.0 / cells.1 - 1.0).abs() > 0.01 {
        eprintln!(
            "note: cell sizes differ ({:.2} m vs {:.2} m): slopes and curvatures compare at different scales",
            cells.0, cells.1
        );
    }
    let (s, r) = rayon::join(
        || eval::describe(&synth).map_err(|e| format!("{}: {e}", sp.display())),
        || Reference::new(&reference).map_err(|e| format!("{}: {e}", rp.display())),
    );
    let (s, r) = (s?, r?);
    let cmp = r.compare(&s);
    let usage = match (&a.coords, &a.db) {
        (Some(c), Some(d)) => Some(type_usage(c, d, (synth.width(), synth.height()))?),
        _ => None,
    };
    if let Some(p) = &a.plot {
        let title = format!("{} vs {}", name(sp), name(rp));
        terrasynth::render::write_png(p, &eval::plot::plot(&r, &s, &cmp, &title))?;
        eprintln!("wrote {}", p.display());
    }
    if a.json {
        let report = Report {
            synth: sp,
            reference: rp,
            comparison: &cmp,
            type_usage: usage,
        };
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    println!(
        "synthesis  {}  ({} x {}, cell {:.2} m)",
        sp.display(),
        synth.width(),
        synth.height(),
        cells.0
    );
    println!(
        "reference  {}  ({} x {}, cell {:.2} m)",
        rp.display(),
        reference.width(),
        reference.height(),
        cells.1
    );
    println!();
    print_comparison(&cmp);
    if let Some(u) = &usage {
        println!();
        print_type_usage(u);
    }
    Ok(())
}

/// A file's name, for titles.
pub fn name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}

/// Type usage from a coordinates map file and a database file; the map
/// must have the synthesis's size.
fn type_usage(coords: &Path, db: &Path, size: (usize, usize)) -> Result<TypeUsage, String> {
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
    let db = Database::load(db).map_err(|e| e.to_string())?;
    eval::type_usage(&map, &db).map_err(|e| format!("{}: {e}", coords.display()))
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

/// `--size` of the protocol: the exemplar's own, or a fixed WxH.
#[derive(Clone, Copy, Debug)]
pub enum SizeArg {
    Exemplar,
    Fixed(usize, usize),
}

pub fn parse_size_arg(s: &str) -> Result<SizeArg, String> {
    if s == "exemplar" {
        Ok(SizeArg::Exemplar)
    } else {
        parse_size(s).map(|(w, h)| SizeArg::Fixed(w, h))
    }
}
