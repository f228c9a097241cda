//! What holds across backends rather than per stage: whole syntheses,
//! sessions and sketches CPU ≡ GPU (`end_to_end`), `--backend` on the CLI
//! (`cli`), the editor's sessions and previews CPU ≡ GPU (`editor`),
//! windows of worlds and scenes on every backend (`window`,
//! `window_scene`), and the kernels' sources checked without a GPU: their
//! parameter blocks against the Rust mirrors (`layout`, naga) and their
//! headers against the files and items they cite (`kernel_headers`).
//! `.ci/run` runs this target with `stages` on lavapipe.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod editor;
mod end_to_end;
mod kernel_headers;
mod layout;
mod window;
mod window_scene;
