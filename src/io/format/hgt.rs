//! SRTM `.hgt` tiles (read only): a square of big-endian i16 metres, rows
//! north to south, void = −32768 (→ NaN).
//!
//! The size follows from the byte count alone: 1201² samples (SRTM3, 3
//! arc-seconds) or 3601² (SRTM1, 1 arc-second); anything else is refused.
//! The tile's name (`N41E001.hgt`) places it: [`crate::io::place::ground::hgt_georef`]
//! gives it an EPSG:4326 georeference, and [`crate::io::load`] then resamples
//! it east–west to square cells of its true north–south spacing (a tile is
//! not square on the ground away from the equator). A tile whose name says
//! nowhere keeps the posting on the WGS84 equator — 1″ = 30.92 m, so 92.77 m
//! for SRTM3 and 30.92 m for SRTM1 — as its cell size, unplaced and
//! unresampled: rename it, or pass `--cell-size`.

use crate::heightfield::Heightfield;
use crate::io::FormatError;

/// One arc-second on the WGS84 equator, in metres (40 075 016.686 m / 1 296 000).
pub const ARC_SECOND_M: f64 = 30.922_080;

/// SRTM's void marker.
pub const VOID: i16 = -32768;

/// (samples per side, arc-seconds per cell) of the two SRTM products.
const PRODUCTS: [(usize, f64); 2] = [(1201, 3.0), (3601, 1.0)];

pub(in crate::io) fn decode(bytes: &[u8]) -> Result<Heightfield, FormatError> {
    let Some(&(side, arcsec)) = PRODUCTS
        .iter()
        .find(|(side, _)| side * side * 2 == bytes.len())
    else {
        return Err(FormatError::DimensionMismatch(format!(
            "an SRTM .hgt tile has {} bytes (1201x1201, SRTM3) or {} bytes (3601x3601, SRTM1); this file has {}",
            1201 * 1201 * 2,
            3601 * 3601 * 2,
            bytes.len()
        )));
    };
    let data = bytes
        .chunks_exact(2)
        .map(|c| match i16::from_be_bytes([c[0], c[1]]) {
            VOID => f32::NAN,
            v => v as f32,
        })
        .collect();
    Ok(Heightfield::from_vec(
        side,
        side,
        arcsec * ARC_SECOND_M,
        data,
    )?)
}
