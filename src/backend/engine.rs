//! The one backend choice every driver makes: [`Engine::choose`] turns the
//! user's [`Choice`] (`--backend`) into an [`Engine`], and synthesis
//! (`synth::Synthesizer::use_engine`), the preview's stage `shade`
//! ([`Engine::shade`], through `render::render_on`) and the patch engine's
//! stage `fill_ssd` (`patch::fill::fill_ssd::FillCost::new`) all run on the
//! engine they are handed — so `render` and `patch` pick the CPU or the GPU
//! exactly as `synth` does, with the same fallback and the same notice.

use super::{BackendError, Choice};
use crate::isa::Isa;
use crate::stages::shade::{self, ShadeBuffers, ShadeParams};

/// Where the stages run.
#[derive(Clone)]
pub enum Engine {
    /// The rayon + SIMD stages, at an instruction-set level.
    Cpu(Isa),
    /// The WGSL stages on one device, shared by everything that runs on it
    /// (compiling the kernels is the slow part).
    #[cfg(feature = "gpu")]
    Gpu(std::sync::Arc<super::gpu::Context>),
}

impl Default for Engine {
    /// The CPU at its default level ([`Isa::default`]).
    fn default() -> Engine {
        Engine::Cpu(Isa::default())
    }
}

impl Engine {
    /// The engine `choice` names, and a one-line notice when
    /// [`Choice::Auto`] found no GPU and stays on the CPU.
    pub fn choose(choice: Choice) -> Result<(Engine, Option<String>), BackendError> {
        match choice {
            Choice::Cpu => Ok((Engine::default(), None)),
            Choice::Gpu => Ok((Engine::gpu()?, None)),
            Choice::Auto => Ok(match Engine::gpu() {
                Ok(gpu) => (gpu, None),
                Err(e) => (Engine::default(), Some(format!("{e}; using the CPU"))),
            }),
        }
    }

    /// The first usable GPU, or why there is none.
    fn gpu() -> Result<Engine, BackendError> {
        #[cfg(feature = "gpu")]
        {
            Ok(Engine::Gpu(super::gpu::Context::new()?))
        }
        #[cfg(not(feature = "gpu"))]
        {
            Err(BackendError::NotCompiled)
        }
    }

    /// `"cpu"` or `"gpu"`, for reports.
    pub fn name(&self) -> &'static str {
        match self {
            Engine::Cpu(_) => "cpu",
            #[cfg(feature = "gpu")]
            Engine::Gpu(_) => "gpu",
        }
    }

    /// The GPU adapter's name (for reports), `None` on the CPU.
    pub fn adapter(&self) -> Option<String> {
        match self {
            Engine::Cpu(_) => None,
            #[cfg(feature = "gpu")]
            Engine::Gpu(ctx) => Some(ctx.adapter_name()),
        }
    }

    /// Stage `shade` (the preview renderer's): the packed RGBA pixels of
    /// `b`, row-major, the same bytes on every engine. Checks the
    /// parameters first.
    pub fn shade(&self, p: &ShadeParams, b: &ShadeBuffers<'_>) -> Result<Vec<u32>, BackendError> {
        match self {
            Engine::Cpu(_) => {
                let mut pixels = vec![0u32; b.heights.len()];
                shade::shade(p, b, &mut pixels)?;
                Ok(pixels)
            }
            #[cfg(feature = "gpu")]
            Engine::Gpu(ctx) => ctx.shade(p, b),
        }
    }
}
