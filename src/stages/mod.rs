//! The synthesis stages: each a pure function over flat buffers, named like
//! its WGSL mirror in `kernels/` (DESIGN §3).

pub mod correct;
pub mod fill_ssd;
pub mod reconstruct;
pub mod reduce_types;
pub mod reduce_weights;
pub mod shade;
pub mod upsample_jitter;
