//! What keeps reading and writing safe: atomic output (a failed write never
//! leaves a partial file, [`atomic`]), the decoded size a file's length can
//! justify, checked before allocating ([`limits`]), and the memory the
//! system can give for a large request ([`memory`]).

pub mod atomic;
pub mod limits;
pub mod memory;
