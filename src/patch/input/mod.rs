//! What a synthesis starts from: the user's sketch, the prepared source
//! DEMs and their disk cache, and the features both are read into — PPA's
//! ridge and valley lines reduced to a graph of control points.

pub mod cache;
pub mod control_point;
pub mod graph;
pub(crate) mod library;
pub mod ppa;
pub mod sketch;
