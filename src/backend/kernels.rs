//! The WGSL kernels (`kernels/`) and the parameter blocks they share with
//! Rust.
//!
//! Always compiled, with or without the `gpu` feature, so that a plain
//! `cargo test` checks every `#[repr(C)]` struct here against the WGSL
//! declaration of the same name (sizes and member offsets, parsed by naga):
//! a field added on one side only fails that test instead of silently
//! shifting the GPU's view of its parameters.

use bytemuck::{Pod, Zeroable};

/// Hash and fixed-point rules shared by every kernel.
pub const COMMON: &str = include_str!("../../kernels/common.wgsl");

/// One GPU stage: its name (= the CPU mirror's module and the `.wgsl` file)
/// and its source without [`COMMON`].
#[derive(Debug, Clone, Copy)]
pub struct Kernel {
    pub name: &'static str,
    pub source: &'static str,
}

impl Kernel {
    /// The complete WGSL module: WGSL has no includes, so [`COMMON`] is
    /// prepended.
    pub fn module_source(&self) -> String {
        format!("{COMMON}\n{}", self.source)
    }
}

/// A kernel named like its `.wgsl` file (and its CPU mirror), so the three
/// names cannot drift apart.
macro_rules! kernel {
    ($name:literal) => {
        Kernel {
            name: $name,
            source: include_str!(concat!("../../kernels/", $name, ".wgsl")),
        }
    };
}

pub const UPSAMPLE_JITTER: Kernel = kernel!("upsample_jitter");
pub const CORRECT: Kernel = kernel!("correct");
pub const RECONSTRUCT: Kernel = kernel!("reconstruct");

pub const REDUCE_TYPES: Kernel = kernel!("reduce_types");
pub const REDUCE_WEIGHTS: Kernel = kernel!("reduce_weights");

/// The preview renderer's stage (`render::shade`); its parameter block is
/// `render::shade::ShadeParams` itself, already `#[repr(C)]` and Pod.
pub const SHADE: Kernel = kernel!("shade");

/// The patch engine's data-parallel cost stage (`patch::costs`, round one
/// of hole filling).
pub const FILL_SSD: Kernel = kernel!("fill_ssd");

/// Every kernel, for tests that check them all.
pub const ALL: [Kernel; 7] = [
    UPSAMPLE_JITTER,
    CORRECT,
    REDUCE_TYPES,
    REDUCE_WEIGHTS,
    RECONSTRUCT,
    SHADE,
    FILL_SSD,
];

/// Workgroup side of every kernel (`@workgroup_size(8, 8)`).
pub const WORKGROUP: u32 = 8;

/// `upsample_jitter::Step` as the kernel's `step` field.
pub const STEP_PYRAMID: u32 = 0;
pub const STEP_VIRTUAL: u32 = 1;
pub const STEP_WRAP: u32 = 2;

/// `UpsampleParams` of `kernels/upsample_jitter.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct UpsampleUniform {
    pub child_width: u32,
    pub child_height: u32,
    pub parent_width: u32,
    pub seed: u32,
    pub level: u32,
    pub jitter: i32,
    pub step: u32,
    pub shift: u32,
    pub min_x: i32,
    pub max_x: i32,
    pub min_y: i32,
    pub max_y: i32,
    /// `UpsampleParams::origin`.
    pub origin_x: u32,
    pub origin_y: u32,
    pub pad0: u32,
    pub pad1: u32,
}

/// `CorrectParams` of `kernels/correct.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct CorrectUniform {
    pub width: u32,
    pub height: u32,
    pub px: u32,
    pub py: u32,
    /// `CORRECT_*` bits: which controls apply.
    pub flags: u32,
    /// `Guide::level`.
    pub level: u32,
    /// Types of the database (`AtlasLevel::seed_counts.len()`).
    pub type_count: u32,
    /// `CorrectParams::prior`.
    pub prior: u32,
    /// `Guide::window` (the whole level without one).
    pub x0: u32,
    pub y0: u32,
    pub x1: u32,
    pub y1: u32,
    /// The parent level's size, and whether there is one (the prior's
    /// anchor).
    pub parent_width: u32,
    pub parent_height: u32,
    pub has_parent: u32,
    /// `Guide::origin` (the type-seeding hash reads absolute coordinates).
    pub origin_x: u32,
    pub origin_y: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

/// `GuideCell` of `kernels/correct.wgsl`: one pixel's control inputs of
/// `correct`, all in one buffer so the kernel needs few bindings. Parts
/// whose flag is off are zero and never read.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct GuideCell {
    /// `blend::Target` (height, tol).
    pub blend_target: [i32; 2],
    /// R^i (`correct::Guide::allowed`).
    pub allowed: u32,
    /// W^i in quarters, widened.
    pub weight: u32,
    /// The previous frame's S (`Coord::pack`'s bytes) and V.
    pub prev_s: [i32; 2],
    pub prev_v: i32,
    pub pad0: i32,
}

/// `CorrectUniform::flags`: geometric targets, type sets, coherence.
pub const CORRECT_TARGETS: u32 = 1;
pub const CORRECT_ALLOWED: u32 = 2;
pub const CORRECT_COHERENCE: u32 = 4;

/// `ReconstructParams` of `kernels/reconstruct.wgsl` (padded to 16 bytes,
/// the uniform block granularity).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct ReconstructUniform {
    pub width: u32,
    pub height: u32,
    pub pad0: u32,
    pub pad1: u32,
}

/// `ReduceTypesParams` of `kernels/reduce_types.wgsl` (padded to 32 bytes,
/// a whole number of 16-byte uniform rows).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct ReduceTypesUniform {
    pub width: u32,
    pub height: u32,
    pub child_width: u32,
    pub child_height: u32,
    /// Every type of the database (`reduce_types`' `full`).
    pub full: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

/// `ReduceWeightsParams` of `kernels/reduce_weights.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct ReduceWeightsUniform {
    pub width: u32,
    pub height: u32,
    pub child_width: u32,
    pub child_height: u32,
}

/// `FillSsdParams` of `kernels/fill_ssd.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct FillSsdUniform {
    pub cells: u32,
    pub candidates: u32,
    pub transforms: u32,
    pub pad0: u32,
}
