//! `terrasynth water` (issue 41): the fill and the drainage network, the
//! fast paths against the plain ones, MFD routing, and a tiled world's
//! water against the whole's.

#[path = "../common/mod.rs"]
mod common;

mod fast;
mod mfd;
mod network;
mod tiles;
