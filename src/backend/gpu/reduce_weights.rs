//! Stage `reduce_weights` on the GPU (`kernels/reduce_weights.wgsl`): one
//! level's coherence weights W^i from the finer level's.

use super::{Gpu, GpuRaster};
use crate::backend::BackendError;
use crate::stages::reduce_weights::ReduceWeightsUniform;

impl Gpu {
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
