//! Novelty (issue 46): how much of a terrain is a recognisable copy of its
//! exemplars, and how much of it repeats itself — what the realism ratio
//! cannot see (a verbatim copy of the reference scores ≤ 1 by
//! construction).
//!
//! **Copy share** ([`copies`]): heights are averaged over `ds × ds` blocks
//! (default 2); the synthesis is cut into non-overlapping windows of
//! `window` cells (default 64: 32 × 32 after the averaging), at most
//! `max_windows` of them evenly spread (default 150); windows flatter than
//! `flat` × the exemplars' median window standard deviation are skipped
//! (default ¼: a plain matches any plain); each remaining window gets its
//! best normalised cross-correlation (NCC) with any window of any
//! exemplar, in any of the 8 orientations (rotations by 90° and mirrors).
//! A window whose best NCC is at least `threshold` (default 0.95) is a
//! **copy**: a person sees the same landform. The copy share is the share
//! of scored windows that are copies; the median best NCC is reported
//! beside it. This is the rule of `../shared/tools/novelty.py` (the
//! reference script, numpy + scikit-image), window for window.
//!
//! **Baseline** ([`halves`]): the same figure for a real DEM's top half
//! against its bottom half — what real terrain scores against another part
//! of itself (0–21 % on the shared DEMs), the bar a synthesis is held to.
//!
//! **Self-repetition** ([`repetition`]): the share of a synthesis's windows
//! that have a near-duplicate elsewhere in the same synthesis (same NCC
//! rule, every orientation, positions whose window overlaps the window
//! itself excluded): landmarks that recur across a large world.
//!
//! NCC is invariant to a height offset and scale, so a copy raised,
//! lowered or exaggerated is still a copy.

mod map;
mod ncc;

pub use map::copy_map;
pub use ncc::Orientation;

use super::EvalError;
use crate::heightfield::Heightfield;
use ncc::{Grid, Target};
use serde::Serialize;

/// The rule's settings (defaults: the reference script's).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Params {
    /// Window side in cells of the synthesis.
    pub window: usize,
    /// Heights are averaged over blocks of this side before matching.
    pub downsample: usize,
    /// Best NCC at or above which a window is a copy.
    pub threshold: f64,
    /// Windows whose standard deviation is under this fraction of the
    /// exemplars' median window standard deviation are not scored.
    pub flat: f64,
    /// At most this many windows are scored, evenly spread.
    pub max_windows: usize,
}

impl Default for Params {
    fn default() -> Params {
        Params {
            window: 64,
            downsample: 2,
            threshold: 0.95,
            flat: 0.25,
            max_windows: 150,
        }
    }
}

/// One scored window of a synthesis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Window {
    /// Corner of the window, in cells of the synthesis.
    pub x: usize,
    pub y: usize,
    /// Its best NCC.
    pub ncc: f64,
    /// Where that is: the exemplar (index into the list given; 0 for
    /// self-repetition), the orientation (0–7: bit 0 mirrors x, bit 1
    /// mirrors y, bit 2 transposes) and the matching window's corner in
    /// that exemplar's cells.
    pub exemplar: usize,
    pub orientation: u8,
    pub source_x: usize,
    pub source_y: usize,
}

/// The result of one novelty measure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Novelty {
    /// Share of the scored windows that are copies (0–1).
    pub share: f64,
    /// Median best NCC of the scored windows.
    pub median_ncc: f64,
    /// Windows scored, and windows skipped as flat.
    pub scored: usize,
    pub flat: usize,
    pub params: Params,
    /// Every scored window.
    pub windows: Vec<Window>,
}

impl Novelty {
    /// Whether a scored window is a copy.
    pub fn is_copy(&self, w: &Window) -> bool {
        w.ncc >= self.params.threshold
    }
}

/// The three figures of a synthesis against its exemplars.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Report {
    /// The synthesis against the exemplars ([`copies`]).
    pub copies: Novelty,
    /// Each exemplar's [`halves`] (None where it is under two windows high).
    pub baselines: Vec<Option<Novelty>>,
    /// The mean share of the baselines: what real terrain scores against
    /// itself (None when no exemplar is large enough).
    pub baseline: Option<f64>,
    /// The synthesis against itself ([`repetition`]).
    pub repetition: Novelty,
}

