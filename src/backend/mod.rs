//! The backend seam (DESIGN §3): where the synthesis stages run.
//!
//! The synthesizer drives one [`Backend`] through the same sequence of
//! stage calls whatever it is: [`cpu::Cpu`] (rayon + SIMD, the reference)
//! or, with the `gpu` feature, `gpu::Gpu` (wgpu on Vulkan, one WGSL kernel
//! per stage in `kernels/`). A backend keeps each level's state where it
//! computes — host memory or GPU buffers — so state stays on the GPU across
//! stages and levels and only results (and requested debug maps) come back.
//! Both produce the same bytes after every stage (DESIGN §6); the
//! `stages` and `backend` test targets check it. Which one runs — for synthesis, the
//! preview's `shade` and the patch engine's `fill_ssd` alike — is one
//! [`engine::Engine`], chosen once from the user's [`Choice`].

pub mod cpu;
pub mod engine;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod kernels;

use crate::level::fixed::Coord;
use crate::level::state::State;
use crate::stages::Stage;
use crate::stages::correct::{self, CorrectParams};
use crate::stages::upsample_jitter::UpsampleParams;
use std::time::Duration;
use thiserror::Error;

/// The device's own measure of one stage call (GPU timestamp queries).
#[derive(Debug, Clone, Copy)]
pub struct StageTime {
    /// The stage, keyed by its line in the table of stages.
    pub stage: Stage,
    /// The level the call worked on.
    pub level: usize,
    pub time: Duration,
}

/// The synthesis stages of one backend, bound to one database.
///
/// Stage calls may be queued (a GPU runs them asynchronously, in order);
/// [`Backend::finish`] waits for them, and every call that returns host
/// data waits implicitly.
///
/// Database data is bound at construction and addressed by level index;
/// per-level inputs of later stages (the user-control rasters of
/// `synth::control`: targets, allowed types, previous results, coherence
/// weights) are uploaded as a backend-side [`Backend::Guide`] and passed to
/// [`Backend::correct_guided`] next to the state. The pyramids of two of
/// them are stages of their own ([`Backend::reduce_types`],
/// [`Backend::reduce_weights`]).
pub trait Backend {
    /// One level's coordinates S and offsets V, where this backend keeps them.
    type State;
    /// One level's target type sets R^i (u32 masks of type ids), where this
    /// backend keeps them.
    type Types;
    /// One level's coherence weights W^i (quarters, u8 on the host), where
    /// this backend keeps them.
    type Weights;
    /// One pass's control inputs of `correct` at one level (a
    /// `correct::Guide`), where this backend reads them.
    type Guide<'g>;

