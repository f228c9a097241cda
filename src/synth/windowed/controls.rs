//! Windowed synthesis under user control: a window of what a scene's
//! editing session makes in its first step (`Session::apply` of every
//! control at once), byte for byte, computed over cones.
//!
//! The session runs one frame with the geometric constraints and the type
//! paint, then — when there are pastes — writes the pastes into that
//! frame's per-pass results and runs a second, coherent frame (weights:
//! pasted and frozen pixels 0, a margin around the pastes free, the rest
//! coherent), whose frozen pixels keep the first frame's heights. Here:
//! - the **second frame** (or the only one) runs over the window's cone;
//! - the **first frame** runs over a cone that covers the second's regions
//!   at every level (its per-pass results are the second's coherence
//!   candidates, read pixel for pixel over the whole region, so they must
//!   be right over all of it, not only where the second frame is) and the
//!   sources of the pastes that reach them ([`super::paste::needs`]);
//! - **guides** are computed over each cone only: constraint targets are
//!   blended over the regions ([`Blend::over`]), type sets and weights are
//!   pyramids over aligned footprints ([`super::pyramid`]), paint is asked
//!   for over rectangles ([`WindowControls`]).
//!
//! Restricted re-synthesis (`Guides::restrict`) is off: it gives the same
//! bytes as a full second frame (tested in `tests/synth/control.rs`), and a
//! window's second frame is small anyway.

use super::paste::{self, PasteGeometry};
use super::pyramid::{footprints, type_sets, weight_sets};
use super::{WindowError, check_window};
use crate::heightfield::Heightfield;
use crate::level::state::{level_size, top_level};
use crate::stages::correct::{W_COHERENT, W_FREE, W_FROZEN};
use crate::synth::cone::{Cone, Rect, crop};
use crate::synth::control::{Blend, Constraint, FIRST_LEVEL, Paste, UNCONSTRAINED};
use crate::synth::session::PASTE_MARGIN;
use crate::synth::{Frames, Guides, LevelGuide, PassResult, SynthError, Synthesizer};
use std::sync::Arc;

/// Paint asked for over a rectangle of output pixels (inside the world),
/// row-major: how a window reads type paint and freeze masks without a
/// raster of the world (a scene paints its strokes over the rectangle).
pub type Paint<'a, T> = &'a (dyn Fn(Rect) -> Vec<T> + Sync);

/// The user's controls, as a windowed synthesis reads them.
#[derive(Clone, Copy)]
pub struct WindowControls<'a> {
    /// Point and curve constraints.
    pub constraints: &'a [Arc<dyn Constraint>],
    /// Painted type ids of the database ([`UNCONSTRAINED`] = none); `None`
    /// when nothing is painted.
    pub types: Option<Paint<'a, u8>>,
    /// Frozen pixels; `None` when nothing is frozen.
    pub freeze: Option<Paint<'a, bool>>,
    /// Copy-pastes, in order.
    pub pastes: &'a [Paste],
}