/// [`copies`], each exemplar's [`halves`] and [`repetition`] of `synth`.
pub fn measure(
    synth: &Heightfield,
    exemplars: &[&Heightfield],
    p: &Params,
) -> Result<Report, EvalError> {
    let copies = copies(synth, exemplars, p)?;
    let repetition = repetition(synth, exemplars, p)?;
    let baselines = exemplars
        .iter()
        .map(|e| match halves(e, p) {
            Ok(n) => Ok(Some(n)),
            Err(EvalError::TooSmall { .. }) => Ok(None),
            Err(e) => Err(e),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let shares: Vec<f64> = baselines.iter().flatten().map(|b| b.share).collect();
    let baseline = (!shares.is_empty()).then(|| shares.iter().sum::<f64>() / shares.len() as f64);
    Ok(Report {
        copies,
        baselines,
        baseline,
        repetition,
    })
}

/// The copy share of `synth` against `exemplars` (see the module docs).
pub fn copies(
    synth: &Heightfield,
    exemplars: &[&Heightfield],
    p: &Params,
) -> Result<Novelty, EvalError> {
    let s = prepare(synth, p)?;
    let ex = prepare_all(exemplars, p)?;
    let flat = flat_std(&ex, p);
    score(&s, &ex, flat, p, &|_, _, _| None)
}

/// The baseline of a real DEM: its top half (rows `..h/2`) against its
/// bottom half (rows `h/2..`), as [`copies`] scores them.
pub fn halves(reference: &Heightfield, p: &Params) -> Result<Novelty, EvalError> {
    let (w, h) = (reference.width(), reference.height());
    let crop = |y: usize, n: usize| {
        reference
            .crop(0, y, w, n)
            .map_err(|_| too_small(w, h, 2 * p.window))
    };
    let (top, bottom) = (crop(0, h / 2)?, crop(h / 2, h - h / 2)?);
    copies(&top, &[&bottom], p)
}

/// The self-repetition of `synth`: each window against the rest of the
/// synthesis (positions whose window overlaps it excluded, in every
/// orientation). Windows are skipped as flat against `exemplars`' median
/// window (the synthesis's own when none are given).
pub fn repetition(
    synth: &Heightfield,
    exemplars: &[&Heightfield],
    p: &Params,
) -> Result<Novelty, EvalError> {
    let s = prepare(synth, p)?;
    let flat = if exemplars.is_empty() {
        flat_std(std::slice::from_ref(&s), p)
    } else {
        flat_std(&prepare_all(exemplars, p)?, p)
    };
    let n = p.window / p.downsample;
    // A window must not match itself: positions whose window overlaps it
    // (corners within n − 1 cells both ways), in every orientation.
    let near = |(px, py): (usize, usize), o: Orientation| {
        let (ow, oh) = o.size(s.w, s.h);
        let src = (
            px.saturating_sub(n - 1),
            py.saturating_sub(n - 1),
            (px + n - 1).min(s.w - n),
            (py + n - 1).min(s.h - n),
        );
        Some(o.target_box(src, n, ow, oh))
    };
    score(&s, std::slice::from_ref(&s), flat, p, &|at, _, o| {
        near(at, o)
    })
}

/// [`prepare`] of every one of `hfs`, in order.
fn prepare_all(hfs: &[&Heightfield], p: &Params) -> Result<Vec<Grid>, EvalError> {
    hfs.iter().map(|hf| prepare(hf, p)).collect()
}

/// A heightfield's averaged grid, checked: no nodata, at least one window.
fn prepare(hf: &Heightfield, p: &Params) -> Result<Grid, EvalError> {
    let (w, h) = (hf.width(), hf.height());
    let valid = p.downsample > 0
        && p.window / p.downsample >= 4
        && p.max_windows >= 2
        && p.threshold > 0.0
        && p.threshold <= 1.0
        && p.flat >= 0.0;
    if !valid {
        return Err(EvalError::NoveltyParams(*p));
    }
    if w < p.window || h < p.window {
        return Err(too_small(w, h, p.window));
    }
    super::check_nodata(hf)?;
    Ok(Grid::down(hf.data(), w, h, p.downsample))
}

fn too_small(width: usize, height: usize, min: usize) -> EvalError {
    EvalError::TooSmall { width, height, min }
}

/// `flat` × the median standard deviation of the non-overlapping windows
/// of `grids` (numpy's median: the mean of the middle two of an even count).
fn flat_std(grids: &[Grid], p: &Params) -> f64 {
    let n = p.window / p.downsample;
    let mut stds: Vec<f64> = grids
        .iter()
        .flat_map(|g| {
            tiles(g, n)
                .into_iter()
                .map(move |(x, y)| g.window_std(x, y, n))
        })
        .collect();
    p.flat * median(&mut stds)
}

/// Corners of the non-overlapping `n × n` windows of `g`, row-major.
fn tiles(g: &Grid, n: usize) -> Vec<(usize, usize)> {
    (0..=g.h - n)
        .step_by(n)
        .flat_map(|y| (0..=g.w - n).step_by(n).map(move |x| (x, y)))
        .collect()
}

/// `max` of `all` evenly spread (numpy's `linspace(0, len − 1, max)`
/// rounded half to even), or all of them.
fn spread<T: Copy>(all: &[T], max: usize) -> Vec<T> {
    if all.len() <= max {
        return all.to_vec();
    }
    let last = (all.len() - 1) as f64;
    let step = last / (max - 1) as f64;
    (0..max)
        .map(|i| {
            let t = if i + 1 == max { last } else { i as f64 * step };
            all[t.round_ties_even() as usize]
        })
        .collect()
}

/// The median of `v` (sorted in place); 0 when empty.
fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        (v[m - 1] + v[m]) / 2.0
    }
}

