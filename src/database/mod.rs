//! The exemplar database (paper §4, DESIGN §4): everything synthesis draws
//! from, analysed once and stored compactly.
//!
//! Per level `i` (`0..=L`) and per exemplar texel:
//!
//! | data | bytes | why |
//! |---|---|---|
//! | A^i appearance, 4 × i16 | 8 | what correction scores |
//! | C₂^i best other match, packed x,y | 4 | the k = 2 candidate (C₁ is the identity, not stored) |
//! | T^i type id | 1 | type rejection |
//! | E⁰ height (level 0 only) | 2 | reconstruction |
//!
//! That is 15 B/px at level 0 and 13 B/px at each coarser level, ≈ 19.3 B per
//! base pixel with the pyramid (the paper: 32, 42⅔ with the pyramid). Coarse
//! heights E^{i>0} are not stored: synthesis reads heights only at level 0.

pub mod appearance;
mod build;
pub mod c2;
pub mod c2_cache;
pub mod cache;
pub mod default;
pub mod error;
pub mod file;
pub mod kdtree;
pub mod layout;
pub mod patchmatch;
pub mod pyramid;
pub mod types;

pub use build::{BuildOptions, BuildReport, ExemplarInput, build};
pub use error::DbError;
pub use layout::{LevelLayout, Rect};
pub use pyramid::Quantization;

use file::{Bytes, Kind};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// Metadata stored as JSON in the file's first section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Meta {
    pub exemplars: Vec<ExemplarMeta>,
    pub quantization: Quantization,
    pub levels: Vec<LevelMeta>,
    pub types: Vec<String>,
    /// Settings the database was built with.
    pub build: BuildMeta,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExemplarMeta {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub cell_size_m: f64,
    pub min_m: f64,
    pub max_m: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelMeta {
    pub layout: LevelLayout,
    pub basis: appearance::Basis,
    /// Mean distance (height units, √ of the weighted SSD) from each texel to
    /// its C₂ match: how alike the table's alternatives are.
    pub mean_match_distance: f64,
    /// Seed slots filled per type.
    pub seed_counts: Vec<u32>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BuildMeta {
    pub gaussian_sigma: f64,
    pub patchmatch_iterations: u32,
    pub exclusion_radius: u32,
    pub seeds_per_type: u32,
}

/// One level's arrays, borrowed from the database.
#[derive(Clone, Copy)]
pub struct Level<'a> {
    pub index: usize,
    pub layout: &'a LevelLayout,
    /// Exemplar id per virtual column ([`layout::NO_EXEMPLAR`] in gaps).
    pub columns: &'a [u8],
    pub appearance: &'a [u64],
    pub similar: &'a [u32],
    pub types: &'a [u8],
    /// `types × SEEDS_PER_TYPE` packed coordinates.
    pub seeds: &'a [u32],
}

impl Level<'_> {
    /// Texel index of a packed virtual coordinate; `None` outside every exemplar.
    pub fn index_of(&self, c: u32) -> Option<usize> {
        let (x, y) = layout::unpack(c);
        let e = self.layout.exemplar_at(self.columns, x, y)?;
        Some(self.layout.rects[e].index(x, y))
    }

    /// The k = 2 similarity candidates of texel `u` (paper eq. 3):
    /// C₁(u) = u (the coherent candidate, not stored) and C₂(u).
    pub fn candidates(&self, u: u32) -> [u32; 2] {
        let k = self.index_of(u).expect("u lies in an exemplar");
        [u, self.similar[k]]
    }
}

struct LevelRanges {
    appearance: Range<usize>,
    similar: Range<usize>,
    types: Range<usize>,
    seeds: Range<usize>,
}

/// A loaded (or freshly built) database. Cheap to share by reference; the
/// arrays are views into one buffer ([`file::Bytes`]).
pub struct Database {
    meta: Meta,
    bytes: Bytes,
    heights: Range<usize>,
    levels: Vec<LevelRanges>,
    columns: Vec<Vec<u8>>,
    /// C₂'s diagonal texels per level, built on first use ([`c2`]).
    c2: OnceLock<c2::Tables>,
    /// Where they are kept across processes, if anywhere
    /// ([`Database::keep_c2_at`]).
    c2_file: Option<PathBuf>,
}

