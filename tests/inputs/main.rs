//! What a synthesis starts from: the exemplar database, the procedural
//! exemplars and their noise, and scene files.

#[path = "../common/mod.rs"]
mod common;

mod database;
mod procedural;
mod procedural_noise;
mod scene;
