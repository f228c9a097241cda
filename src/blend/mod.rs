//! The blending toolbox of seed 002 §7.4: three ways to put a source
//! heightfield into a destination inside a mask, in increasing order of
//! cost and quality.
//!
//! - [`feather`]: DC-corrected feathering (§7.4.1) — lerp of the zero-mean
//!   parts plus a lerp of the means, so that a source at another base height
//!   does not raise a plateau;
//! - [`laplacian`]: multi-resolution blending (§7.4.2, Burt & Adelson) —
//!   each octave is blended over a distance that matches its size;
//! - [`gradient_domain`]: Poisson blending (§7.4.3, Pérez et al.) — the
//!   destination outside the mask is untouched and the source's gradients
//!   are reproduced inside; built on the crate's one Poisson solver
//!   ([`crate::poisson`]).
//!
//! The patch engine ([`crate::patch`]) merges with the Poisson variant; the
//! other two are for tools (copy brushes) and comparison.
//!
//! All three take their grids as one [`Inputs`]: row-major `f32` grids of
//! one size and a mask in `[0, 1]` (`1` = take the source).

pub mod feather;
pub mod gradient_domain;
pub mod laplacian;

use thiserror::Error;

/// Why a blend could not run.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BlendError {
    #[error("{what} has {found} samples but the {width}x{height} grid needs {expected}")]
    Length {
        what: &'static str,
        width: usize,
        height: usize,
        expected: usize,
        found: usize,
    },
    #[error("mask value {value} at pixel ({x}, {y}) is outside the allowed range 0..=1")]
    Mask { x: usize, y: usize, value: f32 },
    #[error(transparent)]
    Poisson(#[from] crate::poisson::PoissonError),
}

/// The inputs every blend takes: a destination blended in place, a source
/// and a mask in `[0, 1]` (`1` = take the source), row-major grids of one
/// size. One type, checked once when it is made ([`Inputs::new`]), so
/// that the three methods agree on what they accept.
#[derive(Debug)]
pub struct Inputs<'a> {
    width: usize,
    height: usize,
    dst: &'a mut [f32],
    src: &'a [f32],
    mask: &'a [f32],
}

impl<'a> Inputs<'a> {
    /// Checks that every buffer has `width * height` samples and the mask
    /// is in `[0, 1]`.
    pub fn new(
        width: usize,
        height: usize,
        dst: &'a mut [f32],
        src: &'a [f32],
        mask: &'a [f32],
    ) -> Result<Inputs<'a>, BlendError> {
        check_lengths(
            width,
            height,
            &[
                ("destination", dst.len()),
                ("source", src.len()),
                ("mask", mask.len()),
            ],
        )?;
        if let Some(i) = mask.iter().position(|m| !(0.0..=1.0).contains(m)) {
            return Err(BlendError::Mask {
                x: i % width,
                y: i / width,
                value: mask[i],
            });
        }
        Ok(Inputs {
            width,
            height,
            dst,
            src,
            mask,
        })
    }
}

/// Checks that each named buffer has `width * height` samples.
fn check_lengths(
    width: usize,
    height: usize,
    bufs: &[(&'static str, usize)],
) -> Result<(), BlendError> {
    let expected = width * height;
    match bufs.iter().find(|&&(_, found)| found != expected) {
        Some(&(what, found)) => Err(BlendError::Length {
            what,
            width,
            height,
            expected,
            found,
        }),
        None => Ok(()),
    }
}
