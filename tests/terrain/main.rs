//! Tools on a heightfield: the erosion filter, the realism and novelty
//! measures, meshes (and the glTF validator and trimesh reading them), and
//! the preview renderer.

#[path = "../common/mod.rs"]
mod common;

mod erode;
mod eval;
mod eval_novelty;
mod mesh;
mod mesh_clients;
mod render_io;
mod render_limits;
mod render_shade;
