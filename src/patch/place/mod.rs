//! Where patches come from and where they go: the feature patches' places
//! on the sketch, the sources' candidates, their warps and their costs
//! (both rounds).

pub mod candidates;
pub mod costs;
pub(crate) mod placement;
pub(crate) mod round2;
pub(crate) mod warp;
