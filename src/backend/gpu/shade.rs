//! Stage `shade` on the GPU (`kernels/shade.wgsl`), the preview renderer's.

use super::{Context, groups};
use crate::backend::BackendError;
use crate::stages::Stage;
use crate::stages::shade::{ShadeBuffers, ShadeParams};

impl Context {
    /// Stage `shade` (the preview renderer's): the same packed RGBA pixels
    /// as `stages::shade::shade`, row-major. Checks the parameters first,
    /// exactly like the CPU stage.
    pub fn shade(&self, p: &ShadeParams, b: &ShadeBuffers<'_>) -> Result<Vec<u32>, BackendError> {
        p.validate(b)?;
        let n = p.width as u64 * p.height as u64;
        // Type buffers may be empty when the overlay is off: bind a word.
        let some = |v: &[u32]| -> Vec<u32> { if v.is_empty() { vec![0] } else { v.to_vec() } };
        let heights = self.storage("shade heights", bytemuck::cast_slice(b.heights))?;
        let types = self.storage("shade types", bytemuck::cast_slice(&some(b.types)))?;
        let tint = self.storage("tint", bytemuck::cast_slice(b.tint))?;
        let colours = self.storage("type colours", bytemuck::cast_slice(&some(b.type_colours)))?;
        let out = self.storage_empty("preview", n * 4)?;
        self.dispatch(
            Stage::Shade,
            None,
            bytemuck::bytes_of(p),
            &[&heights, &types, &tint, &colours, &out],
            (groups(p.width as usize), groups(p.height as usize)),
        );
        self.read(&out)
    }
}
