//! What every WGSL kernel (`kernels/`) shares: `common.wgsl`, the entry
//! point and the workgroup side. Each kernel's own source comes from its
//! line in the table of stages (`stages::Stage::wgsl`).
//!
//! Each kernel's parameter block lives with its CPU mirror, in
//! `stages::<name>` (e.g. `stages::correct::CorrectUniform`), so that a
//! field added on one side is next to the other. The stages are always
//! compiled, with or without the `gpu` feature, so a plain `cargo test`
//! checks every such `#[repr(C)]` struct against the WGSL declaration of
//! the same name (sizes and member offsets, parsed by naga:
//! `tests/backend/layout.rs`).

use crate::stages::Stage;

/// Hash and fixed-point rules shared by every kernel.
pub const COMMON: &str = include_str!("../../kernels/common.wgsl");

/// The complete WGSL module of `stage`'s kernel: WGSL has no includes, so
/// [`COMMON`] is prepended.
pub fn module_source(stage: Stage) -> String {
    format!("{COMMON}\n{}", stage.wgsl())
}

/// The one entry point of every kernel (`@compute fn main`).
pub const ENTRY_POINT: &str = "main";

/// Workgroup side of every kernel (`@workgroup_size(8, 8)`).
pub const WORKGROUP: u32 = 8;
