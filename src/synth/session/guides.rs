//! A frame's per-level rasters (targets, type sets, weights) and where they
//! differ from the previous frame's, which bounds what restricted
//! re-synthesis corrects.
//!
//! An edit usually moves one constraint, so the previous frame's targets
//! are carried over and re-derived only where the blend's sums changed
//! ([`Blend::retarget`](crate::synth::control::Blend::retarget)); that
//! region is also where they can differ, so they are not compared pixel by
//! pixel either. At 1024² re-deriving and
//! comparing every level's targets took ~14 ms of a ~50 ms edit.

use super::super::window::row_bounds;
use super::super::{Guides, LevelGuide, union};
use super::{FIRST_LEVEL, Session};
use crate::level::state::level_size;
use crate::stages::common::ALL_TYPES;
use crate::stages::correct::nudge::Target;
use crate::stages::correct::{W_FREE, W_FROZEN};
use crate::stages::reduce_types::reduce_types;
use crate::stages::reduce_weights::reduce_weights;
use crate::synth::control::UNCONSTRAINED;
use rayon::prelude::*;
use std::ops::Range;

impl Session<'_> {
    /// Per-level rasters of this frame, with the pixels whose inputs differ
    /// from the previous frame's marked dirty. Takes the previous frame's
    /// targets (they become this frame's).
    pub(super) fn guides(&mut self, mut w0: Vec<u8>) -> Guides {
        let db = self.synth.database();
        let last = self.pasted.len() - 1;
        let cell = self.synth.cell_size_m();
        let full = ((1u64 << db.type_names().len()) - 1) as u32;
        let (lw, lh) = level_size(self.width, self.height, 0);
        let mut allowed = self.controls.types.as_ref().map(|m| {
            let mut r = vec![ALL_TYPES; lw * lh];
            for y in 0..self.height {
                for x in 0..self.width {
                    let t = m[y * self.width + x];
                    if t != UNCONSTRAINED {
                        r[y * lw + x] = 1 << t;
                    }
                }
            }
            r
        });
        let pasted = !self.controls.pastes.is_empty();
        let touched = self.blend.take_touched();
        let mut levels: Vec<LevelGuide> = Vec::with_capacity(last + 1);
        let mut moved = Vec::with_capacity(last + 1);
        for (i, touched) in touched.into_iter().enumerate().take(last + 1) {
            let (w, h) = level_size(self.width, self.height, i);
            // Each level's weights are reduced from the level below's,
            // which its guide already holds (no copy of either).
            let weights = match levels.last() {
                None => std::mem::take(&mut w0),
                Some(below) => {
                    let (cw, ch) = level_size(self.width, self.height, i - 1);
                    allowed = allowed.map(|a| reduce_types(&a, cw, ch, w, h, full));
                    let child = below.weights.as_deref().expect("every level has weights");
                    let mut weights = reduce_weights(child, cw, ch, w, h);
                    if pasted {
                        for (k, p) in self.pasted[i].iter().enumerate() {
                            if *p {
                                weights[k] = W_FROZEN;
                            }
                        }
                    }
                    weights
                }
            };
            let before = self
                .guides
                .as_mut()
                .and_then(|g| g.levels.get_mut(i))
                .and_then(|g| g.targets.take());
            let (targets, changed) = match before {
                Some(mut t) if self.blend.reaches(i) => {
                    let changed = self.blend.retarget(i, cell, &mut t, touched);
                    (Some(t), changed)
                }
                before => {
                    let now = self.blend.targets(i, cell).map(|t| t.cells);
                    let changed = differ(before.as_deref(), now.as_deref(), w, h);
                    (now, changed)
                }
            };
            moved.push(changed);
            levels.push(LevelGuide {
                targets,
                allowed: allowed.clone().filter(|_| i >= FIRST_LEVEL),
                weights: Some(weights),
                dirty: None,
            });
        }
        // Dirty: inputs that differ from the previous frame's, or changed
        // weights (a weight that changes switches how the previous result
        // competes; only freezing is safe, as it keeps the previous result).
        let prev = self.guides.as_ref();
        let none = LevelGuide::default();
        for (i, g) in levels.iter_mut().enumerate() {
            let (w, h) = level_size(self.width, self.height, i);
            let p = prev.and_then(|p| p.levels.get(i)).unwrap_or(&none);
            let fresh = self.fresh.get(i).map(|f| &f[..]);
            g.dirty = union(moved[i], dirty_bounds(g, p, fresh, w, h));
        }
        Guides {
            levels,
            restrict: self.restrict && self.coherence,
        }
    }
}

/// Bounds of the cells where two targets rasters of a `w × h` level
/// differ (None: no targets, i.e. [`Target::NONE`] everywhere).
fn differ(a: Option<&[Target]>, b: Option<&[Target]>, w: usize, h: usize) -> Option<[usize; 4]> {
    let at = |t: Option<&[Target]>, k: usize| t.map_or(Target::NONE, |t| t[k]);
    let row = |y: usize| row_bounds(y, 0, (y * w..(y + 1) * w).map(|k| at(a, k) != at(b, k)));
    match (a, b) {
        (None, None) => None,
        _ => (0..h).into_par_iter().map(row).reduce(|| None, union),
    }
}

/// Bounds of the pixels of a `w × h` level whose type sets or weights in
/// `g` differ from the previous frame's `p`, or that received pasted
/// values in this step (`fresh`: their previous results were
/// overwritten); the targets' differences are [`Session::guides`]'. Most
/// rows of an edit are unchanged: a row whose rasters compare equal as
/// slices is skipped without looking at its pixels.
fn dirty_bounds(
    g: &LevelGuide,
    p: &LevelGuide,
    fresh: Option<&[bool]>,
    w: usize,
    h: usize,
) -> Option<[usize; 4]> {
    fn same<T: PartialEq>(a: &Option<Vec<T>>, b: &Option<Vec<T>>, r: Range<usize>) -> bool {
        match (a, b) {
            (Some(a), Some(b)) => a[r.clone()] == b[r],
            (None, None) => true,
            _ => false,
        }
    }
    let a = |g: &LevelGuide, k: usize| g.allowed.as_ref().map_or(ALL_TYPES, |a| a[k]);
    let wt = |g: &LevelGuide, k: usize| g.weights.as_ref().map_or(W_FREE, |w| w[k]);
    let fresh_at = |k: usize| fresh.is_some_and(|f| f[k]);
    let row = |y: usize| {
        let r = y * w..(y + 1) * w;
        if same(&g.allowed, &p.allowed, r.clone())
            && same(&g.weights, &p.weights, r.clone())
            && !fresh.is_some_and(|f| f[r.clone()].contains(&true))
        {
            return None;
        }
        let differs = |k: usize| {
            a(g, k) != a(p, k) || (wt(g, k) != wt(p, k) && wt(g, k) != W_FROZEN) || fresh_at(k)
        };
        row_bounds(y, 0, r.map(differs))
    };
    (0..h).into_par_iter().map(row).reduce(|| None, union)
}
