//! Where round one of hole filling runs — stage `fill_ssd`, the patch
//! engine's data-parallel cost (DESIGN §7): on the CPU
//! ([`fill_ssd_table`], rayon over candidates, `wide` SIMD
//! over cells) or, with the `gpu` feature, as `kernels/fill_ssd.wgsl`, with
//! every source's candidate cells uploaded once per synthesis. Both give
//! the same table, so the same terrain bytes. Which one runs is the
//! [`Engine`] the caller chose, as for every stage.

use crate::backend::engine::Engine;
use crate::patch::{Library, PatchError};
use crate::stages::fill_ssd::fill_ssd_table;

/// The backend of stage `fill_ssd`.
pub enum FillCost {
    /// rayon + SIMD, the reference.
    Cpu,
    /// The WGSL kernel; one device buffer per source.
    #[cfg(feature = "gpu")]
    Gpu {
        ctx: std::sync::Arc<crate::backend::gpu::Context>,
        sources: Vec<crate::backend::gpu::fill_ssd::FillSource>,
    },
}

impl FillCost {
    /// Stage `fill_ssd` for `lib` on `engine` (`Engine::choose`, as for
    /// a synthesis); on a GPU every source's candidate cells are uploaded
    /// here, once.
    #[cfg_attr(not(feature = "gpu"), allow(unused_variables))]
    pub fn new(engine: &Engine, lib: &Library) -> Result<FillCost, PatchError> {
        match engine {
            Engine::Cpu(_) => Ok(FillCost::Cpu),
            #[cfg(feature = "gpu")]
            Engine::Gpu(ctx) => {
                let m = lib.params.patch / crate::patch::place::candidates::COARSE;
                let sources = lib
                    .sources
                    .iter()
                    .map(|s| ctx.upload_fill_source(&s.fill_cells, m * m))
                    .collect::<Result<_, _>>()?;
                Ok(FillCost::Gpu {
                    ctx: ctx.clone(),
                    sources,
                })
            }
        }
    }

    /// `"cpu"` or `"gpu"`, for reports.
    pub fn name(&self) -> &'static str {
        match self {
            FillCost::Cpu => "cpu",
            #[cfg(feature = "gpu")]
            FillCost::Gpu { .. } => "gpu",
        }
    }

    /// Source `si`'s round-one table against one window (see
    /// [`fill_ssd_table`]): entry `k · transforms + v`.
    pub(crate) fn table(
        &self,
        lib: &Library,
        si: usize,
        user: &[Vec<i32>],
        mask: &[Vec<i32>],
        count: i64,
    ) -> Result<Vec<u64>, PatchError> {
        match self {
            FillCost::Cpu => Ok(fill_ssd_table(
                user,
                mask,
                &lib.sources[si].fill_cells,
                count,
            )),
            #[cfg(feature = "gpu")]
            FillCost::Gpu { ctx, sources } => Ok(ctx.fill_ssd(&sources[si], user, mask, count)?),
        }
    }
}
