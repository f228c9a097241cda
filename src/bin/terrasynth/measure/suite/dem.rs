//! The protocol on one DEM: its single-exemplar database, a synthesis per
//! seed compared with the DEM (realism, and novelty: its copy share against
//! the DEM and its self-repetition), and the medians over seeds against the
//! targets of issues 14 and 46.

use super::{Dem, Result, SuiteArgs};
use crate::measure::bench::median;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;
use terrasynth::Heightfield;
use terrasynth::database::{BuildOptions, ExemplarInput, cache};
use terrasynth::eval::{self, Comparison, DESCRIPTORS, Reference, novelty};
use terrasynth::io::{self, WriteOptions};
use terrasynth::render::{self, RenderOptions};
use terrasynth::synth::{Params, Synthesizer};

/// The targets of issues 14 and 46, per DEM (median over seeds): realism
/// ratio, median slope, relief, pits, and the copy share's margin over the
/// DEM's own halves.
pub(super) const TARGET_RATIO: f64 = 1.2;
pub(super) const TARGET_SLOPE: f64 = 0.10;
pub(super) const TARGET_RELIEF: f64 = 0.85;
pub(super) const TARGET_PITS: f64 = 1.5;
pub(super) const TARGET_COPY_POINTS: f64 = 0.05;

/// One synthesis's novelty figures (`eval::novelty`).
#[derive(Serialize, Clone, Copy)]
pub(super) struct SeedNovelty {
    pub(super) copy_share: f64,
    pub(super) median_ncc: f64,
    pub(super) windows: usize,
    pub(super) repetition: f64,
}

#[derive(Serialize)]
pub(super) struct SeedResult {
    pub(super) seed: u32,
    pub(super) synth_ms: f64,
    #[serde(flatten)]
    pub(super) comparison: Comparison,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(super) novelty: Option<SeedNovelty>,
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
    /// [`terrasynth::eval::drainage::closed_share`]; not a target.
    pub(super) closed_real: f64,
    pub(super) closed_synth: f64,
    /// Copy share and self-repetition (when novelty is measured).
    pub(super) copy_share: Option<f64>,
    pub(super) repetition: Option<f64>,
}

/// Whether each target is met (`copies`: None when novelty is not measured).
#[derive(Serialize)]
pub(super) struct Targets {
    pub(super) ratio: bool,
    pub(super) slope: bool,
    pub(super) relief: bool,
    pub(super) pits: bool,
    pub(super) copies: Option<bool>,
}

#[derive(Serialize)]
pub(super) struct DemResult {
    pub(super) name: String,
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) cell_size_m: f64,
    pub(super) synth_size: [usize; 2],
    /// Correction passes per level of the synthesis, finest first: the
    /// start level takes more for an exemplar smooth at the pixel scale
    /// (`Synthesizer::level_passes`).
    pub(super) level_passes: Vec<u32>,
    /// Real against real: the DEM's top half against its bottom half, in
    /// units of its left half against its right (about 1; what an equally
    /// real synthesis could score).
    pub(super) baseline: f64,
    /// The copy share of the DEM's top half against its bottom half: what
    /// real terrain scores against another part of itself.
    pub(super) copy_baseline: Option<f64>,
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
    copies: Option<&novelty::Novelty>,
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
    if let Some(n) = copies {
        let img = novelty::copy_map(synth, n, stem).map_err(|e| err(&e))?;
        render::write_png(&out.join(format!("{stem}_copies.png")), &img).map_err(|e| err(&e))?;
    }
    Ok(())
}

