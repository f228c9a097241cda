//! One pyramid level as every stage sees it: fixed-point exemplar
//! coordinates ([`fixed`]), the per-level state S and V ([`state`]) and a
//! database level's texel addressing ([`atlas`]).
//!
//! The leaf below `stages` and the drivers: the stages (CPU and GPU) and
//! `synth` both work on these types, so they live under neither; `synth`
//! re-exports them under their old paths (`level::fixed`, …).

pub mod atlas;
pub mod fixed;
pub mod state;