/// Which positions a window may not match: (its corner in grid cells, the
/// exemplar, the orientation) → a box of oriented positions, if any.
type Exclude<'a> = dyn Fn((usize, usize), usize, Orientation) -> Option<[usize; 4]> + Sync + 'a;

/// Scores the spread windows of `s` that are not flat against every
/// exemplar grid.
fn score(
    s: &Grid,
    ex: &[Grid],
    flat: f64,
    p: &Params,
    exclude: &Exclude<'_>,
) -> Result<Novelty, EvalError> {
    let n = p.window / p.downsample;
    let chosen = spread(&tiles(s, n), p.max_windows);
    let (scored, flat_count): (Vec<(usize, usize)>, usize) = {
        let kept: Vec<_> = chosen
            .iter()
            .copied()
            .filter(|&(x, y)| s.window_std(x, y, n) >= flat)
            .collect();
        let skipped = chosen.len() - kept.len();
        (kept, skipped)
    };
    let templates: Vec<Vec<f64>> = scored.iter().map(|&(x, y)| s.window(x, y, n)).collect();
    let mut best: Vec<Option<Window>> = vec![None; scored.len()];
    for (e, g) in ex.iter().enumerate() {
        if g.w < n || g.h < n {
            continue;
        }
        let target = Target::new(g, n);
        let here = |k: usize, o: Orientation| exclude(scored[k], e, o);
        for (k, b) in target.best(&templates, &here).into_iter().enumerate() {
            let Some(b) = b else { continue };
            if best[k].is_some_and(|w| w.ncc >= b.ncc) {
                continue;
            }
            let (ow, oh) = target.size(b.o);
            let (sx, sy) = b.o.source_window(b.x, b.y, n, ow, oh);
            best[k] = Some(Window {
                x: scored[k].0 * p.downsample,
                y: scored[k].1 * p.downsample,
                ncc: b.ncc,
                exemplar: e,
                orientation: b.o.0,
                source_x: sx * p.downsample,
                source_y: sy * p.downsample,
            });
        }
    }
    let windows: Vec<Window> = best.into_iter().flatten().collect();
    let copies = windows.iter().filter(|w| w.ncc >= p.threshold).count();
    let mut nccs: Vec<f64> = windows.iter().map(|w| w.ncc).collect();
    Ok(Novelty {
        share: if windows.is_empty() {
            0.0
        } else {
            copies as f64 / windows.len() as f64
        },
        median_ncc: median(&mut nccs),
        scored: windows.len(),
        flat: flat_count,
        params: *p,
        windows,
    })
}

#[cfg(test)]
mod tests;
