//! `terrasynth serve`, the editor (feature `serve`): its JSON API, limits
//! and memory, undo of pastes, and the page itself in headless Chromium
//! (browser, banners, export, sculpt, tabs, autosave, 3D view;
//! `TERRASYNTH_REQUIRE_BROWSER` turns "no browser, skipped" into a
//! failure). One target, so the editor's tests share one build.
#![cfg(feature = "serve")]

#[path = "../common/mod.rs"]
mod common;

mod api;
mod autosave;
mod banners;
mod browser;
mod export;
mod limits;
mod memory;
mod paste_undo;
mod sculpt;
mod tabs;
mod view3d;
