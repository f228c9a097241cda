//! Subcommands that make terrain: `synth` (from exemplars), `sketch`
//! (from a ridge/valley sketch), `generate` (procedural styles) and
//! `tiles` (a world as tile files).

pub mod generate;
pub mod sketch;
pub mod synth;
pub mod tiles;
