//! `Database::build`: heightfields (+ optional type masks) → a database.

use super::appearance;
use super::error::DbError;
use super::file::{self, Kind, Section};
use super::layout::{self, MAX_EXEMPLARS};
use super::patchmatch;
use super::pyramid::{self, Grid, Quantization};
use super::types;
use super::{BuildMeta, Database, ExemplarMeta, LevelMeta, Meta};
use crate::heightfield::Heightfield;
use crate::io::TypeMask;
use crate::progress::Progress;
use std::path::Path;

/// Smallest exemplar side at the coarsest level: enough interior for
/// PatchMatch to find matches outside the trivial-match zone.
pub const MIN_COARSE_SIDE: usize = 16;

/// One exemplar to analyse.
#[derive(Debug, Clone)]
pub struct ExemplarInput {
    pub name: String,
    pub heights: Heightfield,
    pub types: Option<TypeMask>,
}

/// Build settings.
#[derive(Debug, Clone)]
pub struct BuildOptions {
    /// Requested coarsest level L (fewer when an exemplar is too small).
    pub levels: usize,
    /// Resample every exemplar to this cell size (metres) first. Without it,
    /// differing cell sizes are only reported: synthesis then mixes features
    /// of different physical scales, which is sometimes what an artist wants.
    pub cell_size: Option<f64>,
    /// Fill nodata by harmonic interpolation instead of refusing it.
    pub fill_nodata: bool,
    pub patchmatch_iterations: u32,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions {
            levels: 6,
            cell_size: None,
            fill_nodata: false,
            patchmatch_iterations: patchmatch::Params::default().iterations,
        }
    }
}

/// One level's arrays, before they are laid out in the file.
struct LevelArrays {
    appearance: Vec<u64>,
    similar: Vec<u32>,
    types: Vec<u8>,
    seeds: Vec<u32>,
}

/// What a build noticed.
#[derive(Debug, Clone, Default)]
pub struct BuildReport {
    /// Things the user should know (differing cell sizes, reduced levels…).
    pub warnings: Vec<String>,
}