impl std::fmt::Debug for Database {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Database")
            .field("exemplars", &self.meta.exemplars.len())
            .field("levels", &self.meta.levels.len())
            .field("bytes", &self.file_bytes().len())
            .finish()
    }
}

impl Database {
    /// Loads a `.tsdb` file, verifying every checksum and the contents
    /// (see [`file`](mod@file)).
    pub fn load(path: &Path) -> Result<Database, DbError> {
        Database::parse(Bytes::read(path)?, path)
    }

    /// Validates an in-memory `.tsdb` image (for embedding, pipes and the
    /// fuzzer); `name` stands for its origin in error messages. The bytes are
    /// copied once into aligned storage, as the arrays require.
    pub fn from_bytes(bytes: &[u8], name: &Path) -> Result<Database, DbError> {
        Database::parse(Bytes::copied(bytes), name)
    }

    /// Writes the database atomically.
    pub fn save(&self, path: &Path) -> Result<(), DbError> {
        Ok(crate::io::write_atomic(path, self.file_bytes())?)
    }

    /// The exact bytes of the `.tsdb` file.
    pub fn file_bytes(&self) -> &[u8] {
        self.bytes.as_slice()
    }

    pub fn meta(&self) -> &Meta {
        &self.meta
    }
    pub fn quantization(&self) -> Quantization {
        self.meta.quantization
    }
    /// Number of levels (L + 1).
    pub fn level_count(&self) -> usize {
        self.meta.levels.len()
    }
    pub fn type_names(&self) -> &[String] {
        &self.meta.types
    }
    /// E⁰ in height units, in level-0 texel order.
    pub fn heights(&self) -> &[u16] {
        bytemuck::cast_slice(&self.file_bytes()[self.heights.clone()])
    }
    /// Exemplar `i`'s level-0 heights in metres, with its cell size (what
    /// the build analysed, after any resampling): for previews and for
    /// measuring a synthesis against its exemplars.
    pub fn exemplar(&self, i: usize) -> crate::heightfield::Heightfield {
        let r = self.level(0).layout.rects[i];
        let q = self.quantization();
        let start = r.offset as usize;
        let data = self.heights()[start..start + r.texels() as usize]
            .iter()
            .map(|&u| q.metres(u as f64) as f32)
            .collect();
        let cell = self.meta.exemplars[i].cell_size_m;
        crate::heightfield::Heightfield::from_vec(r.width as usize, r.height as usize, cell, data)
            .expect("a database's exemplar rectangles are valid heightfield sizes")
    }
    pub fn level(&self, i: usize) -> Level<'_> {
        let b = self.file_bytes();
        let r = &self.levels[i];
        Level {
            index: i,
            layout: &self.meta.levels[i].layout,
            columns: &self.columns[i],
            appearance: bytemuck::cast_slice(&b[r.appearance.clone()]),
            similar: bytemuck::cast_slice(&b[r.similar.clone()]),
            types: &b[r.types.clone()],
            seeds: bytemuck::cast_slice(&b[r.seeds.clone()]),
        }
    }
    /// C₂'s diagonal texels of level `i` (the CPU correction's table,
    /// [`c2`]), gathered for every level on first use, or read from the
    /// file that keeps them ([`Database::keep_c2_at`]).
    ///
    /// Built without a lock: a caller that finds the tables missing builds
    /// them, and where two race one result is kept. No thread ever waits
    /// on another, so a synthesis started inside a rayon task (tiles run
    /// them so) cannot deadlock on the build's own parallel loop.
    pub fn c2(&self, i: usize) -> &[c2::Quad] {
        let tables = match self.c2.get() {
            Some(t) => t,
            None => {
                let file = self.c2_file.as_deref();
                let tables = file
                    .and_then(|p| c2_cache::load(p, self))
                    .unwrap_or_else(|| {
                        let built: Vec<_> = (0..self.level_count())
                            .map(|i| c2::gather(&self.level(i)))
                            .collect();
                        if let Some(p) = file {
                            c2_cache::save(p, self, &built);
                        }
                        c2::Tables::Gathered(built)
                    });
                let _ = self.c2.set(tables);
                self.c2.get().expect("set just above")
            }
        };
        tables.level(i)
    }

    /// Keeps C₂'s tables ([`Database::c2`]) in the file `path` across
    /// processes: they are read from it when it holds this database's
    /// tables, else gathered and written there. For databases in the
    /// cache directory ([`c2_cache`]); has no effect once the tables exist.
    pub fn keep_c2_at(&mut self, path: PathBuf) {
        self.c2_file = Some(path);
    }

    /// Which database this is, for files derived from it: the CRC-32 of
    /// the file's header (which covers every section's CRC) and its length.
    pub fn fingerprint(&self) -> c2_cache::Fingerprint {
        let b = self.file_bytes();
        c2_cache::Fingerprint {
            crc: file::header_crc(b),
            len: b.len() as u64,
        }
    }

    /// Exemplar base pixels (level 0).
    pub fn base_pixels(&self) -> u64 {
        self.meta.levels[0].layout.texels()
    }
    /// Database bytes per exemplar base pixel, pyramid included.
    pub fn bytes_per_pixel(&self) -> f64 {
        self.file_bytes().len() as f64 / self.base_pixels() as f64
    }

    /// Validates container and contents; the one path both [`Database::load`]
    /// and a build go through.
    fn parse(bytes: Bytes, path: &Path) -> Result<Database, DbError> {
        if cfg!(target_endian = "big") {
            return Err(DbError::File {
                path: path.to_path_buf(),
                message: "databases are little-endian and this host is big-endian".into(),
            });
        }
        let fail = |message: String| DbError::File {
            path: path.to_path_buf(),
            message,
        };
        let data = bytes.as_slice();
        let found = file::decode(data, path)?;
        let find = |kind: Kind, level: u32| -> Result<Range<usize>, DbError> {
            let mut it = found.iter().filter(|f| f.kind == kind && f.level == level);
            match (it.next(), it.next()) {
                (Some(f), None) => Ok(f.range.clone()),
                (None, _) => Err(fail(format!("missing {kind:?} section for level {level}"))),
                _ => Err(fail(format!(
                    "duplicate {kind:?} section for level {level}"
                ))),
            }
        };
        let meta: Meta = serde_json::from_slice(&data[find(Kind::Meta, 0)?])
            .map_err(|e| fail(format!("invalid metadata: {e}")))?;
        check_meta(&meta).map_err(fail)?;
        let expected_sections = 2 + 4 * meta.levels.len();
        if found.len() != expected_sections {
            return Err(fail(format!(
                "{} sections where {expected_sections} were expected",
                found.len()
            )));
        }
        let sized =
            |kind: Kind, level: usize, elem: usize, count: u64| -> Result<Range<usize>, DbError> {
                let r = find(kind, level as u32)?;
                if r.len() as u64 != count * elem as u64 {
                    return Err(fail(format!(
                        "{kind:?} section of level {level} has {} bytes, expected {}",
                        r.len(),
                        count * elem as u64
                    )));
                }
                Ok(r)
            };
        let heights = sized(Kind::Heights, 0, 2, meta.levels[0].layout.texels())?;
        let ntypes = meta.types.len();
        let mut levels = Vec::with_capacity(meta.levels.len());
        let mut columns = Vec::with_capacity(meta.levels.len());
        for (i, lm) in meta.levels.iter().enumerate() {
            let n = lm.layout.texels();
            levels.push(LevelRanges {
                appearance: sized(Kind::Appearance, i, 8, n)?,
                similar: sized(Kind::Similar, i, 4, n)?,
                types: sized(Kind::Types, i, 1, n)?,
                seeds: sized(Kind::Seeds, i, 4, (ntypes * types::SEEDS_PER_TYPE) as u64)?,
            });
            columns.push(lm.layout.column_table());
        }
        let db = Database {
            meta,
            bytes,
            heights,
            levels,
            columns,
            c2: OnceLock::new(),
            c2_file: None,
        };
        for i in 0..db.level_count() {
            db.check_level(i).map_err(fail)?;
        }
        Ok(db)
    }

    /// Every similarity entry and seed is an interior coordinate; every type
    /// id names a type; each seed has the type it is listed under.
    fn check_level(&self, i: usize) -> Result<(), String> {
        let l = self.level(i);
        let ntypes = self.meta.types.len();
        let interior = |c: u32| {
            let (x, y) = layout::unpack(c);
            l.layout
                .exemplar_at(l.columns, x, y)
                .filter(|&e| l.layout.rects[e].is_interior(x, y))
        };
        if let Some(k) = l
            .similar
            .par_iter()
            .position_any(|&c| interior(c).is_none())
        {
            return Err(format!(
                "level {i}: similarity entry {k} is not an interior coordinate"
            ));
        }
        if let Some(k) = l.types.par_iter().position_any(|&t| t as usize >= ntypes) {
            return Err(format!("level {i}: type id at texel {k} is out of range"));
        }
        for t in 0..ntypes {
            let list = &l.seeds[t * types::SEEDS_PER_TYPE..(t + 1) * types::SEEDS_PER_TYPE];
            let used = self.meta.levels[i].seed_counts[t] as usize;
            for (s, &c) in list.iter().enumerate() {
                let ok = if s < used {
                    interior(c).is_some_and(|e| {
                        let (x, y) = layout::unpack(c);
                        l.types[l.layout.rects[e].index(x, y)] as usize == t
                    })
                } else {
                    c == types::NO_SEED
                };
                if !ok {
                    return Err(format!("level {i}: seed {s} of type {t} is invalid"));
                }
            }
        }
        Ok(())
    }
}

