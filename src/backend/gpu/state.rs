//! One level's synthesis state on the device, and its upload and download.

use super::Gpu;
use crate::backend::BackendError;
use crate::level::fixed::Coord;
use crate::level::state::State;

/// One level's state on the device: S as `vec2<i32>` (the bytes of
/// `Coord::pack`), V as `i32`.
pub struct GpuState {
    pub width: usize,
    pub height: usize,
    pub(super) s: wgpu::Buffer,
    pub(super) v: wgpu::Buffer,
}

impl Gpu {
    pub(super) fn upload_state(&self, st: State) -> Result<GpuState, BackendError> {
        let s: Vec<u64> = st.coords().into_iter().map(Coord::pack).collect();
        Ok(GpuState {
            width: st.width,
            height: st.height,
            s: self.ctx.storage("state S", bytemuck::cast_slice(&s))?,
            v: self
                .ctx
                .storage("state V", bytemuck::cast_slice(&st.offsets()))?,
        })
    }

    pub(super) fn alloc_state(
        &self,
        width: usize,
        height: usize,
    ) -> Result<GpuState, BackendError> {
        let n = (width * height) as u64;
        Ok(GpuState {
            width,
            height,
            s: self.ctx.storage_empty("state S", n * 8)?,
            v: self.ctx.storage_empty("state V", n * 4)?,
        })
    }

    /// A copy of the pixels `[x0, x1) × [y0, y1)` of `st`, row by row on the
    /// device (windowed synthesis, [`crate::backend::Backend::crop`]). The
    /// copies go into the shared encoder after the passes recorded so far,
    /// so they see those passes' writes.
    pub(super) fn crop_state(
        &self,
        st: &GpuState,
        [x0, y0, x1, y1]: [usize; 4],
    ) -> Result<GpuState, BackendError> {
        let (w, h) = (x1 - x0, y1 - y0);
        let out = self.alloc_state(w, h)?;
        let mut rec = self.ctx.recorder();
        let enc = rec.encoder(&self.ctx.device);
        for y in 0..h {
            let (from, to, n) = (((y0 + y) * st.width + x0) as u64, (y * w) as u64, w as u64);
            enc.copy_buffer_to_buffer(&st.s, from * 8, &out.s, to * 8, n * 8);
            enc.copy_buffer_to_buffer(&st.v, from * 4, &out.v, to * 4, n * 4);
        }
        Ok(out)
    }

    pub(super) fn download_state(
        &self,
        st: &GpuState,
    ) -> Result<(Vec<Coord>, Vec<i32>), BackendError> {
        let s: Vec<u64> = self.ctx.read(&st.s)?;
        let v: Vec<i32> = self.ctx.read(&st.v)?;
        Ok((s.into_iter().map(Coord::unpack).collect(), v))
    }
}
