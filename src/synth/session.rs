//! Editing sessions (paper §5.3, DESIGN §2): a sequence of edits, each
//! re-synthesized coherently with the previous frame.
//!
//! Per frame, W⁰ (quarters) is 4 (unweighted) inside the influence of the
//! constraints, type paint and pastes edited in this step (a replaced
//! constraint: where its samples changed, see `mark`; and where a
//! sculpt edit changed the target), 1 (coherent,
//! 0.25) elsewhere and 0 where frozen (freezing brush, pasted regions);
//! W^i follows by `reduce_weights`. The previous frame's per-pass results
//! are the coherence candidates, and with [`Session::restrict`] only the
//! region that can change is re-synthesized (exactly, see
//! [`crate::synth::Guides::restrict`]).

use super::control::{
    Blend, Constraint, ConstraintId, Controls, FIRST_LEVEL, Paste, PasteSource, UNCONSTRAINED,
};
use super::window::row_bounds;
use super::{Frames, Guides, Params, SynthError, Synthesizer, union};
use crate::database::Database;
use crate::heightfield::Heightfield;
use crate::level::state::{level_size, top_level};
use crate::stages::correct::{W_COHERENT, W_FREE, W_FROZEN};
use rayon::prelude::*;
use std::sync::Arc;
use std::time::Duration;
use thiserror::Error;

mod guides;
mod mark;
mod paste;
mod sculpt;
mod snapshot;

pub use snapshot::Snapshot;

/// Pixels around a paste left unweighted in its step, so it blends in.
pub const PASTE_MARGIN: f64 = 8.0;

/// One change to the controls.
#[derive(Debug, Clone)]
pub enum Edit {
    /// Adds a constraint, or replaces the one with this id.
    SetConstraint(ConstraintId, Arc<dyn Constraint>),
    RemoveConstraint(ConstraintId),
    /// Replaces R⁰ (see [`Controls::types`]); None clears it.
    PaintTypes(Option<Vec<u8>>),
    /// Replaces the freeze mask; None clears it.
    Freeze(Option<Vec<bool>>),
    Paste(Paste),
    /// Replaces the sculpt layer (None clears it); only where the old and
    /// new layers' targets differ is re-synthesized.
    Sculpt(Option<Arc<super::control::SculptLayer>>),
}

/// Invalid edits and sessions.
#[non_exhaustive]
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SessionError {
    #[error(transparent)]
    Synth(#[from] SynthError),
    #[error("removing constraint {0}: no constraint has this id")]
    NoConstraint(u64),
    #[error("{what} has {got} pixels: expected {width}×{height} = {}", width * height)]
    MaskSize {
        what: &'static str,
        got: usize,
        width: usize,
        height: usize,
    },
    #[error("type map pixel ({x}, {y}) has type {id}: expected 0..={max} or 255 (unconstrained)")]
    TypeId {
        x: usize,
        y: usize,
        id: u8,
        max: usize,
    },
    #[error("paste source exemplar {index} does not exist: the database has {count}")]
    PasteExemplar { index: usize, count: usize },
    #[error("paste lasso has {0} points: expected at least 3")]
    PasteLasso(usize),
    #[error("paste height offset {0} m is invalid: expected a finite value")]
    PasteDelta(f64),
}

/// Where a frame differs from the one before.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// Per output pixel: the height changed (any bit).
    pub mask: Vec<bool>,
    /// How many pixels changed.
    pub pixels: usize,
    /// Bounds `[x0, y0, x1, y1)` of the changed pixels.
    pub bounds: Option<[usize; 4]>,
}

/// One synthesized frame.
#[derive(Debug, Clone)]
pub struct Frame {
    pub heightfield: Heightfield,
    /// None for the first frame.
    pub change: Option<Change>,
    pub time: Duration,
}

/// An editing session on one output.
pub struct Session<'db> {
    synth: Synthesizer<'db>,
    width: usize,
    height: usize,
    seed: u32,
    controls: Controls,
    blend: Blend,
    /// The last frame's per-pass results and rasters.
    frames: Option<Frames>,
    guides: Option<Guides>,
    /// Per level (index = level), pasted pixels: frozen, with stored S, V.
    pasted: Vec<Vec<bool>>,
    /// Per level, pixels pasted in the current step.
    fresh: Vec<Vec<bool>>,
    last: Option<Heightfield>,
    /// Use coherence (paper §5.3); off = every frame from scratch.
    pub coherence: bool,
    /// Re-synthesize only where the frame can change (same bytes).
    pub restrict: bool,
}

