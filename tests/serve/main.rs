//! `terrasynth serve`, the editor (feature `serve`): its JSON API, limits
//! and memory, undo of pastes, tabs, autosave, and the page itself in
//! headless Chromium (browser, export, sculpt, 3D view;
//! `TERRASYNTH_REQUIRE_BROWSER` turns "no browser, skipped" into a
//! failure).
#![cfg(feature = "serve")]

#[path = "../common/mod.rs"]
mod common;

mod api;
mod autosave;
mod browser;
mod export;
mod limits;
mod memory;
mod paste_undo;
mod sculpt;
mod tabs;
mod view3d;
