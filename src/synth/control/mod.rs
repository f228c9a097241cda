//! User control inside the correction (paper §5, DESIGN §5): geometric
//! constraints (points here, curves in `curve`), their overlap blend, and
//! the per-level integer rasters the `correct` stage reads.
//!
//! Everything in this module is CPU-side preparation (DESIGN §6 rule 5):
//! constraint geometry may use floats, but what reaches a kernel is
//! quantized once, here, into integers — so the scalar, SIMD and WGSL
//! corrections see the same numbers.
//!
//! Coordinates are *output pixels*: pixel (i, j) of the finest level has its
//! centre at (i + 0.5, j + 0.5). A pixel (x, y) of level i is centred at
//! ((x + 0.5)·2^i, (y + 0.5)·2^i).

pub mod blend;
pub mod point;

pub use blend::{Blend, Target, Targets};
pub use point::PointConstraint;

use thiserror::Error;

/// Geometric constraints act on levels ≥ this one (paper §5.1: "disabling
/// geometric constraints on the finest two levels"); type constraints too
/// (§5.2).
pub const FIRST_LEVEL: usize = 2;

/// What one geometric constraint asks of one output position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Target height h_t at this position, metres.
    pub target_m: f64,
    /// Distance d from the position to the constraint site (the point, or the
    /// closest curve point), in output (finest-level) pixels.
    pub distance: f64,
    /// The constraint's reach (area of effect) here, output pixels
    /// (side-dependent for curves, after envelope smoothing).
    pub reach: f64,
}

/// A geometric constraint (point or curve), evaluated in output pixel
/// coordinates (pixel (i, j) has its centre at (i + 0.5, j + 0.5)).
pub trait Constraint: Send + Sync + std::fmt::Debug {
    /// Bounds [x0, y0, x1, y1) of everything it can influence, output pixels.
    fn bounds(&self) -> [f64; 4];
    /// The sample at output position (x, y); None outside its reach.
    fn sample(&self, x: f64, y: f64) -> Option<Sample>;
}

/// Invalid control inputs. Messages name the field and the allowed range.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ControlError {
    #[error("{field} {value} is invalid: expected {expected}")]
    Value {
        field: &'static str,
        value: f64,
        expected: &'static str,
    },
}

/// Checks that `value` is finite and in `range`, naming `field` otherwise.
pub(crate) fn check(
    field: &'static str,
    value: f64,
    ok: bool,
    expected: &'static str,
) -> Result<f64, ControlError> {
    if value.is_finite() && ok {
        Ok(value)
    } else {
        Err(ControlError::Value {
            field,
            value,
            expected,
        })
    }
}
