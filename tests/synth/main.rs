//! The synthesizer (`terrasynth::synth`): the engine's determinism and
//! invariants, user control, pastes, sculpt brushes, painted types, scenes
//! through editing sessions, and worlds as tiles.

#[path = "../common/mod.rs"]
mod common;

mod control;
mod engine;
mod painted_relief;
mod paste;
mod scene_session;
mod sculpt;
mod tiles;
mod tiles_engine;
mod valleys;
