//! Errors of the preview renderer.

use crate::backend::BackendError;
use crate::io::IoError;
use crate::size::SizeError;
use crate::stages::shade::ParamsError;
use std::path::PathBuf;
use thiserror::Error;

/// Why a preview could not be made.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum RenderError {
    #[error("{option} {value} is invalid: expected {allowed}")]
    Option {
        option: &'static str,
        value: String,
        allowed: String,
    },
    #[error(
        "type mask is {mask_width}x{mask_height} but the heightfield is {width}x{height}: a type mask must have the heightfield's size"
    )]
    TypesSize {
        mask_width: usize,
        mask_height: usize,
        width: usize,
        height: usize,
    },
    #[error("type mask {path}: {message}")]
    TypesFile { path: PathBuf, message: String },
    #[error("cannot encode the preview PNG: {0}")]
    Encode(String),
    #[error(transparent)]
    Params(#[from] ParamsError),
    #[error(transparent)]
    Size(#[from] SizeError),
    #[error(transparent)]
    Io(#[from] IoError),
    /// The GPU failed while shading (never the arithmetic: that is tested).
    #[error(transparent)]
    Backend(BackendError),
}
