//! The wgpu backend (`--features gpu`): each stage is one compute dispatch
//! of its WGSL kernel (`kernels/<stage>.wgsl`), each level's state two
//! storage buffers that stay on the device from the coarse start to the
//! reconstructed heights.
//!
//! Vulkan only: on the GL backend signed `%` and division by zero came out
//! wrong here (DESIGN §6), and the kernels rely on both being right. Without
//! a hardware adapter wgpu falls back to Mesa's lavapipe (software Vulkan,
//! Debian package `mesa-vulkan-drivers`), which is how CI checks this path.
//!
//! Each stage call records one compute pass into a shared encoder,
//! submitted in batches (`dispatch`); passes run in recording order and
//! wgpu orders storage-buffer accesses between them, so one subpass sees
//! the previous one's writes.
//!
//! The parts: `context` (device and pipelines), `buffers` (storage
//! buffers and read-back), `dispatch` (one compute pass), `timing`
//! (timestamp queries), `database` (the atlas on the device), `state`
//! and `rasters` (per-level data, and the one dispatch of the two
//! reductions, `reduce_types` and `reduce_weights`), one module per other
//! stage, named like its kernel and its CPU mirror in `stages`
//! (`upsample_jitter`, `correct`, `reconstruct`, `shade`, and the patch
//! engine's [`fill_ssd`]) and `backend` (the [`super::Backend`] trait on
//! [`Gpu`]).

mod backend;
mod buffers;
mod context;
mod correct;
mod database;
mod dispatch;
pub mod fill_ssd;
mod rasters;
mod reconstruct;
mod shade;
mod state;
mod timing;
mod upsample_jitter;

use super::kernels;

pub use context::Context;
pub use correct::GpuGuide;
pub use database::Gpu;
pub use rasters::GpuRaster;
pub use state::GpuState;

/// Workgroups covering `n` invocations.
fn groups(n: usize) -> u32 {
    (n as u32).div_ceil(kernels::WORKGROUP)
}
