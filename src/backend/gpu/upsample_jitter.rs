//! Stage `upsample_jitter` on the GPU (`kernels/upsample_jitter.wgsl`).

use super::{Gpu, GpuState, groups};
use crate::stages::Stage;
use crate::stages::upsample_jitter::{
    STEP_PYRAMID, STEP_VIRTUAL, STEP_WRAP, Step, UpsampleParams, UpsampleUniform,
};

impl Gpu {
    pub(super) fn dispatch_upsample_jitter(
        &self,
        parent: &GpuState,
        child: &GpuState,
        level: usize,
        p: &UpsampleParams,
    ) {
        let mut u = UpsampleUniform {
            child_width: child.width as u32,
            child_height: child.height as u32,
            parent_width: parent.width as u32,
            seed: p.seed,
            level: p.level,
            jitter: p.jitter,
            origin_x: p.origin[0],
            origin_y: p.origin[1],
            ..Default::default()
        };
        match p.step {
            Step::Pyramid => u.step = STEP_PYRAMID,
            Step::Virtual { shift } => {
                u.step = STEP_VIRTUAL;
                u.shift = shift;
            }
            Step::Wrap {
                min_x,
                max_x,
                min_y,
                max_y,
            } => {
                u.step = STEP_WRAP;
                (u.min_x, u.max_x, u.min_y, u.max_y) = (min_x, max_x, min_y, max_y);
            }
        }
        // Only the pyramid step reads the columns; the others get the
        // coarsest level's so that the binding is valid.
        let columns = &self.levels[level.min(self.levels.len() - 1)].columns;
        self.ctx.dispatch(
            Stage::UpsampleJitter,
            Some(level),
            bytemuck::bytes_of(&u),
            &[&parent.s, &parent.v, &child.s, &child.v, columns],
            (groups(child.width), groups(child.height)),
        );
    }
}
