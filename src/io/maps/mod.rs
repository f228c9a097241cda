//! Per-cell rasters that travel beside a heightfield but are not heights:
//! terrain-type masks ([`type_mask`]) and source-coordinate maps
//! ([`coords_map`]), both PNGs.

pub mod coords_map;
pub mod type_mask;
