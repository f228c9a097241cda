//! The stages: every WGSL kernel's CPU mirror, one stem per stage.
//!
//! Stage `<x>` is `kernels/<x>.wgsl` on the GPU, `stages::<x>` here (the
//! reference: rayon, with explicit SIMD where it pays, always beside its
//! scalar oracle) and `backend/gpu/<x>.rs` for its GPU host code; its
//! parameter block (`#[repr(C)]`, the kernel's uniform) lives in its stage
//! file. Each is a pure function over flat buffers with the same integer
//! arithmetic on both sides, so both give the same bytes (DESIGN §3, §6).
//! Stages import only the leaf types below them (`level`, `database`,
//! `hash`, `isa`), never a driver (`synth`, `render`, `patch`) or the
//! backend. `docs/ARCHITECTURE.md` lists each stage's files, tests and
//! benches.
//!
//! Each stage is declared once, by its line in the `stages!` table
//! below: the line makes its module, its [`Stage`] and its kernel source,
//! and every other list of the stages — the GPU pipelines, the timing
//! keys, the layout checks, the bench groups — is [`Stage::ALL`]. Adding a
//! stage is its stem files and one line here.

pub mod common; // what several stages share: texel heights, Δ order, type sets, height bits

/// The table of stages: one `name: Variant` line each, the name being the
/// module, the `.wgsl` file's stem, the timing key and the bench group, so
/// that they cannot drift apart. The line's doc comment is the
/// [`Stage`]'s.
macro_rules! stages {
    ($($(#[doc = $doc:literal])* $name:ident: $variant:ident,)*) => {
        $(pub mod $name;)*

        /// A stage: one WGSL kernel and its CPU mirror (see [`Stage::ALL`]).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Stage {
            $($(#[doc = $doc])* $variant,)*
        }

        impl Stage {
            /// Every stage, in the table's order (`Stage::X as usize` is
            /// its index).
            pub const ALL: [Stage; [$(Stage::$variant),*].len()] = [$(Stage::$variant),*];

            /// The stage's name: its module, its kernel `kernels/<name>.wgsl`,
            /// its bench group and its test module `tests/stages/<name>.rs`.
            pub const fn name(self) -> &'static str {
                match self {
                    $(Stage::$variant => stringify!($name),)*
                }
            }

            /// The kernel's WGSL source, without `kernels/common.wgsl`
            /// (`backend::kernels::module_source` prepends it).
            pub const fn wgsl(self) -> &'static str {
                match self {
                    $(Stage::$variant => include_str!(
                        concat!("../../kernels/", stringify!($name), ".wgsl")
                    ),)*
                }
            }
        }
    };
}

stages! {
    /// A level's coordinates from the coarser level's, jittered (paper
    /// eq. 1–2).
    upsample_jitter: UpsampleJitter,
    /// One subpass of the correction, under control inputs (paper eq. 3–9).
    correct: Correct,
    /// One level's allowed type sets R^i from the finer level's.
    reduce_types: ReduceTypes,
    /// One level's coherence weights W^i from the finer level's.
    reduce_weights: ReduceWeights,
    /// Level-0 coordinates and offsets → blended fixed-point heights.
    reconstruct: Reconstruct,
    /// Reconstruct's second half: spurious pits and peaks at patch joins
    /// (fused with it on the CPU, a second dispatch on the GPU).
    repair_extrema: RepairExtrema,
    /// One RGBA8 preview pixel from quantized heights (the renderer's).
    shade: Shade,
    /// Round one of the patch engine's hole filling: DC-corrected SSD table.
    fill_ssd: FillSsd,
}
