//! Stage `reconstruct` on the GPU (`kernels/reconstruct.wgsl`): the final
//! heights, read back to the host.

use super::{Gpu, GpuState, groups};
use crate::backend::{BackendError, Stage};
use crate::stages::reconstruct::ReconstructUniform;

impl Gpu {
    /// Stage `reconstruct`; `f` gets the heights where the device maps
    /// them.
    pub(super) fn dispatch_reconstruct<R>(
        &self,
        st: &GpuState,
        f: impl FnOnce(&[i32]) -> R,
    ) -> Result<R, BackendError> {
        let u = ReconstructUniform {
            width: st.width as u32,
            height: st.height as u32,
            ..Default::default()
        };
        let out = self
            .ctx
            .storage_empty("heights out", (st.width * st.height * 4) as u64)?;
        self.ctx.dispatch(
            Some((Stage::Reconstruct, 0)),
            &self.ctx.reconstruct,
            bytemuck::bytes_of(&u),
            &[&st.s, &st.v, &self.levels[0].columns, &self.heights, &out],
            (groups(st.width), groups(st.height)),
        );
        self.ctx.read_with(&out, f)
    }
}
