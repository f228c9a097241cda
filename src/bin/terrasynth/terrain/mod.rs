//! Subcommands that work on a heightfield: `water`, `erode`, `masks`,
//! `mesh`, `normals` and `render`.

pub mod erode;
pub mod masks;
pub mod mesh;
pub mod normals;
pub mod render;
pub mod water;
