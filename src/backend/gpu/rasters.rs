//! Control rasters (type sets, coherence weights) on the device: their
//! upload and download, and the one dispatch both reductions share.

use super::{Gpu, groups};
use crate::backend::{BackendError, check_raster};
use crate::stages::Stage;

/// One level's control raster on the device, one u32 per pixel: type sets
/// as they are, coherence weights widened from u8 (see
/// `kernels/reduce_weights.wgsl`).
pub struct GpuRaster {
    pub width: usize,
    pub height: usize,
    pub(super) buf: wgpu::Buffer,
}

impl Gpu {
    pub(super) fn upload_raster(
        &self,
        what: &'static str,
        data: &[u32],
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        check_raster(what, data.len(), width, height)?;
        Ok(GpuRaster {
            width,
            height,
            buf: self.ctx.storage(what, bytemuck::cast_slice(data))?,
        })
    }

    pub(super) fn upload_weight_raster(
        &self,
        data: &[u8],
        width: usize,
        height: usize,
    ) -> Result<GpuRaster, BackendError> {
        let wide: Vec<u32> = data.iter().map(|&w| w as u32).collect();
        self.upload_raster("coherence weights", &wide, width, height)
    }

    pub(super) fn download_type_raster(&self, r: &GpuRaster) -> Result<Vec<u32>, BackendError> {
        self.ctx.read(&r.buf)
    }

    pub(super) fn download_weight_raster(&self, r: &GpuRaster) -> Result<Vec<u8>, BackendError> {
        let wide: Vec<u32> = self.ctx.read(&r.buf)?;
        // Every stored weight is ≤ 255 (an uploaded u8 or a reduction's ≤ 4).
        Ok(wide.into_iter().map(|w| w as u8).collect())
    }

    /// One dispatch of a reduction (`stage`: `reduce_types` or
    /// `reduce_weights`) from `child` into a new `width × height` raster;
    /// `uniform` is the kernel's parameter block.
    pub(super) fn reduce(
        &self,
        what: &'static str,
        stage: Stage,
        uniform: &impl bytemuck::Pod,
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
            stage,
            None,
            bytemuck::bytes_of(uniform),
            &[&child.buf, &buf],
            (groups(width), groups(height)),
        );
        Ok(GpuRaster { width, height, buf })
    }
}
