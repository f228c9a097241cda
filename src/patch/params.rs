//! What a synthesis is asked for: its parameters, the second-round cost
//! weights, and why a request is refused ([`PatchError`]). Kept apart from
//! the driver so that the knobs and their reasons read in one place.

use thiserror::Error;

/// Why a synthesis could not run.
#[non_exhaustive]
#[derive(Debug, Error)]
pub enum PatchError {
    #[error("patch size {0} is invalid: expected a multiple of 8 in 16..=256")]
    PatchSize(usize),
    #[error(
        "output size {width}x{height} is invalid: each side must be at least the patch size {patch} and at most 16384"
    )]
    OutputSize {
        width: usize,
        height: usize,
        patch: usize,
    },
    #[error("no source DEM was given: at least one is needed")]
    NoSources,
    #[error(
        "source {name} is {width}x{height} at {cell_m} m cells (the sources' common cell size: each is resampled to the median of theirs): each side must be at least 2x the patch size {patch}"
    )]
    SourceSize {
        name: String,
        width: usize,
        height: usize,
        cell_m: f64,
        patch: usize,
    },
    #[error("source {name} was prepared for patch size {found}, not {expected}")]
    PreparedFor {
        name: String,
        found: usize,
        expected: usize,
    },
    #[error(transparent)]
    Backend(#[from] crate::backend::BackendError),
    #[error(transparent)]
    Other(#[from] crate::Error),
}

/// Weights of the second-round costs (all terms are made dimensionless
/// first; see `select`). Seed 001 uses λ_d = 1000, λ_g = 1, λ_f = 3 on
/// unnormalised terms; seed 004's values were lost. Ours were set by looking
/// at the terms' typical sizes on the shared DEMs so that none dominates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Weights {
    pub feature: f64,
    pub deform: f64,
    pub ssd: f64,
    pub noise: f64,
    pub cut: f64,
    pub repeat: f64,
    /// Weight of the detail cost: `Σ_l ln((σ_c,l + 1 m) / (σ_ref,l + 1 m))²`
    /// between a candidate's wavelet noise levels and the library's
    /// typical ones ([`Library::noise_ref`]). Not in the seeds: with many
    /// sources of different character (plains next to alpine ranges), the
    /// relief-normalised profile costs cannot tell a faint ridge of a plain
    /// from a real one, and whole sketched features came out as smooth,
    /// detail-free bands (or single rough masses); this keeps every patch
    /// near the library's typical roughness. With one source it only
    /// prefers that source's typical patches.
    ///
    /// [`Library::noise_ref`]: super::Library::noise_ref
    pub detail: f64,
    /// Weight of the noise cost against the SSD in the integer first round
    /// of hole filling.
    pub fill_noise: u64,
    /// Weight of the coherence cost: the share of a window's placed pixels
    /// that came from another source than the candidate's. Not in the
    /// seeds (seed 004 takes the best patch of any source at every step).
    /// Without it, eight shared DEMs made a patchwork that switched source
    /// at nearly every patch (a patch of Alpine ridge, then one of a
    /// coastal plain, then one of a low plateau, all brought to one relief
    /// but each with its own mix of fine and mid-scale relief): blobs of
    /// mush between sharp patches, ridges broken into lumps, and the
    /// plains' fine noise with none of their structure. Real terrain
    /// changes character over tens of kilometres, not every patch; with
    /// this cost a source is kept until another fits clearly better. With
    /// one source it is always 0.
    pub coherence: f64,
}

impl Default for Weights {
    fn default() -> Self {
        Weights {
            feature: 1.0,
            deform: 0.5,
            ssd: 1.0,
            noise: 0.5,
            cut: 0.5,
            repeat: 0.5,
            detail: 1.0,
            fill_noise: 4,
            coherence: 1.0,
        }
    }
}

/// Synthesis parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Params {
    /// Patch side in pixels (multiple of 8, 16..=256).
    pub patch: usize,
    /// PPA dip threshold on sources, as a fraction of their 2–98 % relief.
    pub source_dip: f32,
    /// Weakest source feature kept, as a fraction of relief.
    pub source_min_prominence: f32,
    /// At most this many feature nodes per kind and source (strongest kept).
    pub max_source_nodes: usize,
    /// Best-set size per source (seed 004 §6.3.1: 5).
    pub best_per_source: usize,
    /// Candidates that get a graph-cut cost (seed 004: 5).
    pub finalists: usize,
    /// Amplitude of the final sketch deformation, as a fraction of the
    /// synthesized relief (0 = off); see [`deform_by_sketch`].
    ///
    /// [`deform_by_sketch`]: super::deform_by_sketch
    pub sketch_relief: f32,
    pub weights: Weights,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            patch: 64,
            source_dip: 0.02,
            source_min_prominence: 0.01,
            max_source_nodes: 2500,
            best_per_source: 5,
            finalists: 5,
            sketch_relief: 1.0,
            weights: Weights::default(),
        }
    }
}

impl Params {
    pub(super) fn check(&self) -> Result<(), PatchError> {
        if !(16..=256).contains(&self.patch) || self.patch % 8 != 0 {
            return Err(PatchError::PatchSize(self.patch));
        }
        Ok(())
    }
}
