//! Stage `reduce_types` on the GPU (`kernels/reduce_types.wgsl`): one
//! level's type sets R^i from the finer level's.

use super::{Gpu, GpuRaster};
use crate::backend::BackendError;
use crate::stages::reduce_types::ReduceTypesUniform;

impl Gpu {
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
}
