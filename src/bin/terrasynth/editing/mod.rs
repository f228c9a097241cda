//! Subcommands that edit a terrain through a session: `edit` (scene files
//! in order, also `synth --scene`) and `serve` (the interactive editor).

pub mod edit;
#[cfg(feature = "serve")]
pub mod serve;
