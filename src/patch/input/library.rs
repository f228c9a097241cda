//! The prepared sources ([`Library`]): the source DEMs whose relief fits
//! the library's, each brought to it and prepared once (features and
//! candidates, optionally through the disk cache), then reused across
//! sketches.

use crate::Heightfield;
use crate::patch::input::cache;
use crate::patch::place::candidates::{self, PreparedSource};
use crate::patch::{Params, PatchError};
use crate::progress::Progress;
use crate::resample::resample;
use std::borrow::Cow;

/// The most a source's heights are stretched to reach the library's relief.
///
/// Why sources are chosen by relief: patches of different sources sit side
/// by side as one style only at one relief, and seed 004 mixes sources
/// without saying how. Brought to the median of the eight shared DEMs'
/// reliefs (810 m; they span 193 m to 1.96 km), a sketch's ranges came out
/// at 36–41 % of the relief the Pyrenees alone give them, smooth and with
/// dense contours; brought to the largest, the plains were stretched up to
/// ×10 into ranges, with their terraces and pits. Left at their own relief,
/// the detail cost picked mid-relief hills everywhere (20–61 %); with the
/// stretch capped at ×1.5 or ×2, a patchwork of scales (54–97 %) that
/// scored 2.4–4.3 against its dominant source. A sketch of ridges and valleys asks for the relief of the
/// library's ranges, and only the sources that have it can make them: on
/// the three example sketches the eight DEMs then keep 91–107 % of the
/// one-source relief (the Pyrenees, Yosemite and the Riviera take part).
pub const MAX_STRETCH: f32 = 2.0;

/// Prepared sources, reusable across sketches (the cache of seed 004 §5.4).
#[derive(Debug, Clone)]
pub struct Library {
    /// The sources that take part, in the order given (the others are in
    /// [`Library::left_out`]).
    pub sources: Vec<PreparedSource>,
    /// The relief every source in [`Library::sources`] is brought to: the
    /// largest of the given sources' 2–98 % reliefs, in metres.
    pub relief: f32,
    /// The given sources too flat for [`Library::relief`] (under
    /// 1/`MAX_STRETCH` of it), with their own relief in metres: left
    /// out, and said so to the user.
    pub left_out: Vec<(String, f32)>,
    pub params: Params,
    /// The library's typical roughness: per wavelet level, the median
    /// noise statistic ([`costs::noise_levels`], decimetres) of every
    /// source's non-feature candidates; see [`Weights::detail`].
    ///
    /// [`costs::noise_levels`]: crate::patch::place::costs::noise_levels
    /// [`Weights::detail`]: crate::patch::Weights::detail
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
        let sources = &common_cell(sources)?;
        for (name, hf) in sources {
            if hf.width() < 2 * params.patch || hf.height() < 2 * params.patch {
                return Err(PatchError::SourceSize {
                    name: name.to_string(),
                    width: hf.width(),
                    height: hf.height(),
                    cell_m: hf.cell_size(),
                    patch: params.patch,
                });
            }
        }
        let reliefs: Vec<f32> = sources
            .iter()
            .map(|(_, hf)| candidates::relief(hf.data()).max(1.0))
            .collect();
        let target = reliefs.iter().copied().fold(0.0, f32::max);
        progress.start("preparing sources", sources.len() as u64);
        let mut out = Vec::with_capacity(sources.len());
        let mut left_out = Vec::new();
        let mut hits = 0;
        for ((name, hf), &rel) in sources.iter().zip(&reliefs) {
            if rel * MAX_STRETCH < target {
                left_out.push((name.to_string(), rel));
                progress.advance(1);
                continue;
            }
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
                relief: target,
                left_out,
                params: *params,
                noise_ref,
            },
            hits,
        ))
    }
}

/// The sources on one grid: each resampled to the median of their cell
/// sizes (area-weighted when reducing, `crate::resample`) unless it is
/// within 1 % of it.
///
/// Why: patches are copied pixel for pixel, so a source at another cell
/// size would keep its pixel scale in the output — a 30 m DEM among 92 m
/// ones would enter 3× wider than it is on the ground, its slopes a third
/// as steep. (On sketch river_ranges.json with the eight shared DEMs, six
/// of them at 92 m, the output's median slope goes 7.6° → 8.1° only: the
/// softness of many-source outputs has other causes.)
fn common_cell(
    sources: &[(String, Heightfield)],
) -> Result<Vec<(&str, Cow<'_, Heightfield>)>, PatchError> {
    let mut cells: Vec<f64> = sources.iter().map(|(_, hf)| hf.cell_size()).collect();
    cells.sort_by(f64::total_cmp);
    let cell = cells[cells.len() / 2];
    sources
        .iter()
        .map(|(name, hf)| {
            let k = hf.cell_size() / cell;
            if (k - 1.0).abs() <= 0.01 {
                return Ok((name.as_str(), Cow::Borrowed(hf)));
            }
            let (w, h) = (
                ((hf.width() as f64 * k).round() as usize).max(1),
                ((hf.height() as f64 * k).round() as usize).max(1),
            );
            let r = resample(hf, w, h).map_err(crate::Error::from)?;
            Ok((name.as_str(), Cow::Owned(r)))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp(n: usize, cell: f64) -> (String, Heightfield) {
        let mut hf = Heightfield::new(n, n, cell).unwrap();
        for (k, v) in hf.data_mut().iter_mut().enumerate() {
            *v = (k % n) as f32 * cell as f32 * 0.5;
        }
        (format!("{n}@{cell}"), hf)
    }

    #[test]
    fn sources_are_brought_to_the_median_cell_size() {
        let sources = [ramp(300, 30.0), ramp(100, 90.0), ramp(101, 90.5)];
        let out = common_cell(&sources).unwrap();
        let sizes: Vec<(usize, f64)> = out
            .iter()
            .map(|(_, h)| (h.width(), h.cell_size()))
            .collect();
        // The 30 m source shrinks 3×, the 90.5 m one is within 1 % and kept
        // as it is (borrowed); the ground slope (0.5 m/m) survives resampling.
        assert_eq!(sizes[0].0, 100);
        assert!((sizes[0].1 - 90.0).abs() < 1e-9, "{sizes:?}");
        assert!(matches!(out[2].1, Cow::Borrowed(_)), "kept without a copy");
        assert_eq!(*out[2].1, ramp(101, 90.5).1);
        let r = &out[0].1;
        let slope = (r.get(60, 50) - r.get(40, 50)) as f64 / (20.0 * r.cell_size());
        assert!((slope - 0.5).abs() < 0.01, "slope {slope}");
    }
}