impl<'db> Session<'db> {
    pub fn new(
        db: &'db Database,
        params: Params,
        width: usize,
        height: usize,
        seed: u32,
    ) -> Result<Session<'db>, SessionError> {
        crate::size::check_dims(width, height).map_err(SynthError::from)?;
        let synth = Synthesizer::new(db, params)?;
        let last = synth.coarsest().min(top_level(width, height));
        let pasted = (0..=last)
            .map(|i| {
                let (w, h) = level_size(width, height, i);
                vec![false; w * h]
            })
            .collect();
        Ok(Session {
            fresh: Vec::new(),
            blend: Blend::new(width, height, last, db.quantization()),
            synth,
            width,
            height,
            seed,
            controls: Controls::default(),
            frames: None,
            guides: None,
            pasted,
            last: None,
            coherence: true,
            restrict: true,
        })
    }

    pub fn controls(&self) -> &Controls {
        &self.controls
    }

    /// The last frame's per-level, per-pass results (for inspection).
    pub fn frames(&self) -> Option<&Frames> {
        self.frames.as_ref()
    }

    /// The synthesizer (database, parameters, cell size).
    pub fn synthesizer(&self) -> &Synthesizer<'db> {
        &self.synth
    }

    /// The synthesizer, e.g. to move the session's stages to the GPU
    /// ([`Synthesizer::use_backend`]): every frame runs on its backend, with
    /// the same bytes on each.
    pub fn synthesizer_mut(&mut self) -> &mut Synthesizer<'db> {
        &mut self.synth
    }

    /// The last frame's heights.
    pub fn heightfield(&self) -> Option<&Heightfield> {
        self.last.as_ref()
    }

    /// Applies edits (all or none) and re-synthesizes.
    pub fn apply(&mut self, edits: Vec<Edit>) -> Result<Frame, SessionError> {
        let t = std::time::Instant::now();
        for e in &edits {
            self.check(e)?;
        }
        // A paste writes into the previous frame: make one first.
        if self.frames.is_none() && edits.iter().any(|e| matches!(e, Edit::Paste(_))) {
            let (pastes, rest): (Vec<_>, Vec<_>) =
                edits.into_iter().partition(|e| matches!(e, Edit::Paste(_)));
            self.apply(rest)?;
            let mut frame = self.apply(pastes)?;
            frame.change = None;
            frame.time = t.elapsed();
            return Ok(frame);
        }
        // Pixels pasted in this step (none without a paste: then nothing
        // is allocated or scanned for them).
        self.fresh = match edits.iter().any(|e| matches!(e, Edit::Paste(_))) {
            true => self.pasted.iter().map(|p| vec![false; p.len()]).collect(),
            false => Vec::new(),
        };
        let (w0, h0) = level_size(self.width, self.height, 0);
        let mut weights = vec![W_COHERENT; w0 * h0];
        for e in edits {
            match e {
                Edit::SetConstraint(id, c) => {
                    let old = self.controls.constraints.insert(id, c.clone());
                    if let Some(old) = &old {
                        self.blend(&**old, -1);
                    }
                    self.blend(&*c, 1);
                    mark::free_changed(&*c, old.as_deref(), &mut weights, w0, h0);
                }
                Edit::RemoveConstraint(id) => {
                    let old = self.controls.constraints.remove(&id).expect("checked");
                    self.blend(&*old, -1);
                    mark::free_changed(&*old, None, &mut weights, w0, h0);
                }
                Edit::PaintTypes(map) => {
                    let before = self.controls.types.take();
                    for y in 0..self.height {
                        for x in 0..self.width {
                            let i = y * self.width + x;
                            let get =
                                |m: &Option<Vec<u8>>| m.as_ref().map_or(UNCONSTRAINED, |m| m[i]);
                            if get(&before) != get(&map) {
                                weights[y * w0 + x] = W_FREE;
                            }
                        }
                    }
                    self.controls.types = map;
                }
                Edit::Freeze(mask) => self.controls.freeze = mask,
                Edit::Sculpt(layer) => self.sculpt(layer, &mut weights),
                Edit::Paste(p) => {
                    self.paste(&p, &mut weights);
                    self.controls.pastes.push(p);
                }
            }
        }
        if let Some(f) = &self.controls.freeze {
            for y in 0..self.height {
                for x in 0..self.width {
                    if f[y * self.width + x] {
                        weights[y * w0 + x] = W_FROZEN;
                    }
                }
            }
        }
        if !self.controls.pastes.is_empty() {
            for (i, p) in self.pasted[0].iter().enumerate() {
                if *p {
                    weights[i] = W_FROZEN;
                }
            }
        }
        let guides = self.guides(weights);
        // The run takes the previous frame's results (and reuses their
        // buffers): they are replaced by this frame's.
        let prev = self.frames.take().filter(|_| self.coherence);
        let run = self
            .synth
            .run_with(self.width, self.height, self.seed, &guides, prev, true);
        let (out, frames) = match run {
            Ok(r) => r,
            Err(e) => {
                // The run took the previous frame's results, and `guides`
                // its targets: the next frame is synthesized whole.
                self.guides = None;
                return Err(e.into());
            }
        };
        let mut hf = out.heightfield;
        if let (Some(f), Some(old)) = (&self.controls.freeze, &self.last) {
            // Frozen pixels keep the heights the user froze. Their S and V
            // are kept by the weights, but reconstruct averages each pixel
            // with its 3×3 neighbours' predictions, so a frozen pixel beside
            // an edited one would still move by a share of the new join.
            for ((h, o), _) in hf
                .data_mut()
                .iter_mut()
                .zip(old.data())
                .zip(f)
                .filter(|(_, f)| **f)
            {
                *h = *o;
            }
        }
        let change = self.last.as_ref().map(|old| change(old, &hf));
        self.frames = frames;
        self.guides = Some(guides);
        self.last = Some(hf.clone());
        Ok(Frame {
            heightfield: hf,
            change,
            time: t.elapsed(),
        })
    }

    /// Adds `c` to the blend (`sign` 1) or takes it out (−1), reading the
    /// finest level's samples from those it keeps ([`Constraint::centres`]).
    fn blend(&mut self, c: &dyn Constraint, sign: i64) {
        match (c.centres(), sign > 0) {
            (Some(k), true) => self.blend.add_kept(c, k),
            (Some(k), false) => self.blend.subtract_kept(c, k),
            (None, true) => self.blend.add(c),
            (None, false) => self.blend.subtract(c),
        }
    }

    /// Validates an edit before anything changes.
    fn check(&self, e: &Edit) -> Result<(), SessionError> {
        let n = self.width * self.height;
        let size = |what, got| {
            if got == n {
                Ok(())
            } else {
                Err(SessionError::MaskSize {
                    what,
                    got,
                    width: self.width,
                    height: self.height,
                })
            }
        };
        match e {
            Edit::SetConstraint(..) | Edit::Sculpt(_) => Ok(()),
            Edit::RemoveConstraint(id) => match self.controls.constraints.contains_key(id) {
                true => Ok(()),
                false => Err(SessionError::NoConstraint(id.0)),
            },
            Edit::PaintTypes(None) | Edit::Freeze(None) => Ok(()),
            Edit::PaintTypes(Some(m)) => {
                size("type map", m.len())?;
                let max = self.synth.database().type_names().len() - 1;
                match m
                    .iter()
                    .position(|&t| t != UNCONSTRAINED && t as usize > max)
                {
                    None => Ok(()),
                    Some(i) => Err(SessionError::TypeId {
                        x: i % self.width,
                        y: i / self.width,
                        id: m[i],
                        max,
                    }),
                }
            }
            Edit::Freeze(Some(m)) => size("freeze mask", m.len()),
            Edit::Paste(p) => {
                let count = self.synth.database().meta().exemplars.len();
                if let PasteSource::Exemplar(index) = p.source
                    && index >= count
                {
                    return Err(SessionError::PasteExemplar { index, count });
                }
                if p.lasso.len() < 3 {
                    return Err(SessionError::PasteLasso(p.lasso.len()));
                }
                if !p.delta_m.is_finite() {
                    return Err(SessionError::PasteDelta(p.delta_m));
                }
                Ok(())
            }
        }
    }
}
/// Where `new` differs from `old` (same size), bit for bit; in parallel
/// (it runs on every edit, over every output pixel).
pub fn change(old: &Heightfield, new: &Heightfield) -> Change {
    let w = new.width();
    // Zeroed by the allocator: the pages of rows that compare equal (most
    // of an edit's) are never written. Rows compare as bytes first, one
    // `memcmp` each; only differing rows are looked at pixel by pixel.
    let mut mask = vec![false; old.data().len()];
    fn bits(h: &Heightfield, y: usize) -> &[u32] {
        bytemuck::cast_slice(h.row(y))
    }
    let (pixels, bounds) = mask
        .par_chunks_mut(w)
        .enumerate()
        .map(|(y, row)| {
            let (a, b) = (bits(old, y), bits(new, y));
            if a == b {
                return (0, None);
            }
            for ((m, a), b) in row.iter_mut().zip(a).zip(b) {
                *m = a != b;
            }
            let n = row.iter().filter(|c| **c).count();
            (n, row_bounds(y, 0, row.iter().copied()))
        })
        .reduce(|| (0, None), |(n, a), (m, b)| (n + m, union(a, b)));
    Change {
        pixels,
        mask,
        bounds,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn change_counts_and_bounds_the_differing_pixels() {
        let (w, h) = (37, 23);
        let old = Heightfield::from_fn(w, h, 1.0, |x, y| (x * 3 + y) as f32).unwrap();
        let diffs: [&[(usize, usize)]; 4] = [
            &[],
            &[(5, 7)],
            &[(36, 0), (0, 22), (12, 9)],
            // -0.0 against 0.0: equal as floats, not as bits.
            &[(0, 0), (3, 4), (4, 3)],
        ];
        for d in diffs {
            let mut new = old.clone();
            for &(x, y) in d {
                let v = &mut new.data_mut()[y * w + x];
                *v = if *v == 0.0 { -0.0 } else { *v + 0.5 };
            }
            let c = change(&old, &new);
            assert_eq!(c.pixels, d.len());
            let want = d
                .iter()
                .fold(None, |b, &(x, y)| union(b, Some([x, y, x + 1, y + 1])));
            assert_eq!(c.bounds, want);
            for (k, m) in c.mask.iter().enumerate() {
                assert_eq!(*m, d.contains(&(k % w, k / w)), "pixel {k}");
            }
        }
    }
}
