//! The table of WGSL kernels (`kernels/`): each stage's name, WGSL source
//! and entry point, nothing else.
//!
//! Each kernel's parameter block lives with its CPU mirror, in
//! `stages::<name>` (e.g. `stages::correct::CorrectUniform`), so that a
//! field added on one side is next to the other. The stages are always
//! compiled, with or without the `gpu` feature, so a plain `cargo test`
//! checks every such `#[repr(C)]` struct against the WGSL declaration of
//! the same name (sizes and member offsets, parsed by naga:
//! `tests/backend_layout.rs`).

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
pub const REPAIR_EXTREMA: Kernel = kernel!("repair_extrema");

pub const REDUCE_TYPES: Kernel = kernel!("reduce_types");
pub const REDUCE_WEIGHTS: Kernel = kernel!("reduce_weights");

/// The preview renderer's stage; its parameter block is
/// `stages::shade::ShadeParams` itself, already `#[repr(C)]` and Pod.
pub const SHADE: Kernel = kernel!("shade");

/// The patch engine's data-parallel cost stage (round one of hole
/// filling).
pub const FILL_SSD: Kernel = kernel!("fill_ssd");

/// Every kernel, for tests that check them all.
pub const ALL: [Kernel; 8] = [
    UPSAMPLE_JITTER,
    CORRECT,
    REDUCE_TYPES,
    REDUCE_WEIGHTS,
    RECONSTRUCT,
    REPAIR_EXTREMA,
    SHADE,
    FILL_SSD,
];

/// The one entry point of every kernel (`@compute fn main`).
pub const ENTRY_POINT: &str = "main";

/// Workgroup side of every kernel (`@workgroup_size(8, 8)`).
pub const WORKGROUP: u32 = 8;
