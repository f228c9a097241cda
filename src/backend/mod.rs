//! The backend seam (DESIGN §3): where the synthesis stages run.
//!
//! The synthesizer drives one [`Backend`] through the same sequence of
//! stage calls whatever it is: [`cpu::Cpu`] (rayon + SIMD, the reference)
//! or, with the `gpu` feature, `gpu::Gpu` (wgpu on Vulkan, one WGSL kernel
//! per stage in `kernels/`). A backend keeps each level's state where it
//! computes — host memory or GPU buffers — so state stays on the GPU across
//! stages and levels and only results (and requested debug maps) come back.
//! Both produce the same bytes after every stage (DESIGN §6); the
//! `backend_*` tests check it.

pub mod cpu;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod kernels;

use crate::synth::fixed::Coord;
use crate::synth::stages::correct::CorrectParams;
use crate::synth::stages::upsample_jitter::UpsampleParams;
use crate::synth::state::State;
use thiserror::Error;

/// The synthesis stages of one backend, bound to one database.
///
/// Stage calls may be queued (a GPU runs them asynchronously, in order);
/// [`Backend::finish`] waits for them, and every call that returns host
/// data waits implicitly.
pub trait Backend {
    /// One level's coordinates S and offsets V, where this backend keeps them.
    type State;

    /// `"cpu"` or `"gpu"`, for reports.
    fn name(&self) -> &'static str;
    /// Moves a host state (the coarse start) to the backend.
    fn upload(&self, st: State) -> Result<Self::State, BackendError>;
    /// A `width × height` state whose contents the next stage overwrites.
    fn alloc(&self, width: usize, height: usize) -> Result<Self::State, BackendError>;
    /// Stage `upsample_jitter` into `child` (level `level`, the child's).
    fn upsample_jitter(
        &self,
        parent: &Self::State,
        child: &Self::State,
        level: usize,
        p: &UpsampleParams,
    );
    /// One subpass of stage `correct` at database level `level`, in place.
    fn correct(&self, st: &Self::State, level: usize, p: &CorrectParams);
    /// Stage `reconstruct` of a level-0 state: fixed-point heights (see
    /// `synth::stages::reconstruct`), row-major.
    fn reconstruct(&self, st: &Self::State) -> Result<Vec<i32>, BackendError>;
    /// A copy of a state's coordinates and offsets, row-major.
    fn download(&self, st: &Self::State) -> Result<(Vec<Coord>, Vec<i32>), BackendError>;
    /// Waits until every queued stage has run (so a caller's clock measures
    /// the work, not its submission).
    fn finish(&self) -> Result<(), BackendError>;
}

/// Which backend a user asked for (`--backend`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Choice {
    /// The rayon + SIMD stages.
    #[default]
    Cpu,
    /// The WGSL stages; an error when no GPU adapter (or no `gpu` feature).
    Gpu,
    /// The GPU when there is one, else the CPU with a notice.
    Auto,
}

/// Failures of a backend (never of its arithmetic: that is checked by tests).
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BackendError {
    #[error("the GPU backend is not compiled in: rebuild with `--features gpu`")]
    NotCompiled,
    #[error("no usable GPU adapter (Vulkan; install mesa-vulkan-drivers for a software one): {0}")]
    NoAdapter(String),
    #[error("the GPU adapter refused a device: {0}")]
    Device(String),
    #[error(
        "{what} needs a {bytes}-byte GPU buffer: the device allows 1..={limit} bytes per buffer"
    )]
    TooLarge {
        what: &'static str,
        bytes: u64,
        limit: u64,
    },
    #[error("GPU error: {0}")]
    Gpu(String),
}