impl Synthesizer<'_> {
    /// The `window` of the `world` that a scene's session makes with these
    /// controls in its first step, byte for byte (see the module docs), in
    /// memory proportional to the window plus the pastes' sources.
    pub fn synthesize_window_with(
        &self,
        world: (usize, usize),
        window: Rect,
        seed: u32,
        c: &WindowControls<'_>,
    ) -> Result<Heightfield, SynthError> {
        check_window(world, window)?;
        let db = self.database();
        let last = self.coarsest().min(top_level(world.0, world.1));
        let cone = self.cone(world, window, &[]);
        let pastes: Vec<PasteGeometry> = c
            .pastes
            .iter()
            .map(|p| PasteGeometry::new(p, db, world, last))
            .collect();
        let first = match pastes.is_empty() {
            true => cone.clone(),
            false => {
                let regions: Vec<Rect> = (0..=last).map(|i| cone.region(i)).collect();
                self.cone(world, window, &paste::needs(&pastes, &regions))
            }
        };
        for i in 0..=first.top() {
            let r = first.region(i);
            crate::size::check_dims(r.width(), r.height())?;
        }
        let guides = self.window_guides(&first, last, c, None)?;
        let (one, frames) = self.run_cone(&first, seed, &guides, None, !pastes.is_empty())?;
        let mut hf = one.heightfield;
        if let Some(mut frames) = frames {
            let regions: Vec<Rect> = (0..=last).map(|i| first.region(i)).collect();
            paste::write(&pastes, db, &mut frames, &regions);
            let prev = Frames {
                levels: (frames.levels.iter().enumerate())
                    .map(|(i, passes)| {
                        let (from, to) = (first.region(i), cone.region(i));
                        (passes.iter())
                            .map(|q| PassResult {
                                coords: crop(&q.coords, from, to),
                                offsets: crop(&q.offsets, from, to),
                            })
                            .collect()
                    })
                    .collect(),
                ..Frames::default()
            };
            let guides = self.window_guides(&cone, last, c, Some(&pastes))?;
            let two = self.run_cone(&cone, seed, &guides, Some(prev), false)?.0;
            let frozen = paint(c.freeze, window, "freeze mask")?;
            let old = std::mem::replace(&mut hf, two.heightfield);
            if let Some(f) = frozen {
                for ((h, o), _) in (hf.data_mut().iter_mut().zip(old.data()))
                    .zip(&f)
                    .filter(|(_, f)| **f)
                {
                    *h = *o;
                }
            }
        }
        self.place(&mut hf, &cone);
        Ok(hf)
    }

    /// Per-level guides over a cone's regions (levels 0..=last): targets,
    /// type sets (levels ≥ 2), and with `pastes` (the second frame) the
    /// coherence weights.
    fn window_guides(
        &self,
        cone: &Cone,
        last: usize,
        c: &WindowControls<'_>,
        pastes: Option<&[PasteGeometry]>,
    ) -> Result<Guides, SynthError> {
        let db = self.database();
        let world = cone.world();
        let regions: Vec<Rect> = (0..=last).map(|i| cone.region(i)).collect();
        let mut blend = Blend::over(&regions, db.quantization());
        for k in c.constraints {
            blend.add(&**k);
        }
        let fp = footprints(cone, last);
        let in_world = |r: Rect| Rect {
            x1: r.x1.min(world.0),
            y1: r.y1.min(world.1),
            ..r
        };
        let allowed = match paint(c.types, in_world(fp[0]), "type paint")? {
            None => None,
            Some(painted) => {
                let max = db.type_names().len() - 1;
                if let Some(k) = painted
                    .iter()
                    .position(|&t| t != UNCONSTRAINED && t as usize > max)
                {
                    let r = in_world(fp[0]);
                    return Err(WindowError::TypeId {
                        x: r.x0 + k % r.width(),
                        y: r.y0 + k / r.width(),
                        id: painted[k],
                        max,
                    }
                    .into());
                }
                let full = ((1u64 << db.type_names().len()) - 1) as u32;
                Some(type_sets(&painted, world, &fp, full))
            }
        };
        let weights = match pastes {
            None => None,
            Some(p) => Some(self.weights(world, &fp, p, c.freeze)?),
        };
        let cell = self.cell_size_m();
        let levels = (0..=last)
            .map(|i| {
                let r = regions[i];
                LevelGuide {
                    targets: blend.targets(i, cell).map(|t| t.cells),
                    allowed: (allowed.as_ref())
                        .filter(|_| i >= FIRST_LEVEL)
                        .map(|a| crop(&a[i], fp[i], r)),
                    weights: weights.as_ref().map(|w| crop(&w[i], fp[i], r)),
                    dirty: None,
                }
            })
            .collect();
        Ok(Guides {
            levels,
            restrict: false,
        })
    }

    /// W^i over the footprints for the paste step: level 0 coherent, free
    /// within [`PASTE_MARGIN`] of a pasted pixel, frozen where frozen or
    /// pasted; pasted pixels frozen at every level.
    fn weights(
        &self,
        world: (usize, usize),
        fp: &[Rect],
        pastes: &[PasteGeometry],
        freeze: Option<Paint<'_, bool>>,
    ) -> Result<Vec<Vec<u8>>, SynthError> {
        let pasted: Vec<Vec<bool>> = (0..fp.len())
            .map(|i| paste::pasted(pastes, i, fp[i]))
            .collect();
        let f0 = fp[0];
        let m = PASTE_MARGIN as usize;
        let near_rect = f0.widen(m, level_size(world.0, world.1, 0));
        let near = dilate(&paste::pasted(pastes, 0, near_rect), near_rect, m);
        let mut w0 = vec![W_COHERENT; f0.pixels()];
        for (k, w) in w0.iter_mut().enumerate() {
            let (x, y) = (f0.x0 + k % f0.width(), f0.y0 + k / f0.width());
            if near[(y - near_rect.y0) * near_rect.width() + x - near_rect.x0] {
                *w = W_FREE;
            }
        }
        let inner = Rect {
            x1: f0.x1.min(world.0),
            y1: f0.y1.min(world.1),
            ..f0
        };
        if let Some(f) = paint(freeze, inner, "freeze mask")? {
            for (k, _) in f.iter().enumerate().filter(|(_, f)| **f) {
                let (x, y) = (inner.x0 + k % inner.width(), inner.y0 + k / inner.width());
                w0[(y - f0.y0) * f0.width() + x - f0.x0] = W_FROZEN;
            }
        }
        for (w, &p) in w0.iter_mut().zip(&pasted[0]) {
            if p {
                *w = W_FROZEN;
            }
        }
        Ok(weight_sets(w0, fp, &pasted))
    }
}

/// Paint over `rect`, checked to hold one value per pixel.
fn paint<T>(
    p: Option<Paint<'_, T>>,
    rect: Rect,
    what: &'static str,
) -> Result<Option<Vec<T>>, WindowError> {
    let Some(p) = p else { return Ok(None) };
    let v = p(rect);
    if v.len() != rect.pixels() {
        return Err(WindowError::Paint {
            what,
            got: v.len(),
            expected: rect.pixels(),
        });
    }
    Ok(Some(v))
}

/// Pixels of `rect` within `by` (per axis) of a set pixel of `mask`.
fn dilate(mask: &[bool], rect: Rect, by: usize) -> Vec<bool> {
    let (w, h) = (rect.width(), rect.height());
    let pass = |src: &[bool], n: usize, step: usize, lines: usize, stride: usize| {
        let mut out = vec![false; src.len()];
        for line in 0..lines {
            let at = |i: usize| line * stride + i * step;
            for i in 0..n {
                let (a, b) = (i.saturating_sub(by), (i + by).min(n - 1));
                out[at(i)] = (a..=b).any(|j| src[at(j)]);
            }
        }
        out
    };
    let rows = pass(mask, w, 1, h, w);
    pass(&rows, h, w, w, 1)
}
