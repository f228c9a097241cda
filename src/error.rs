//! Error types shared across the crate. Each area has its own
//! `#[non_exhaustive]` enum whose messages state what was wrong and the
//! allowed range; [`Error`] gathers them for callers that do not care which
//! area failed (the CLI prints it and exits non-zero).

use thiserror::Error;

/// A grid size, window or cell size that cannot be used.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SizeError {
    #[error("size {width}x{height} is empty: width and height must be at least 1")]
    Empty { width: usize, height: usize },
    #[error(
        "size {width}x{height} is too large: at most {max_side} per side and {max_pixels} samples"
    )]
    TooLarge {
        width: usize,
        height: usize,
        max_side: usize,
        max_pixels: usize,
    },
    #[error("sample count {found} does not match the size ({expected} expected)")]
    Length { expected: usize, found: usize },
    #[error("sample at pixel ({x}, {y}) is infinite: heights must be finite, or NaN for nodata")]
    Infinite { x: usize, y: usize },
    #[error("cell size {0} m is invalid: expected a finite value > 0")]
    CellSize(f64),
    #[error("window {w}x{h} at ({x}, {y}) does not fit a {width}x{height} grid")]
    Window {
        x: usize,
        y: usize,
        w: usize,
        h: usize,
        width: usize,
        height: usize,
    },
}

/// Any terrasynth error.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum Error {
    #[error(transparent)]
    Size(#[from] SizeError),
    #[error(transparent)]
    Io(#[from] crate::io::IoError),
    #[error(transparent)]
    Database(#[from] crate::database::DbError),
    #[error(transparent)]
    Synth(#[from] crate::synth::SynthError),
    #[error(transparent)]
    Poisson(#[from] crate::poisson::PoissonError),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
