//! Error types shared across the crate. Each area has its own
//! `#[non_exhaustive]` enum whose messages state what was wrong and the
//! allowed range; [`Error`](enum@Error) gathers them for callers that do not care which
//! area failed (the CLI prints it and exits non-zero).

use crate::size::SizeError;
use thiserror::Error;

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
    #[error(transparent)]
    Water(#[from] crate::water::WaterError),
    #[error(transparent)]
    Erode(#[from] crate::erode::ErodeError),
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