    /// `"cpu"` or `"gpu"`, for reports.
    fn name(&self) -> &'static str;
    /// Moves a host state (the coarse start) to the backend.
    fn upload(&self, st: State) -> Result<Self::State, BackendError>;
    /// The host state a backend state is, if this backend keeps its states
    /// on the host (the CPU's: `Some`, without a copy); `None` otherwise.
    /// A session keeps each level's final state this way, so that an
    /// edit patches the next frame's level in place instead of rebuilding
    /// it from the recorded results.
    fn host_state(&self, st: Self::State) -> Option<State> {
        let _ = st;
        None
    }
    /// A `width × height` state whose contents the next stage overwrites.
    fn alloc(&self, width: usize, height: usize) -> Result<Self::State, BackendError>;
    /// A copy of the pixels `[x0, x1) × [y0, y1)` of a state: windowed
    /// synthesis keeps of the level above only what the next level reads
    /// (`synth::cone::Cone::parent_crop`), so that the stages' parent of
    /// pixel p stays at p / 2 in the buffers.
    fn crop(&self, st: &Self::State, rect: [usize; 4]) -> Result<Self::State, BackendError>;
    /// Stage `upsample_jitter` into `child` (level `level`, the child's).
    fn upsample_jitter(
        &self,
        parent: &Self::State,
        child: &Self::State,
        level: usize,
        p: &UpsampleParams,
    );
    /// [`Backend::upsample_jitter`] of which only the child pixels in
    /// `rect` are read before being overwritten (an edit's restricted
    /// re-synthesis); a backend may fill more. Default: the whole child.
    fn upsample_jitter_rect(
        &self,
        parent: &Self::State,
        child: &Self::State,
        level: usize,
        p: &UpsampleParams,
        rect: [usize; 4],
    ) {
        let _ = rect;
        self.upsample_jitter(parent, child, level, p);
    }
    /// One subpass of stage `correct` at database level `level`, in place;
    /// `parent` is the level above (the height prior's anchor), none at the
    /// coarsest corrected level.
    fn correct(
        &self,
        st: &Self::State,
        parent: Option<&Self::State>,
        level: usize,
        p: &CorrectParams,
    );
    /// Moves the control inputs of one pass over a `width × height` level
    /// to the backend (the CPU borrows them as they are).
    fn upload_guide<'g>(
        &self,
        g: &correct::Guide<'g>,
        width: usize,
        height: usize,
    ) -> Result<Self::Guide<'g>, BackendError>;
    /// One subpass of stage `correct` under control inputs (paper §5), in
    /// place; with a guide of `correct::Guide::NONE` the same bytes as
    /// [`Backend::correct`].
    fn correct_guided(
        &self,
        st: &Self::State,
        parent: Option<&Self::State>,
        level: usize,
        p: &CorrectParams,
        g: &Self::Guide<'_>,
    );
    /// Stage `reconstruct` of a level-0 state: fixed-point heights (see
    /// `stages::reconstruct`), row-major.
    fn reconstruct(&self, st: &Self::State) -> Result<Vec<i32>, BackendError>;
    /// [`Backend::reconstruct`], the heights handed to `f` where they lie
    /// rather than returned: on the GPU, the mapped read-back itself, not a
    /// copy of it in a `Vec` (the copy cost 0.6 ms of a 5 ms 1024²
    /// synthesis on an H100). Default: `f` of the returned heights.
    fn reconstruct_with<R>(
        &self,
        st: &Self::State,
        f: impl FnOnce(&[i32]) -> R,
    ) -> Result<R, BackendError> {
        Ok(f(&self.reconstruct(st)?))
    }
    /// [`Backend::reconstruct`] where the heights can differ from `prev`
    /// (the previous frame's, level-sized) only in `rect`: an edit's
    /// re-synthesis. `prev` is taken so that a backend may patch it in
    /// place (a level-sized copy per edit was a fresh 4 MB at 1024²).
    /// Default: the whole level.
    fn reconstruct_rect(
        &self,
        st: &Self::State,
        prev: Vec<i32>,
        rect: [usize; 4],
    ) -> Result<Vec<i32>, BackendError> {
        let _ = (prev, rect);
        self.reconstruct(st)
    }
    /// A copy of a state's coordinates and offsets, row-major.
    fn download(&self, st: &Self::State) -> Result<(Vec<Coord>, Vec<i32>), BackendError>;
    /// Moves a `width × height` raster of type sets to the backend.
    fn upload_types(
        &self,
        data: &[u32],
        width: usize,
        height: usize,
    ) -> Result<Self::Types, BackendError>;
    /// Moves a `width × height` raster of coherence weights to the backend.
    fn upload_weights(
        &self,
        data: &[u8],
        width: usize,
        height: usize,
    ) -> Result<Self::Weights, BackendError>;
    /// Stage `reduce_types`: the `width × height` level above `child`.
    fn reduce_types(
        &self,
        child: &Self::Types,
        width: usize,
        height: usize,
        full: u32,
    ) -> Result<Self::Types, BackendError>;
    /// Stage `reduce_weights`: the `width × height` level above `child`.
    fn reduce_weights(
        &self,
        child: &Self::Weights,
        width: usize,
        height: usize,
    ) -> Result<Self::Weights, BackendError>;
    /// A copy of a type-set raster, row-major.
    fn download_types(&self, r: &Self::Types) -> Result<Vec<u32>, BackendError>;
    /// A copy of a weight raster, row-major.
    fn download_weights(&self, r: &Self::Weights) -> Result<Vec<u8>, BackendError>;
    /// Waits until every queued stage has run (so a caller's clock measures
    /// the work, not its submission).
    fn finish(&self) -> Result<(), BackendError>;
    /// Whether [`Backend::device_times`] reports the stages' own times, so
    /// that the caller need not wait after each stage to time it.
    fn has_device_clock(&self) -> bool {
        false
    }
    /// The device's times of the stage calls since the last call (and
    /// forgets them); `None` without a device clock.
    fn device_times(&self) -> Result<Option<Vec<StageTime>>, BackendError> {
        Ok(None)
    }
}

/// A control raster in host memory (the CPU backend's [`Backend::Types`]
/// and [`Backend::Weights`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Raster<T> {
    pub width: usize,
    pub height: usize,
    /// Row-major, `width × height` values.
    pub data: Vec<T>,
}

impl<T: Clone> Raster<T> {
    /// A raster of `data`, which must hold `width × height` values.
    pub fn new(
        what: &'static str,
        data: &[T],
        width: usize,
        height: usize,
    ) -> Result<Raster<T>, BackendError> {
        check_raster(what, data.len(), width, height)?;
        Ok(Raster {
            width,
            height,
            data: data.to_vec(),
        })
    }
}

/// Rejects a raster whose length is not `width × height` (the stages index
/// it by pixel, so a short one would read out of bounds).
pub fn check_raster(
    what: &'static str,
    len: usize,
    width: usize,
    height: usize,
) -> Result<(), BackendError> {
    if width.checked_mul(height) != Some(len) {
        return Err(BackendError::RasterSize {
            what,
            len,
            width,
            height,
        });
    }
    Ok(())
}

/// Rejects a guide whose rasters are not `width × height` (every backend
/// checks before `correct_guided` indexes them by pixel).
pub fn check_guide(
    g: &correct::Guide<'_>,
    width: usize,
    height: usize,
) -> Result<(), BackendError> {
    if let Some(t) = g.targets {
        check_raster("targets", t.len(), width, height)?;
    }
    if let Some(a) = g.allowed {
        check_raster("type sets", a.len(), width, height)?;
    }
    if let Some(c) = g.coherence {
        check_raster("previous coordinates", c.coords.len(), width, height)?;
        check_raster("previous offsets", c.offsets.len(), width, height)?;
        check_raster("coherence weights", c.weights.len(), width, height)?;
    }
    Ok(())
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
    #[error("{what} raster holds {len} values, but {width} × {height} were given")]
    RasterSize {
        what: &'static str,
        len: usize,
        width: usize,
        height: usize,
    },
    #[error("GPU error: {0}")]
    Gpu(String),
    #[error(transparent)]
    Shade(#[from] crate::stages::shade::ParamsError),
}