/// Analyses exemplars into a database (see the module docs of
/// [`super`] for what is stored).
pub fn build(
    inputs: Vec<ExemplarInput>,
    opts: &BuildOptions,
    progress: &dyn Progress,
) -> Result<(Database, BuildReport), DbError> {
    let mut report = BuildReport::default();
    if inputs.is_empty() {
        return Err(DbError::NoExemplars);
    }
    if inputs.len() > MAX_EXEMPLARS {
        return Err(DbError::TooManyExemplars(inputs.len()));
    }
    let mut inputs = inputs;
    for ex in &mut inputs {
        let nodata = ex.heights.nodata_count();
        if nodata > 0 {
            if !opts.fill_nodata {
                return Err(DbError::Nodata {
                    name: ex.name.clone(),
                    count: nodata,
                });
            }
            crate::nodata::fill_nodata(&mut ex.heights).map_err(|e| DbError::File {
                path: ex.name.clone().into(),
                message: e.to_string(),
            })?;
            report
                .warnings
                .push(format!("{}: filled {nodata} nodata samples", ex.name));
        }
        if let Some(cell) = opts.cell_size {
            let f = ex.heights.cell_size() / cell;
            if (f - 1.0).abs() > 1e-6 {
                let (w, h) = (
                    ((ex.heights.width() as f64 * f).round() as usize).max(1),
                    ((ex.heights.height() as f64 * f).round() as usize).max(1),
                );
                let mut r = crate::resample::resample(&ex.heights, w, h)?;
                r.set_cell_size(cell)?;
                ex.types = ex.types.take().map(|m| resample_mask(&m, w, h));
                ex.heights = r;
            }
        }
    }
    let cells: Vec<f64> = inputs.iter().map(|e| e.heights.cell_size()).collect();
    let (cmin, cmax) = cells
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &c| (a.min(c), b.max(c)));
    if cmax > cmin * 1.01 {
        let list: Vec<String> = inputs
            .iter()
            .map(|e| format!("{} {:.2} m", e.name, e.heights.cell_size()))
            .collect();
        report.warnings.push(format!(
            "cell sizes differ ({}); features of different physical scale will mix — use --cell-size to resample",
            list.join(", ")
        ));
    }

    // Levels: as many as requested while every exemplar keeps MIN_COARSE_SIDE.
    let min_side = inputs
        .iter()
        .map(|e| e.heights.width().min(e.heights.height()))
        .min()
        .expect("non-empty");
    if let Some(e) = inputs
        .iter()
        .find(|e| e.heights.width().min(e.heights.height()) < MIN_COARSE_SIDE)
    {
        return Err(DbError::TooSmall {
            name: e.name.clone(),
            width: e.heights.width(),
            height: e.heights.height(),
            min: MIN_COARSE_SIDE,
        });
    }
    let max_levels = (min_side / MIN_COARSE_SIDE).ilog2() as usize;
    let levels = opts.levels.min(max_levels);
    if levels < opts.levels {
        report.warnings.push(format!(
            "using {levels} levels instead of {}: the smallest exemplar is {min_side} samples across",
            opts.levels
        ));
    }

    let sizes: Vec<(u32, u32)> = inputs
        .iter()
        .map(|e| (e.heights.width() as u32, e.heights.height() as u32))
        .collect();
    let plan = layout::plan(&sizes, levels).ok_or(DbError::AtlasTooLarge)?;

    let (gmin, gmax) = inputs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), e| {
            let s = e.heights.stats().expect("nodata was filled or refused");
            (a.min(s.min as f64), b.max(s.max as f64))
        });
    let q = Quantization::spanning(gmin, gmax);

    let names: Vec<String> = inputs.iter().map(|e| e.name.clone()).collect();
    let usizes: Vec<(usize, usize)> = sizes
        .iter()
        .map(|&(w, h)| (w as usize, h as usize))
        .collect();
    let masks: Vec<Option<&TypeMask>> = inputs.iter().map(|e| e.types.as_ref()).collect();
    let (type_names, t0) = types::unify(&masks, &usizes, &names)?;

    let exemplar_meta: Vec<ExemplarMeta> = inputs
        .iter()
        .map(|e| {
            let s = e.heights.stats().expect("checked");
            ExemplarMeta {
                name: e.name.clone(),
                width: e.heights.width() as u32,
                height: e.heights.height() as u32,
                cell_size_m: e.heights.cell_size(),
                min_m: s.min as f64,
                max_m: s.max as f64,
            }
        })
        .collect();

    let heights0: Vec<u16> = inputs
        .iter()
        .flat_map(|e| e.heights.data().iter().map(|&m| q.quantize(m as f64)))
        .collect();
    let pyramids: Vec<Vec<Grid>> = inputs
        .into_iter()
        .map(|e| {
            let base = Grid {
                width: e.heights.width(),
                height: e.heights.height(),
                data: e.heights.into_vec(),
            };
            pyramid::pyramid(base, levels)
        })
        .collect();

    let total: u64 = plan.iter().map(|l| l.texels()).sum();
    progress.start("analysing exemplars", total * 2);
    let mut level_meta = Vec::with_capacity(levels + 1);
    let mut arrays: Vec<LevelArrays> = Vec::with_capacity(levels + 1);
    for (i, lay) in plan.iter().enumerate() {
        let grids: Vec<&Grid> = pyramids.iter().map(|p| &p[i]).collect();
        let pca = appearance::pca(&grids, &q);
        let projected = appearance::project(&grids, &q, &pca);
        let basis = pca.basis;
        progress.advance(lay.texels());
        let (similar, dist) = patchmatch::similar(
            lay,
            &projected.features,
            &projected.keys,
            patchmatch::Params {
                iterations: opts.patchmatch_iterations,
                level: i as u32,
                ..Default::default()
            },
        );
        let texels = projected.texels;
        progress.advance(lay.texels());
        let mean_match_distance = projected.feature_scale
            * dist.iter().map(|&d| (d as f64).sqrt()).sum::<f64>()
            / dist.len() as f64;
        let tlevel: Vec<u8> = t0
            .iter()
            .zip(&lay.rects)
            .zip(&usizes)
            .flat_map(|((t, r), &(w, _))| {
                types::majority(t, w, i, r.width as usize, r.height as usize)
            })
            .collect();
        let seeds = types::seeds(lay, &tlevel, type_names.len(), i as u32);
        let seed_counts = (0..type_names.len())
            .map(|t| {
                seeds[t * types::SEEDS_PER_TYPE..(t + 1) * types::SEEDS_PER_TYPE]
                    .iter()
                    .filter(|&&c| c != types::NO_SEED)
                    .count() as u32
            })
            .collect();
        level_meta.push(LevelMeta {
            layout: lay.clone(),
            basis,
            mean_match_distance,
            seed_counts,
        });
        arrays.push(LevelArrays {
            appearance: texels,
            similar,
            types: tlevel,
            seeds,
        });
    }
    progress.finish();

    let meta = Meta {
        exemplars: exemplar_meta,
        quantization: q,
        levels: level_meta,
        types: type_names,
        build: BuildMeta {
            gaussian_sigma: appearance::SIGMA,
            patchmatch_iterations: opts.patchmatch_iterations,
            exclusion_radius: patchmatch::EXCLUSION,
            seeds_per_type: types::SEEDS_PER_TYPE as u32,
        },
    };
    let meta_json = serde_json::to_vec(&meta).expect("metadata serializes");
    let mut sections = vec![
        Section {
            kind: Kind::Meta,
            level: 0,
            bytes: &meta_json,
        },
        Section {
            kind: Kind::Heights,
            level: 0,
            bytes: bytemuck::cast_slice(&heights0),
        },
    ];
    for (i, arr) in arrays.iter().enumerate() {
        let (a, s, t, sd) = (&arr.appearance, &arr.similar, &arr.types, &arr.seeds);
        let level = i as u32;
        sections.push(Section {
            kind: Kind::Appearance,
            level,
            bytes: bytemuck::cast_slice(a),
        });
        sections.push(Section {
            kind: Kind::Similar,
            level,
            bytes: bytemuck::cast_slice(s),
        });
        sections.push(Section {
            kind: Kind::Types,
            level,
            bytes: t,
        });
        sections.push(Section {
            kind: Kind::Seeds,
            level,
            bytes: bytemuck::cast_slice(sd),
        });
    }
    let db = Database::parse(file::encode(&sections), Path::new("<built database>"))?;
    Ok((db, report))
}

/// Nearest-neighbour resampling of a type mask alongside its heightfield.
fn resample_mask(m: &TypeMask, w: usize, h: usize) -> TypeMask {
    let mut indices = Vec::with_capacity(w * h);
    for y in 0..h {
        let sy = ((y as f64 + 0.5) * m.height as f64 / h as f64) as usize;
        for x in 0..w {
            let sx = ((x as f64 + 0.5) * m.width as f64 / w as f64) as usize;
            indices.push(m.indices[sy.min(m.height - 1) * m.width + sx.min(m.width - 1)]);
        }
    }
    TypeMask {
        width: w,
        height: h,
        indices,
        names: m.names.clone(),
    }
}
