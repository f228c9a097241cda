//! Type usage of the protocol: the typed database of every DEM with its
//! `<stem>_types.png` mask, and unconstrained syntheses from it, one per
//! seed: each type's share of the output against its share of the exemplars.

use super::{Dem, Result, SuiteArgs};
use crate::measure::bench::median;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;
use terrasynth::Heightfield;
use terrasynth::database::{BuildOptions, Database, ExemplarInput, cache};
use terrasynth::eval::{self, TypeUsage};
use terrasynth::io::TypeMask;
use terrasynth::io::{self, WriteOptions};
use terrasynth::render::{self, RenderOptions};
use terrasynth::synth::{Params, Synthesizer, source_map::source_map};

#[derive(Serialize)]
pub(super) struct TypedResult {
    pub(super) size: [usize; 2],
    pub(super) exemplars: Vec<String>,
    pub(super) seeds: Vec<(u32, TypeUsage)>,
    /// Per type: (name, median share of the output, share of the exemplars).
    pub(super) median: Vec<(String, f64, f64)>,
}

/// Type usage of unconstrained syntheses from the database of every DEM
/// with its type mask; None (with a note) when no DEM has a mask.
pub(super) fn run_typed(
    dems: &[Dem],
    a: &SuiteArgs,
    cache_dir: &Path,
) -> Result<Option<TypedResult>> {
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
        piece_size: a.piece_size,
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
    let (exact, picture) = (
        out.join(format!("{stem}_coords.png")),
        out.join(format!("{stem}_coords_preview.png")),
    );
    crate::synthesis::synth::write_coords(map, db, (Some(&exact), Some(&picture)))
        .map_err(|e| e.to_string())
}
