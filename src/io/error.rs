//! Errors of the format layer. [`FormatError`] says what is wrong with the
//! bytes; [`IoError`] adds the file it came from.

use crate::size::SizeError;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What is wrong with a file's contents.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum FormatError {
    #[error("truncated: {what} needs {expected} bytes, the file has {found}")]
    Truncated {
        what: &'static str,
        expected: u64,
        found: u64,
    },
    #[error("truncated: the {0} ends early")]
    EndsEarly(&'static str),
    #[error("bad magic: expected {expected}, found {found}")]
    BadMagic {
        expected: &'static str,
        found: String,
    },
    #[error("unsupported {what}: {found} (supported: {supported})")]
    Unsupported {
        what: &'static str,
        found: String,
        supported: &'static str,
    },
    #[error("dimension mismatch: {0}")]
    DimensionMismatch(String),
    #[error("declared size {width}x{height} needs more data than a {file_len}-byte file can hold")]
    SizeNotJustified {
        width: u64,
        height: u64,
        file_len: u64,
    },
    #[error("{0}")]
    Size(#[from] SizeError),
    #[error("invalid sidecar: {0}")]
    InvalidSidecar(String),
    #[error("line {line}: {message}")]
    Syntax { line: usize, message: String },
    #[error("corrupt data: {0}")]
    Corrupt(String),
    #[error("invalid metadata: {0}")]
    Metadata(String),
    #[error("invalid .prj (WKT): {0}")]
    Prj(String),
    #[error("cannot write: {0}")]
    Unwritable(String),
    #[error(
        "cannot write: {format} cannot store nodata, and the heightfield has {count} nodata samples; fill them first (terrasynth convert --fill-nodata) or write a format that keeps nodata (exr, tiff, asc, r32, png16)"
    )]
    NodataUnwritable { format: super::Format, count: usize },
}

impl FormatError {
    pub(crate) fn truncated(what: &'static str, expected: u64, found: usize) -> Self {
        FormatError::Truncated {
            what,
            expected,
            found: found as u64,
        }
    }

    /// Checks a per-pixel table of `len` entries against the grid it belongs
    /// to (a valid size, one entry a pixel), naming the entries `what` and
    /// the grid `grid` in the error.
    pub(crate) fn check_table(
        width: usize,
        height: usize,
        len: usize,
        what: &str,
        grid: &str,
    ) -> Result<(), Self> {
        crate::size::check_dims(width, height)?;
        if len != width * height {
            return Err(FormatError::DimensionMismatch(format!(
                "{len} {what} for a {width}x{height} {grid}"
            )));
        }
        Ok(())
    }

    /// A bad signature, showing the first bytes that were found instead.
    pub(crate) fn bad_magic(expected: &'static str, bytes: &[u8]) -> Self {
        let s: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02X}")).collect();
        FormatError::BadMagic {
            expected,
            found: if s.is_empty() {
                "an empty file".into()
            } else {
                s.join(" ")
            },
        }
    }

    /// The declared size is more than `file_len` bytes can hold.
    pub(crate) fn not_justified(width: usize, height: usize, file_len: usize) -> Self {
        FormatError::SizeNotJustified {
            width: width as u64,
            height: height as u64,
            file_len: file_len as u64,
        }
    }

    /// Refuses to write nodata to a format that cannot store it.
    pub(crate) fn check_no_nodata(
        hf: &crate::heightfield::Heightfield,
        format: super::Format,
    ) -> Result<(), FormatError> {
        match hf.nodata_count() {
            0 => Ok(()),
            count => Err(FormatError::NodataUnwritable { format, count }),
        }
    }
}

/// A file that could not be read or written.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum IoError {
    #[error("{path}: {source}")]
    Os {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path}: {kind}")]
    Format { path: PathBuf, kind: FormatError },
    #[error(
        "{path}: cannot tell the format from the file name; give it explicitly (one of: {formats})"
    )]
    UnknownFormat { path: PathBuf, formats: String },
    #[error("{path}: refusing to overwrite the input {input}; choose another output name")]
    WouldOverwrite { path: PathBuf, input: PathBuf },
    #[error(
        "{what} needs about {needed_mib} MiB of memory but only {available_mib} MiB are available; choose a smaller size"
    )]
    Memory {
        what: String,
        needed_mib: u64,
        available_mib: u64,
    },
}

impl IoError {
    pub(crate) fn os(path: &Path, source: std::io::Error) -> Self {
        IoError::Os {
            path: path.to_path_buf(),
            source,
        }
    }
    pub(crate) fn unknown_format(path: &Path) -> Self {
        IoError::UnknownFormat {
            path: path.to_path_buf(),
            formats: super::Format::list(),
        }
    }
    /// The format problem, if this is one (tests match on it).
    pub fn format_error(&self) -> Option<&FormatError> {
        match self {
            IoError::Format { kind, .. } => Some(kind),
            _ => None,
        }
    }
}
