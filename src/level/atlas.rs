//! Fast texel addressing for one database level.
//!
//! The database stores each exemplar's texels back to back
//! (`database::layout`); finding a texel from virtual atlas coordinates needs
//! its exemplar. Synthesis does that for every fetch, so the exemplar id,
//! row stride and base of each virtual column are tabulated once per level
//! (a few KiB: cached) and an index is `base[x] + y·stride[x] + x`.

use crate::database::c2::Quad;
use crate::database::{Database, Level, layout::MARGIN};

/// Per-column addressing of one level.
///
/// `#[repr(C)]` and plain old data: the GPU backend uploads the table as is
/// (`Column` in `kernels/common.wgsl`; layout checked by a test).
#[repr(C)]
#[derive(Clone, Copy, Default, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Column {
    /// `offset − x0` of the column's exemplar (may be negative).
    pub base: i32,
    pub stride: u32,
    /// Interior bounds of the exemplar (inclusive), in texels.
    pub min_x: i32,
    pub max_x: i32,
    pub max_y: i32,
}

/// One level of the database, ready for synthesis.
pub struct AtlasLevel<'a> {
    pub level: Level<'a>,
    pub columns: Vec<Column>,
    /// Seed slots filled per type (type seeding draws from these).
    pub seed_counts: Vec<u32>,
    /// C₂'s four diagonal texels for every texel u (the CPU correction
    /// scores C₂(u) from here rather than chasing `similar[u]` across the
    /// atlas; 32 bytes per texel, 32 MiB for the embedded database; built
    /// once per database, [`Database::c2`]).
    pub c2: &'a [Quad],
}

impl<'a> AtlasLevel<'a> {
    pub fn new(db: &'a Database, i: usize) -> AtlasLevel<'a> {
        let level = db.level(i);
        let mut columns = vec![Column::default(); level.layout.atlas_width as usize];
        for r in &level.layout.rects {
            for x in r.x0..r.x0 + r.width {
                columns[x as usize] = Column {
                    base: (r.offset as i64 - r.x0 as i64) as i32,
                    stride: r.width,
                    min_x: (r.x0 + MARGIN) as i32,
                    max_x: (r.x0 + r.width - 1 - MARGIN) as i32,
                    max_y: (r.height - 1 - MARGIN) as i32,
                };
            }
        }
        AtlasLevel {
            level,
            columns,
            c2: db.c2(i),
            seed_counts: db.meta().levels[i].seed_counts.clone(),
        }
    }

    /// Texel index of (x, y); the caller guarantees it lies in an exemplar.
    #[inline(always)]
    pub fn index(&self, x: i32, y: i32) -> usize {
        let c = &self.columns[x as usize];
        (c.base + y * c.stride as i32 + x) as usize
    }

    /// Appearance texel at (x, y).
    #[inline(always)]
    pub fn appearance(&self, x: i32, y: i32) -> u64 {
        self.level.appearance[self.index(x, y)]
    }

    /// Clamps (x, y) — inside an exemplar — into that exemplar's interior.
    #[inline(always)]
    pub fn clamp_interior(&self, x: i32, y: i32) -> (i32, i32) {
        let c = &self.columns[x as usize];
        (x.clamp(c.min_x, c.max_x), y.clamp(MARGIN as i32, c.max_y))
    }
}
