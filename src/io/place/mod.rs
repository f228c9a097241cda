//! Where a grid lies on the ground: the CRSs of `.prj` files and GeoTIFF PE
//! strings ([`wkt`]), and a georeferenced grid brought to the square metric
//! cells every stage assumes, SRTM tiles placed by their names ([`ground`]).

pub mod ground;
pub mod wkt;
