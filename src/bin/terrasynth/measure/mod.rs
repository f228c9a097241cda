//! Subcommands that measure: `eval` (realism, and the protocol of
//! `eval --suite` in [`suite`]) and `bench` (timings).

pub mod bench;
pub mod eval;
pub mod suite;
