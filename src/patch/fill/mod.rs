//! Filling what the feature patches leave: non-feature hole filling and the
//! backend-dispatched SSD of its first round.

pub mod fill_ssd;
pub mod hole_fill;