/// Structural checks on metadata: the layout must be exactly what the
/// exemplar sizes imply, so array lengths and coordinates can be trusted.
fn check_meta(m: &Meta) -> Result<(), String> {
    if m.exemplars.is_empty() || m.exemplars.len() > layout::MAX_EXEMPLARS {
        return Err(format!(
            "{} exemplars (expected 1..={})",
            m.exemplars.len(),
            layout::MAX_EXEMPLARS
        ));
    }
    if m.levels.is_empty() || m.levels.len() > 16 {
        return Err(format!("{} levels (expected 1..=16)", m.levels.len()));
    }
    if m.types.is_empty() || m.types.len() > types::MAX_TYPES {
        return Err(format!(
            "{} types (expected 1..={})",
            m.types.len(),
            types::MAX_TYPES
        ));
    }
    let q = m.quantization;
    if !(q.offset_m.is_finite() && q.scale_m.is_finite() && q.scale_m > 0.0) {
        return Err("invalid height quantization".into());
    }
    let sizes: Vec<(u32, u32)> = m.exemplars.iter().map(|e| (e.width, e.height)).collect();
    let planned = layout::plan(&sizes, m.levels.len() - 1).ok_or("atlas too large")?;
    for (i, (lm, p)) in m.levels.iter().zip(&planned).enumerate() {
        if lm.layout != *p {
            return Err(format!(
                "level {i}: layout does not match the exemplar sizes"
            ));
        }
        if lm.seed_counts.len() != m.types.len()
            || lm
                .seed_counts
                .iter()
                .any(|&c| c as usize > types::SEEDS_PER_TYPE)
        {
            return Err(format!("level {i}: invalid seed counts"));
        }
        if p.rects
            .iter()
            .any(|r| r.width < 2 * layout::MARGIN + 1 || r.height < 2 * layout::MARGIN + 1)
        {
            return Err(format!("level {i}: an exemplar has no interior"));
        }
    }
    Ok(())
}