/// The protocol on one DEM.
pub(super) fn run_dem(
    dem: &Dem,
    a: &SuiteArgs,
    novelty: Option<&novelty::Params>,
    cache_dir: &Path,
) -> Result<DemResult> {
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
    let copy_baseline = novelty
        .map(|p| novelty::halves(&dem.hf, p).map(|n| n.share))
        .transpose()
        .map_err(|e| format!("{name}: {e}"))?;
    let (w, h) = a.synth_size.of(dem.hf.width(), dem.hf.height());
    let params = Params {
        jitter: a.jitter,
        passes: a.passes,
        piece_size: a.piece_size,
        ..Params::default()
    };
    let synth = Synthesizer::new(&db, params).map_err(|e| format!("{name}: {e}"))?;
    let level_passes = synth.level_passes(w, h);
    eprintln!("{name}: correction passes per level, finest first: {level_passes:?}");
    let mut seeds = Vec::new();
    for (k, &seed) in a.seeds.iter().enumerate() {
        let ts = Instant::now();
        let out = synth.run(w, h, seed).map_err(|e| format!("{name}: {e}"))?;
        let synth_ms = ts.elapsed().as_secs_f64() * 1e3;
        let d = eval::describe(&out.heightfield).map_err(|e| format!("{name}: {e}"))?;
        let c = reference.compare(&d);
        let measured = novelty
            .map(|p| {
                let copies = novelty::copies(&out.heightfield, &[&dem.hf], p)?;
                let repetition = novelty::repetition(&out.heightfield, &[&dem.hf], p)?;
                Ok((copies, repetition))
            })
            .transpose()
            .map_err(|e: eval::EvalError| format!("{name}: {e}"))?;
        if let Some(o) = &a.out_dir {
            let plot = (k == 0).then_some((&reference, &d, &c));
            write_outputs(
                o,
                &format!("{name}_s{seed}"),
                &dem.hf,
                &out.heightfield,
                plot,
                measured.as_ref().map(|m| &m.0),
            )?;
        }
        let novelty = measured.map(|(c, r)| SeedNovelty {
            copy_share: c.share,
            median_ncc: c.median_ncc,
            windows: c.scored,
            repetition: r.share,
        });
        let copies = novelty
            .map(|n| {
                format!(
                    ", copies {:.0} % (median NCC {:.3}), repeats {:.0} %",
                    n.copy_share * 100.0,
                    n.median_ncc,
                    n.repetition * 100.0
                )
            })
            .unwrap_or_default();
        eprintln!(
            "{name} seed {seed}: ratio {:.2}, median slope {:.1}° → {:.1}°, relief kept {:.0} %, pits ×{:.2}, closed {:.1} %{copies} ({:.1} s)",
            c.ratio,
            c.median_slope.reference,
            c.median_slope.synth,
            c.relief.ratio * 100.0,
            c.pits.ratio,
            c.closed.synth * 100.0,
            ts.elapsed().as_secs_f64()
        );
        seeds.push(SeedResult {
            seed,
            synth_ms,
            comparison: c,
            novelty,
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
        closed_real: first.closed.reference,
        closed_synth: med(&|c| c.closed.synth),
        copy_share: novelty_median(&seeds, |n| n.copy_share),
        repetition: novelty_median(&seeds, |n| n.repetition),
    };
    let targets = Targets {
        ratio: median.ratio <= TARGET_RATIO,
        slope: (median.slope_ratio - 1.0).abs() <= TARGET_SLOPE,
        relief: median.relief_kept >= TARGET_RELIEF,
        pits: median.pits_ratio <= TARGET_PITS,
        copies: median
            .copy_share
            .zip(copy_baseline)
            .map(|(c, b)| c <= b + TARGET_COPY_POINTS + 1e-9),
    };
    Ok(DemResult {
        name: name.clone(),
        width: dem.hf.width(),
        height: dem.hf.height(),
        cell_size_m: dem.hf.cell_size(),
        synth_size: [w, h],
        level_passes,
        baseline,
        copy_baseline,
        seeds,
        median,
        targets,
    })
}

/// The median over seeds of a novelty figure (None when not measured).
fn novelty_median(seeds: &[SeedResult], f: impl Fn(&SeedNovelty) -> f64) -> Option<f64> {
    let v: Vec<f64> = seeds
        .iter()
        .filter_map(|s| s.novelty.as_ref().map(&f))
        .collect();
    (!v.is_empty()).then(|| median(v))
}
