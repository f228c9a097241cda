//! Errors of database building and loading.

use std::path::PathBuf;
use thiserror::Error;

#[non_exhaustive]
#[derive(Debug, Error)]
pub enum DbError {
    #[error("no exemplars given: a database needs at least one heightfield")]
    NoExemplars,
    #[error("too many exemplars ({0}): at most {max}", max = super::layout::MAX_EXEMPLARS)]
    TooManyExemplars(usize),
    #[error("exemplar {name:?} is {width}x{height}: every exemplar must be at least {min}x{min}")]
    TooSmall {
        name: String,
        width: usize,
        height: usize,
        min: usize,
    },
    #[error(
        "exemplar {name:?} has {count} nodata samples: fill them first (convert --fill-nodata) or build with --fill-nodata"
    )]
    Nodata { name: String, count: usize },
    #[error(
        "the exemplars are too wide together: the atlas would exceed 65535 columns at level 0 (resample or split the database)"
    )]
    AtlasTooLarge,
    #[error("type mask for {name:?} is {mask_w}x{mask_h} but the exemplar is {width}x{height}")]
    MaskSize {
        name: String,
        mask_w: usize,
        mask_h: usize,
        width: usize,
        height: usize,
    },
    #[error("too many terrain types ({0}): at most 32 (type sets are 32-bit masks)")]
    TooManyTypes(usize),
    #[error("{path}: {message}")]
    File { path: PathBuf, message: String },
    #[error("{path}: {source}")]
    Os {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error(transparent)]
    Io(#[from] crate::io::IoError),
    #[error(transparent)]
    Size(#[from] crate::size::SizeError),
}
