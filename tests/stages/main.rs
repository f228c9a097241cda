//! Every stage's variant test, one module per line of the `stages!` table
//! (`src/stages/mod.rs`): each asks `common::variants` for the scalar
//! oracle, the CPU path at every instruction-set level this CPU has and,
//! with `--features gpu` and an adapter, the kernel, and checks them
//! against one result. One test target, so `.ci/run` runs every stage on
//! lavapipe with `--test stages`, and a module here per stage is what
//! `tests/architecture.rs` checks against the table.

#[path = "../common/mod.rs"]
mod common;

mod correct;
mod fill_ssd;
mod reconstruct;
mod reduce_types;
mod reduce_weights;
mod shade;
mod upsample_jitter;
