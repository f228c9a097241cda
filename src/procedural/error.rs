//! Errors of the procedural toolbox: parameters out of range and inputs the
//! generators cannot work on. Messages name the parameter and its allowed range.

use crate::size::SizeError;
use thiserror::Error;

/// A procedural parameter or input that cannot be used.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ProceduralError {
    #[error("{name} is {value}: expected {allowed}")]
    Param {
        name: &'static str,
        value: f64,
        allowed: &'static str,
    },
    #[error(
        "the heightfield has {count} nodata samples (first at pixel ({x}, {y})): erosion needs every height; fill nodata first"
    )]
    NoData { count: usize, x: usize, y: usize },
    #[error("unknown style {name:?}: expected one of {known}")]
    UnknownStyle { name: String, known: String },
    #[error(transparent)]
    Size(#[from] SizeError),
}

/// Checks that `value` is finite and inside `lo..=hi`.
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    allowed: &'static str,
) -> Result<(), ProceduralError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(ProceduralError::Param {
            name,
            value,
            allowed,
        })
    }
}
