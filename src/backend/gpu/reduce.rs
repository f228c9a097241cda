//! Stages `reduce_types` and `reduce_weights` on the GPU
//! (`kernels/reduce_types.wgsl`, `kernels/reduce_weights.wgsl`): one level's
//! control raster from the finer level's.

use super::{Gpu, GpuRaster, groups};
use crate::backend::BackendError;
use crate::backend::kernels::{ReduceTypesUniform, ReduceWeightsUniform};

impl Gpu {
    /// One dispatch of a reduction from `child` into a new `width × height`
    /// raster.
    fn reduce(
        &self,
        what: &'static str,
        pipeline: &wgpu::ComputePipeline,
        uniform: &[u8],
        child: &GpuRaster,
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        let bytes = (width as u64)
            .checked_mul(height as u64)
            .and_then(|n| n.checked_mul(4))
            .unwrap_or(u64::MAX);
        let buf = self.ctx.storage_empty(what, bytes)?;
        self.ctx.dispatch(
            None,
            pipeline,
            uniform,
            &[&child.buf, &buf],
            (groups(width), groups(height)),
        );
        Ok(GpuRaster { width, height, buf })
    }

    pub(super) fn dispatch_reduce_types(
        &self,
        child: &GpuRaster,
        width: usize,
        height: usize,
        full: u32,
    ) -> Result<GpuRaster, BackendError> {
        let u = ReduceTypesUniform {
            width: width as u32,
            height: height as u32,
            child_width: child.width as u32,
            child_height: child.height as u32,
            full,
            ..Default::default()
        };
        let p = &self.ctx.reduce_types;
        self.reduce("type sets", p, bytemuck::bytes_of(&u), child, width, height)
    }

    pub(super) fn dispatch_reduce_weights(
        &self,
        child: &GpuRaster,
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        let u = ReduceWeightsUniform {
            width: width as u32,
            height: height as u32,
            child_width: child.width as u32,
            child_height: child.height as u32,
        };
        let p = &self.ctx.reduce_weights;
        self.reduce(
            "coherence weights",
            p,
            bytemuck::bytes_of(&u),
            child,
            width,
            height,
        )
    }
}
