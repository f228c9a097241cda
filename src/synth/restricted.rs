//! A level's correction under control ([`Synthesizer::correct_level`]),
//! and restricted re-synthesis
//! ([`Guides::restrict`](super::Guides::restrict)): an edit corrects, at
//! each level, only the window that can differ from the previous frame.
//!
//! The window's passes run on a crop of the level — the window and the
//! two-pixel ring its subpasses read — rather than on the whole level. The
//! stage's rule for pixels outside a window (they take the previous frame's
//! result of the pass, [`correct::keep_outside`]) then writes only the
//! ring, instead of sweeping every pixel of the level in every subpass (at
//! 1024² the sweeps cost several times the window's own correction). The
//! level afterwards is the previous frame's result with the window's
//! pixels replaced: what the whole-level subpasses leave, byte for byte.
//!
//! The GPU crops too: on the whole level it uploaded every pixel's guide
//! cell and read the whole state back after every pass, where the crop
//! moves the window's share of both and uploads the level once (measured
//! on lavapipe: a 20-px point move at 1024², `edit/gpu/1024/moved_point`,
//! 1.48 s → 153 ms; the second frame of the example scene's edit, then
//! `canyonlands` on the procedural default exemplars, 631 → 489 ms; the
//! same bytes).
//!
//! The crop's corner is even, so that its parents stay at p / 2 in the
//! parent's crop ([`parent_view`]); the ring keeps every corrected pixel
//! two pixels from a crop edge that is not the level's, so no read of the
//! stage (reach two, [`REACH_PER_SUBPASS`]; the height prior's parent
//! neighbour) meets an edge the whole level does not have; and
//! [`Guide::origin`] makes the stage's hashes see absolute coordinates.
//!
//! [`correct::keep_outside`]: crate::stages::correct::keep_outside

use super::cone::{Rect, crop, parent_view};
use super::window::{REACH_PER_SUBPASS, changed_bounds, double, row_bounds, union, widen};
use super::{Control, Frames, PassResult, SynthError, Synthesizer};
use crate::backend::Backend;
use crate::level::fixed::Coord;
use crate::level::state::State;
use crate::stages::correct::{Coherence, Guide, SUBPASSES};

/// One level's buffers for [`Synthesizer::correct_cropped`]: the state,
/// the level above and its size, the level's passes and where it lies.
pub(super) struct LevelBuffers<'s, S> {
    pub state: &'s S,
    pub parent: Option<(&'s S, (usize, usize))>,
    pub level: usize,
    pub passes: u32,
    pub region: Rect,
}

