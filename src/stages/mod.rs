//! The stages: every WGSL kernel's CPU mirror, one stem per stage.
//!
//! Stage `<x>` is `kernels/<x>.wgsl` on the GPU, `stages::<x>` here (the
//! reference: rayon, with explicit SIMD where it pays, always beside its
//! scalar oracle) and `backend/gpu/<x>.rs` for its GPU host code; its
//! parameter block (`#[repr(C)]`, the kernel's uniform) lives in its stage
//! file. Each is a pure function over flat buffers with the same integer
//! arithmetic on both sides, so both give the same bytes (DESIGN §3, §6).
//! Stages import only the leaf types below them (`level`, `database`,
//! `hash`), never a driver (`synth`, `render`, `patch`) or the backend.
//! `docs/ARCHITECTURE.md` lists each stage's files, tests and benches.

pub mod common; // what several stages share: texel heights, Δ order, type sets, height bits
pub mod correct; // one subpass of the correction, under control inputs (paper eq. 3–9)
pub mod fill_ssd; // round one of the patch engine's hole filling: DC-corrected SSD table
pub mod reconstruct; // level-0 coordinates and offsets → blended fixed-point heights
pub mod reduce_types; // one level's allowed type sets R^i from the finer level's
pub mod reduce_weights; // one level's coherence weights W^i from the finer level's
pub mod repair_extrema; // reconstruct's second half: spurious pits and peaks at patch joins
pub mod shade; // one RGBA8 preview pixel from quantized heights (the renderer's)
pub mod upsample_jitter; // a level's coordinates from the coarser level's, jittered
