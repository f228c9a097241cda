//! Stage `correct`'s parameter block and per-pixel control inputs as
//! `kernels/correct.wgsl` declares them (`#[repr(C)]`, checked against the
//! WGSL by `tests/backend/layout.rs`).

use bytemuck::{Pod, Zeroable};

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
    /// `CorrectParams::similar` (1: C₂ candidates compete).
    pub similar: u32,
    pub pad1: u32,
    pub pad2: u32,
}

/// `GuideCell` of `kernels/correct.wgsl`: one pixel's control inputs of
/// `correct`, all in one buffer so the kernel needs few bindings. Parts
/// whose flag is off are zero and never read.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
pub struct GuideCell {
    /// [`Target`](super::nudge::Target) (height, tol).
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
