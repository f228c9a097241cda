//! Heightfields in and out (`terrasynth::io`): every format's reading and
//! writing, golden files, round trips, malformed inputs and fuzz replays,
//! and the CLI on bad input. The readers' allocation bound is its own
//! target, `tests/io_alloc.rs`: its counting allocator is process-wide.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod formats;
mod fuzz_replay;
mod georef_fuzz_replay;
mod golden;
mod malformed;
mod roundtrip;
