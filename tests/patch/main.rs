//! Sketch-driven patch synthesis (`terrasynth::patch`): the PPA feature
//! graph, graph-cut seams, the prepared-source cache, the whole pipeline
//! and its realism on real DEMs.

#[path = "../common/mod.rs"]
mod common;

mod cache;
mod graphcut;
mod pipeline;
mod ppa;
mod realism;
