//! Stages `reconstruct` and `repair_extrema` on the GPU
//! (`kernels/reconstruct.wgsl`, `kernels/repair_extrema.wgsl`): the blended
//! heights, then the final ones, read back to the host.

use super::{Gpu, GpuState, groups};
use crate::backend::BackendError;
use crate::stages::Stage;
use crate::stages::reconstruct::ReconstructUniform;

impl Gpu {
    /// Stages `reconstruct` and `repair_extrema`; `f` gets the heights
    /// where the device maps them.
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
        let bytes = (st.width * st.height * 4) as u64;
        let blended = self.ctx.storage_empty("blended heights", bytes)?;
        let level = &self.levels[0];
        let groups = (groups(st.width), groups(st.height));
        self.ctx.dispatch(
            Stage::Reconstruct,
            Some(0),
            bytemuck::bytes_of(&u),
            &[
                &st.s,
                &st.v,
                &level.columns,
                &level.appearance,
                &self.heights,
                &blended,
            ],
            groups,
        );
        let out = self.ctx.storage_empty("heights out", bytes)?;
        self.ctx.dispatch(
            Stage::RepairExtrema,
            Some(0),
            bytemuck::bytes_of(&u),
            &[&st.s, &st.v, &level.columns, &self.heights, &blended, &out],
            groups,
        );
        self.ctx.read_with(&out, f)
    }
}
