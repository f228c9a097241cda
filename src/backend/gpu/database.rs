//! The GPU backend bound to one database: the atlas levels and level-0
//! heights that stay on the device for every synthesis.

use super::Context;
use crate::backend::BackendError;
use crate::level::atlas::AtlasLevel;
use crate::stages::correct::GuideCell;
use std::sync::Arc;

/// One database level on the device.
pub(super) struct Level {
    pub(super) columns: wgpu::Buffer,
    pub(super) appearance: wgpu::Buffer,
    pub(super) similar: wgpu::Buffer,
    /// Seed counts, seeds and texel types in one buffer (see
    /// `kernels/correct.wgsl`'s `type_data`).
    pub(super) type_data: wgpu::Buffer,
    pub(super) type_count: u32,
}

/// The GPU backend bound to one database: its atlas levels and level-0
/// heights uploaded once.
pub struct Gpu {
    pub(super) ctx: Arc<Context>,
    pub(super) levels: Vec<Level>,
    pub(super) heights: wgpu::Buffer,
    /// Bound where a control is off (the kernel never reads it then).
    pub(super) placeholder: wgpu::Buffer,
}

/// A level's type tables as `correct.wgsl` reads them: seed counts, seeds,
/// then the texel types packed four per word (little-endian, like the
/// bytes); one zero word at least (a binding needs a buffer).
fn type_data(seed_counts: &[u32], seeds: &[u32], types: &[u8]) -> Vec<u32> {
    let mut d = Vec::with_capacity(seed_counts.len() + seeds.len() + types.len() / 4 + 1);
    d.extend_from_slice(seed_counts);
    d.extend_from_slice(seeds);
    d.extend(types.chunks(4).map(|c| {
        let mut w = [0u8; 4];
        w[..c.len()].copy_from_slice(c);
        u32::from_le_bytes(w)
    }));
    if d.is_empty() {
        d.push(0);
    }
    d
}

impl Gpu {
    /// Uploads `atlas` (every level of one database) and its level-0
    /// `heights`.
    pub fn new(
        ctx: Arc<Context>,
        atlas: &[AtlasLevel<'_>],
        heights: &[u16],
    ) -> Result<Gpu, BackendError> {
        let levels = atlas
            .iter()
            .map(|a| {
                Ok(Level {
                    columns: ctx.storage("atlas columns", bytemuck::cast_slice(&a.columns))?,
                    appearance: ctx
                        .storage("appearance", bytemuck::cast_slice(a.level.appearance))?,
                    similar: ctx.storage("similarity", bytemuck::cast_slice(a.level.similar))?,
                    type_data: ctx.storage(
                        "type tables",
                        bytemuck::cast_slice(&type_data(
                            &a.seed_counts,
                            a.level.seeds,
                            a.level.types,
                        )),
                    )?,
                    type_count: a.seed_counts.len() as u32,
                })
            })
            .collect::<Result<_, BackendError>>()?;
        let heights = ctx.storage("heights", bytemuck::cast_slice(heights))?;
        let placeholder = ctx.storage("placeholder", bytemuck::bytes_of(&GuideCell::default()))?;
        Ok(Gpu {
            ctx,
            levels,
            heights,
            placeholder,
        })
    }

    pub fn context(&self) -> &Arc<Context> {
        &self.ctx
    }
}
