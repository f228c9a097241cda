//! The protocol on one DEM: its single-exemplar database, a synthesis per
//! seed compared with the DEM, and the medians over seeds against issue 14's
//! targets.

use super::{Dem, Result, SuiteArgs};
use crate::bench::median;
use crate::eval::SizeArg;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;
use terrasynth::Heightfield;
use terrasynth::database::{BuildOptions, ExemplarInput, cache};
use terrasynth::eval::{self, Comparison, DESCRIPTORS, Reference};
use terrasynth::io::{self, WriteOptions};
use terrasynth::render::{self, RenderOptions};
use terrasynth::synth::{Params, Synthesizer};

/// The targets of issue 14's "Done means", per DEM (median over seeds).
pub(super) const TARGET_RATIO: f64 = 1.3;
pub(super) const TARGET_SLOPE: f64 = 0.10;
pub(super) const TARGET_RELIEF: f64 = 0.85;
pub(super) const TARGET_PITS: f64 = 1.5;

#[derive(Serialize)]
pub(super) struct SeedResult {
    pub(super) seed: u32,
    pub(super) synth_ms: f64,
    #[serde(flatten)]
    pub(super) comparison: Comparison,
}

/// Medians over seeds.
#[derive(Serialize)]
pub(super) struct Medians {
    pub(super) ratio: f64,
    /// Each descriptor's ratio.
    pub(super) descriptors: BTreeMap<&'static str, f64>,
    pub(super) median_slope_real: f64,
    pub(super) median_slope_synth: f64,
    pub(super) slope_ratio: f64,
    pub(super) relief_real_m: f64,
    pub(super) relief_kept: f64,
    pub(super) pits_real: f64,
    pub(super) pits_synth: f64,
    pub(super) pits_ratio: f64,
}

/// Whether each of issue 14's targets is met.
#[derive(Serialize)]
pub(super) struct Targets {
    pub(super) ratio: bool,
    pub(super) slope: bool,
    pub(super) relief: bool,
    pub(super) pits: bool,
}

#[derive(Serialize)]
pub(super) struct DemResult {
    pub(super) name: String,
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) cell_size_m: f64,
    pub(super) synth_size: [usize; 2],
    /// Real against real: the DEM's top half against its bottom half, in
    /// units of its left half against its right (about 1; what an equally
    /// real synthesis could score).
    pub(super) baseline: f64,
    pub(super) seeds: Vec<SeedResult>,
    pub(super) median: Medians,
    pub(super) targets: Targets,
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
pub(super) fn run_dem(dem: &Dem, a: &SuiteArgs, cache_dir: &Path) -> Result<DemResult> {
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
    let baseline = reference
        .baseline(&dem.hf)
        .map_err(|e| format!("{name}: {e}"))?;
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
        baseline,
        seeds,
        median,
        targets,
    })
}