impl Synthesizer<'_> {
    /// The window of a `w × h` level that restricted re-synthesis corrects
    /// ([`super::Guides::restrict`], with a previous frame of the level): the
    /// pixels whose own inputs changed and the children of the parent's
    /// changed pixels, widened by how far the level's `passes` carry a
    /// change. None: the whole level.
    pub(super) fn window(
        &self,
        c: &Control<'_>,
        (level, passes): (usize, u32),
        (w, h): (usize, usize),
        changed_parent: Option<[usize; 4]>,
    ) -> Option<[usize; 4]> {
        let prev = c.prev.as_ref()?.borrow();
        if !c.guides.restrict || prev.levels.get(level)?.is_empty() {
            return None;
        }
        let dirty = c.guides.levels.get(level).and_then(|g| g.dirty);
        let seeds = union(dirty, changed_parent.map(double));
        let grow = REACH_PER_SUBPASS * SUBPASSES.len() * passes as usize;
        Some(seeds.map_or([0; 4], |b| widen(b, grow, w, h)))
    }

    /// Whether the level's `window` can be corrected on a crop: each of its
    /// `passes` has the previous frame's result and weights (the coherence
    /// that decides the pixels outside the window).
    pub(super) fn can_crop(&self, c: &Control<'_>, level: usize, passes: u32) -> bool {
        let passes = passes as usize;
        passes > 0
            && c.prev
                .as_ref()
                .and_then(|f| f.borrow().levels.get(level).map(Vec::len))
                .is_some_and(|n| n >= passes)
            && c.guides
                .levels
                .get(level)
                .is_some_and(|g| g.weights.is_some())
    }

    /// The `passes` correction passes of one `w × h` level under control: each
    /// pass's guide uploaded to the backend, its result recorded into
    /// `frames`. With
    /// [`Guides::restrict`](crate::synth::params::Guides::restrict) and a
    /// previous frame, only the window that can differ is corrected (the
    /// stage gives the rest the previous result). Returns the bounds of the pixels that differ from
    /// the previous frame's, for the level below.
    pub(super) fn correct_level<B: Backend>(
        &self,
        b: &B,
        (state, parent): (&B::State, Option<&B::State>),
        (level, passes, region): (usize, u32, Rect),
        c: &Control<'_>,
        window: Option<[usize; 4]>,
        mut frames: Option<&mut Frames>,
    ) -> Result<Option<[usize; 4]>, SynthError> {
        let (w, h) = (region.width(), region.height());
        let lg = c.guides.levels.get(level);
        let prev = c.prev.as_ref().map(|f| f.borrow());
        let before = prev.as_ref().and_then(|f| f.levels.get(level));
        let mut last_result = None;
        for pass in 0..passes as usize {
            let last = before.and_then(|b| b.get(pass));
            let coherence = match (last, lg.and_then(|g| g.weights.as_deref())) {
                (Some(r), Some(weights)) => Some(Coherence {
                    coords: &r.coords,
                    offsets: &r.offsets,
                    weights,
                }),
                _ => None,
            };
            let guide = Guide {
                level: level as u32,
                targets: lg.and_then(|g| g.targets.as_deref()),
                allowed: lg.and_then(|g| g.allowed.as_deref()),
                coherence,
                window,
                origin: [region.x0 as u32, region.y0 as u32],
            };
            let g = b.upload_guide(&guide, w, h)?;
            self.subpasses(b, (state, parent), level, &g);
            let is_last = pass + 1 == passes as usize;
            if frames.is_some() || (is_last && window.is_some()) {
                let (coords, offsets) = b.download(state)?;
                let r = PassResult { coords, offsets };
                match frames.as_deref_mut() {
                    Some(f) => f.levels[level].push(r),
                    None => last_result = Some(r),
                }
            }
        }
        let current = last_result
            .as_ref()
            .or_else(|| frames.and_then(|f| f.levels[level].last()));
        Ok(match (window, before.and_then(|b| b.last()), current) {
            (Some(win), Some(r), Some(cur)) => changed_bounds(&cur.coords, &cur.offsets, w, r, win),
            _ => Some([0, 0, w, h]),
        })
    }

    /// The correction passes of one level's `window` on a crop of the level
    /// (module docs), each pass's result recorded into `frames`. Returns
    /// the bounds of the pixels that differ from the previous frame's and
    /// the corrected level.
    pub(super) fn correct_cropped<B: Backend>(
        &self,
        b: &B,
        buf: LevelBuffers<'_, B::State>,
        c: &Control<'_>,
        window: [usize; 4],
        mut frames: Option<&mut Frames>,
    ) -> Result<(Option<[usize; 4]>, B::State), SynthError> {
        let LevelBuffers {
            state,
            parent,
            level,
            passes,
            region,
        } = buf;
        let (w, h) = (region.width(), region.height());
        let level_rect = Rect::new(0, 0, w, h);
        // This level's previous results, taken: each pass's becomes this
        // frame's, with the window's pixels replaced; so does its final
        // state where one was kept.
        let (before, kept) = {
            let mut prev = c.prev.as_ref().expect("checked by can_crop").borrow_mut();
            let kept = prev.states.get_mut(level).and_then(Option::take);
            (std::mem::take(&mut prev.levels[level]), kept)
        };
        let lg = &c.guides.levels[level];
        let [wx0, wy0, wx1, wy1] = widen(window, REACH_PER_SUBPASS, w, h);
        let cr = Rect {
            x0: wx0,
            y0: wy0,
            x1: wx1,
            y1: wy1,
        }
        .even();
        let sub = b.crop(state, [cr.x0, cr.y0, cr.x1, cr.y1])?;
        let parent_sub = match parent {
            Some((p, size)) => {
                let v = parent_view(cr, (w, h), size);
                Some(b.crop(p, [v.x0, v.y0, v.x1, v.y1])?)
            }
            None => None,
        };
        let targets = lg.targets.as_ref().map(|t| crop(t, level_rect, cr));
        let allowed = lg.allowed.as_ref().map(|a| crop(a, level_rect, cr));
        let weights = crop(lg.weights.as_ref().expect("checked"), level_rect, cr);
        let (a, z) = (window[0] - cr.x0, window[2] - cr.x0);
        let local = [a, window[1] - cr.y0, z, window[3] - cr.y0];
        let (mut last, mut changed) = (None, None);
        let passes = passes as usize;
        for (pass, mut prev) in before.into_iter().enumerate().take(passes) {
            let (coords, offsets) = (
                crop(&prev.coords, level_rect, cr),
                crop(&prev.offsets, level_rect, cr),
            );
            let guide = Guide {
                level: level as u32,
                targets: targets.as_deref(),
                allowed: allowed.as_deref(),
                coherence: Some(Coherence {
                    coords: &coords,
                    offsets: &offsets,
                    weights: &weights,
                }),
                window: Some(local),
                origin: [(region.x0 + cr.x0) as u32, (region.y0 + cr.y0) as u32],
            };
            let g = b.upload_guide(&guide, cr.width(), cr.height())?;
            self.subpasses(b, (&sub, parent_sub.as_ref()), level, &g);
            let is_last = pass + 1 == passes;
            if frames.is_some() || is_last {
                // The pass's result: the previous frame's with the
                // window's pixels replaced (the last pass's changes bound
                // what the level below re-synthesizes).
                let (sc, so) = b.download(&sub)?;
                let c = replace_window(&mut prev, w, window, (&sc, &so), cr.width(), [a, cr.y0]);
                if is_last {
                    changed = c;
                }
                match frames.as_deref_mut() {
                    Some(f) => f.levels[level].push(prev),
                    None => last = Some(prev),
                }
            }
        }
        let last = last
            .as_ref()
            .or_else(|| frames.and_then(|f| f.levels[level].last()))
            .expect("passes > 0 (checked by can_crop)");
        // The level's state holds the last pass's result: the previous
        // frame's state with the window written, or (none kept) a new one.
        let st = match kept.filter(|s| (s.width, s.height) == (w, h)) {
            Some(st) => {
                st.write_rect(window, &last.coords, &last.offsets);
                st
            }
            None => State::from_parts(w, h, &last.coords, &last.offsets),
        };
        Ok((changed, b.upload(st)?))
    }

    /// The subpasses of one correction pass, guided by `g`.
    fn subpasses<B: Backend>(
        &self,
        b: &B,
        (state, parent): (&B::State, Option<&B::State>),
        level: usize,
        g: &B::Guide<'_>,
    ) {
        for &sub in &SUBPASSES {
            let p = self.correct_params(level, sub);
            b.correct_guided(state, parent, level, &p, g);
        }
    }
}

/// Writes a crop's `window` (level coordinates; the crop is `stride` wide,
/// `window[0]` is its column `x`, level row `y` its row `y − y0`) into a
/// whole level's result `r` (`w` wide); returns the bounds of the pixels
/// that changed.
fn replace_window(
    r: &mut PassResult,
    w: usize,
    window: [usize; 4],
    (coords, offsets): (&[Coord], &[i32]),
    stride: usize,
    [x, y0]: [usize; 2],
) -> Option<[usize; 4]> {
    let n = window[2] - window[0];
    let mut changed = None;
    for y in window[1]..window[3] {
        let (to, from) = (y * w + window[0]..y * w + window[2], (y - y0) * stride + x);
        let (c, o) = (&coords[from..from + n], &offsets[from..from + n]);
        let differ = (r.coords[to.clone()].iter().zip(c))
            .zip(r.offsets[to.clone()].iter().zip(o))
            .map(|((a, b), (p, q))| a != b || p != q);
        changed = union(changed, row_bounds(y, window[0], differ));
        r.coords[to.clone()].copy_from_slice(c);
        r.offsets[to].copy_from_slice(o);
    }
    changed
}
