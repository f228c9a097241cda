//! The prepared sources ([`Library`]): every source DEM brought to one
//! relief and prepared once (features and candidates, optionally through
//! the disk cache), then reused across sketches.

use super::candidates::{self, PreparedSource};
use super::{Params, PatchError, cache};
use crate::Heightfield;
use crate::progress::Progress;

/// Prepared sources, reusable across sketches (the cache of seed 004 §5.4).
#[derive(Debug, Clone)]
pub struct Library {
    pub sources: Vec<PreparedSource>,
    pub params: Params,
    /// The library's typical roughness: per wavelet level, the median
    /// noise statistic ([`costs::noise_levels`], decimetres) of every
    /// source's non-feature candidates; see [`Weights::detail`].
    ///
    /// [`costs::noise_levels`]: super::costs::noise_levels
    /// [`Weights::detail`]: super::Weights::detail
    pub noise_ref: [u32; 3],
}

impl Library {
    /// Prepares every source (features, candidates) once.
    pub fn prepare(
        sources: &[(String, Heightfield)],
        params: &Params,
        progress: &dyn Progress,
    ) -> Result<Library, PatchError> {
        Ok(Self::prepare_in(sources, params, None, progress)?.0)
    }

    /// [`Self::prepare`] through the disk cache in `dir` ([`cache`]): each
    /// source's features are read from there when an intact entry for the
    /// same DEM, parameters and code exists, and computed and stored
    /// otherwise. Returns the library and how many sources were read.
    pub fn prepare_cached(
        sources: &[(String, Heightfield)],
        params: &Params,
        dir: &std::path::Path,
        progress: &dyn Progress,
    ) -> Result<(Library, usize), PatchError> {
        Self::prepare_in(sources, params, Some(dir), progress)
    }

    fn prepare_in(
        sources: &[(String, Heightfield)],
        params: &Params,
        dir: Option<&std::path::Path>,
        progress: &dyn Progress,
    ) -> Result<(Library, usize), PatchError> {
        params.check()?;
        if sources.is_empty() {
            return Err(PatchError::NoSources);
        }
        for (name, hf) in sources {
            if hf.width() < 2 * params.patch || hf.height() < 2 * params.patch {
                return Err(PatchError::SourceSize {
                    name: name.clone(),
                    width: hf.width(),
                    height: hf.height(),
                    patch: params.patch,
                });
            }
        }
        // Sources are brought to one relief, the median of their 2–98 %
        // reliefs: patches of an alpine DEM and of a plain then sit side by
        // side as one style instead of a patchwork of scales (seed 004 mixes
        // sources without saying how; with our 8 DEMs spanning 345 m to
        // 2.7 km of relief the unscaled result is dominated by whichever
        // source the first patch came from).
        let reliefs: Vec<f32> = sources
            .iter()
            .map(|(_, hf)| candidates::relief(hf.data()).max(1.0))
            .collect();
        let mut sorted = reliefs.clone();
        sorted.sort_by(f32::total_cmp);
        let target = sorted[sorted.len() / 2];
        progress.start("preparing sources", sources.len() as u64);
        let mut out = Vec::with_capacity(sources.len());
        let mut hits = 0;
        for ((name, hf), rel) in sources.iter().zip(&reliefs) {
            let scale = target / rel;
            out.push(match dir {
                Some(d) => {
                    let (s, o) = cache::prepare(d, name, hf, params, scale)?;
                    hits += (o == cache::Outcome::Hit) as usize;
                    s
                }
                None => PreparedSource::prepare(name, hf, params, scale)?,
            });
            progress.advance(1);
        }
        progress.finish();
        let mut noise_ref = [0u32; 3];
        for (l, r) in noise_ref.iter_mut().enumerate() {
            let mut v: Vec<u32> = out
                .iter()
                .flat_map(|s| s.fill.iter().map(move |c| c.noise[l]))
                .collect();
            v.sort_unstable();
            *r = v.get(v.len() / 2).copied().unwrap_or(0);
        }
        Ok((
            Library {
                sources: out,
                params: *params,
                noise_ref,
            },
            hits,
        ))
    }
}
